"""The flrig source: one radio behind flrig's XML-RPC server, polled.

Each poll asks ``rig.get_vfo``, ``rig.get_split`` and ``rig.get_ptt``
(:mod:`moas_gui.sources.flrig_rpc`); when the radio is split it also asks
``rig.get_AB`` and the other VFO's frequency, which is then the transmit
frequency.  One HTTP connection is kept open between polls; when flrig
answers ``Connection: close`` the next call opens a new one quietly.  See
docs/sources.md.
"""

from __future__ import annotations

import asyncio
import time
from typing import Final

from moas_gui.sources.base import DEFAULT_RETRY, SourceSink
from moas_gui.sources.flrig_rpc import (
    DEFAULT_PORT,
    FlrigReplyError,
    ResponseParser,
    flag,
    hz,
    request,
)
from moas_gui.sources.polling import (
    DEFAULT_INTERVAL,
    DEFAULT_TIMEOUT,
    BadReply,
    PolledRig,
    RigState,
)

READ_SIZE: Final = 8192


class FlrigSource(PolledRig):
    """Polls one flrig."""

    kind = "flrig"
    label = "flrig"

    default_port = DEFAULT_PORT

    def __init__(self, station: int, radio: int, on_event: SourceSink, *,
                 host: str = "127.0.0.1", port: int | None = None,
                 interval: float = DEFAULT_INTERVAL, timeout: float = DEFAULT_TIMEOUT,
                 retry: float = DEFAULT_RETRY) -> None:
        super().__init__(station, radio, on_event, host=host, port=port, interval=interval,
                         timeout=timeout, retry=retry)
        self._parser = ResponseParser()
        self._streams: tuple[asyncio.StreamReader, asyncio.StreamWriter] | None = None
        self._own: asyncio.StreamWriter | None = None
        """A connection this source opened itself after flrig closed one."""

    async def connected(self, reader: asyncio.StreamReader,
                        writer: asyncio.StreamWriter) -> None:
        self._parser = ResponseParser()
        self._streams = (reader, writer)
        self._drop_own()

    def _drop_own(self) -> None:
        own, self._own = self._own, None
        if own is not None:
            own.close()

    async def close(self) -> None:
        await super().close()
        self._drop_own()

    async def _call(self, method: str) -> object:
        if self._parser.closing or self._streams is None:
            self._drop_own()
            reader, writer = await asyncio.open_connection(self.host, self.port)
            self._streams, self._own = (reader, writer), writer
            self._parser = ResponseParser()
        reader, writer = self._streams
        writer.write(request(method, self.host, self.port))
        while True:
            data = await reader.read(READ_SIZE)
            if not data:
                raise EOFError("closed")
            try:
                values = self._parser.feed(data)
            except FlrigReplyError as exc:
                raise BadReply(exc.reason, f"{method}: {exc}") from None
            if values:
                self.answered_at = time.perf_counter()
                return values[-1]

    async def poll(self, reader: asyncio.StreamReader,
                   writer: asyncio.StreamWriter) -> RigState:
        try:
            rx = hz(await self._call("rig.get_vfo"), "rig.get_vfo")
            split = flag(await self._call("rig.get_split"), "rig.get_split")
            ptt = flag(await self._call("rig.get_ptt"), "rig.get_ptt")
            tx = rx
            if split:
                active = await self._call("rig.get_AB")
                other = "rig.get_vfoB" if str(active).strip().upper() != "B" else "rig.get_vfoA"
                tx = hz(await self._call(other), other)
        except FlrigReplyError as exc:
            raise BadReply(exc.reason, str(exc)) from None
        return RigState(rx / 1000.0, tx / 1000.0, ptt)


__all__ = ["DEFAULT_PORT", "FlrigSource"]
