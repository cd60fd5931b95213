"""The rigctld source: one radio behind Hamlib's network rig daemon, polled.

rigctld serves one radio per process and TCP port (4532 by default; a second
radio on 4534, ...).  This source asks it for the frequency, split, split
frequency and PTT (:mod:`moas_gui.sources.rigctld_reply`) ten times a second
and reports the radio of this server's ``station`` and ``radio`` when any of
them changed.  Start the daemon with the radio's Hamlib model, for example
``rigctld -m 3073 -r /dev/ttyUSB0 -t 4532`` (``-m 1`` is Hamlib's dummy rig).
See docs/sources.md.
"""

from __future__ import annotations

import asyncio
import time
from typing import Final

from moas_gui.sources.polling import (
    BadReply,
    PolledRig,
    RigState,
)
from moas_gui.sources.rigctld_reply import (
    DEFAULT_PORT,
    POLL,
    ReplyParser,
    RigctldReplyError,
    RigReading,
)

READ_SIZE: Final = 4096


class RigctldSource(PolledRig):
    """Polls one rigctld."""

    kind = "rigctld"
    label = "rigctld"
    default_port = DEFAULT_PORT
    _parser: ReplyParser

    async def connected(self, reader: asyncio.StreamReader,
                        writer: asyncio.StreamWriter) -> None:
        self._parser = ReplyParser()  # a new connection starts a new reply stream

    async def poll(self, reader: asyncio.StreamReader,
                   writer: asyncio.StreamWriter) -> RigState:
        writer.write(POLL)
        while True:
            data = await reader.read(READ_SIZE)
            if not data:
                raise EOFError("closed")
            try:
                readings = self._parser.feed(data)
            except RigctldReplyError as exc:
                raise BadReply(exc.reason, str(exc)) from None
            if readings:
                self.answered_at = time.perf_counter()
                return _state(readings[-1])


def _state(reading: RigReading) -> RigState:
    tx = reading.transmit_hz
    return RigState(
        rx_khz=None if reading.rx_hz is None else reading.rx_hz / 1000.0,
        tx_khz=None if tx is None else tx / 1000.0,
        transmitting=reading.ptt,
    )


__all__ = ["DEFAULT_PORT", "RigctldSource"]
