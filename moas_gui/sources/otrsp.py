"""The OTRSP source: an SO2R logger's serial commands to transmit focus and antennas.

The logger writes OTRSP (:mod:`moas_gui.sources.otrsp_command`) to a serial
port, normally its SO2R box.  Given that port -- a second port of a virtual
serial pair, a serial splitter, or a pseudo-terminal on Linux -- this source

- turns ``TX1``/``TX2`` into an :class:`~moas_gui.sources.base.ActiveRadio`
  (the transmit focus of the SO2R station),
- turns ``RX1``/``RX2`` (and their stereo forms) into a
  :class:`~moas_gui.sources.base.FocusRadio`,
- turns ``AUX1n``/``AUX2n`` into an :class:`AuxAntenna` when the
  configuration maps value ``n`` of that radio to an antenna (N1MM sends the
  row of its Antennas table; so2sdr and others a band number), and says
  nothing otherwise (one debug line per value a minute);
- answers the queries a logger may send to see the device is there
  (``?NAME`` with ``NAMEmoas-gui``, ``?TX``, ``?RX``, ``?AUX1``, ``?AUX2``;
  any other query is echoed, as the reference device does).

Only changes are passed on.  OTRSP radio 1 and 2 become this station's radios
by the ``radios`` map.  The port is opened through the program's serial layer
(:mod:`moas_gui.serial`) with :data:`OTRSP_PORT`.  A port that is missing or goes away is retried with a
growing pause, with one warning and one "back" line (docs/sources.md).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from moas_gui.retry import Backoff, Pauses
from moas_gui.serial import PortSettings
from moas_gui.sources.base import (
    DEFAULT_RETRY,
    RETRY_LIMIT,
    ActiveRadio,
    AuxAntenna,
    BadInputLog,
    ConnectionLog,
    FocusRadio,
    SourceSink,
)
from moas_gui.sources.otrsp_command import (
    Aux,
    CommandParser,
    OtrspCommand,
    OtrspError,
    Query,
    RxFocus,
    TxFocus,
)

log = logging.getLogger(__name__)

DEVICE_NAME = "moas-gui"


@dataclass(frozen=True, slots=True)
class OtrspMap:
    """What OTRSP's radio 1 and 2 and their AUX values are at this station."""

    station: int
    radios: Mapping[int, int] = field(default_factory=lambda: {1: 1, 2: 2})
    """OTRSP radio (1, 2) to this station's radio number."""
    antennas: Mapping[tuple[int, int], int] = field(default_factory=dict)
    """(OTRSP radio, AUX value) to antenna ID."""


class OtrspSource:
    """Reads one serial port the logger writes OTRSP to."""

    kind = "otrsp"
    label = "OTRSP"

    def __init__(
        self,
        port: str,
        mapping: OtrspMap,
        on_event: SourceSink,
        *,
        transport_factory: Callable[[str], Any] | None = None,
        clock: Callable[[], float] = time.monotonic,
        retry: float = DEFAULT_RETRY,
    ) -> None:
        self.port = port
        self.mapping = mapping
        self._on_event = on_event
        self.origin = f"OTRSP {port}"
        self._factory = transport_factory or _serial_transport
        self.bad = BadInputLog(log, self.label, clock=clock)
        self.link = ConnectionLog(log, f"OTRSP port {port}", clock=clock)
        self._backoff = Pauses(Backoff(first=retry, most=max(retry, RETRY_LIMIT)))
        self._parser = CommandParser()
        self._transport: Any = None
        self._task: asyncio.Task[None] | None = None
        self._lost: asyncio.Event | None = None
        self._tx = 1
        self._rx: RxFocus = RxFocus(1, "mono")
        self._aux: dict[int, int] = {1: 0, 2: 0}
        self._said: dict[str, object] = {}
        self.commands = 0

    async def start(self) -> str:
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._run(), name="OTRSP port")
        return self.port

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task
        self._close_transport()

    def forget(self) -> None:
        """Pass the next focus and AUX command on even if it repeats the last (the engine
        restarted)."""
        self._said.clear()

    def _close_transport(self) -> None:
        transport, self._transport = self._transport, None
        if transport is not None:
            transport.close()

    async def _run(self) -> None:
        while True:
            lost = self._lost = asyncio.Event()
            reasons: list[str] = []
            transport = self._factory(self.port)
            try:
                transport.open(self.feed, _setter(lost, reasons))
            except OSError as exc:
                self.link.lost(str(exc))
                await asyncio.sleep(self._backoff.next())
                continue
            self._transport = transport
            self._parser = CommandParser()
            self._said.clear()
            self.link.up()
            self._backoff.reset()
            await lost.wait()
            self._close_transport()
            self.link.lost(reasons[0] if reasons else "the port was closed")
            await asyncio.sleep(self._backoff.next())

    # -- the logic (callable without a port) -------------------------------------------------
    def feed(self, data: bytes) -> None:
        for item in self._parser.feed(data):
            if isinstance(item, OtrspError):
                self.bad.drop(item.reason, self.port, str(item))
            else:
                self.commands += 1
                self._command(item)

    def _command(self, command: OtrspCommand) -> None:
        m = self.mapping
        if isinstance(command, Query):
            self._answer(command.text)
        elif isinstance(command, TxFocus):
            self._tx = command.radio
            radio = m.radios.get(command.radio)
            if radio is not None:
                self._say("tx", ActiveRadio(m.station, radio, self.origin))
        elif isinstance(command, RxFocus):
            self._rx = command
            radio = m.radios.get(command.radio)
            if radio is not None:
                self._say("rx", FocusRadio(m.station, radio, self.origin))
        elif isinstance(command, Aux):
            self._aux[command.radio] = command.value
            radio = m.radios.get(command.radio)
            antenna = m.antennas.get((command.radio, command.value))
            if radio is None:
                return
            if antenna is None:
                self.bad.drop("unmapped_aux", self.port,
                              f"AUX{command.radio} {command.value} is not mapped to an antenna")
                return
            self._say(f"aux{command.radio}",
                      AuxAntenna(m.station, radio, antenna, command.value, self.origin))

    def _say(self, key: str, event: Any) -> None:
        if self._said.get(key) == event:
            return
        self._said[key] = event
        self._on_event(event)

    def _answer(self, query: str) -> None:
        if query == "NAME":
            reply = f"NAME{DEVICE_NAME}"
        elif query == "TX":
            reply = f"TX{self._tx}"
        elif query == "RX":
            reply = f"RX{self._rx.radio}" + {"mono": "", "stereo": "S",
                                               "reverse": "R"}[self._rx.audio]
        elif query in ("AUX1", "AUX2"):
            reply = f"{query}{self._aux[int(query[-1])]}"
        else:
            reply = f"?{query}"
        transport = self._transport
        if transport is not None:
            try:
                transport.write(reply.encode("ascii") + b"\r")
            except OSError as exc:
                log.debug("OTRSP port %s: the answer to ?%s was not written: %s", self.port,
                          query, exc)


def _setter(event: asyncio.Event, reasons: list[str]) -> Callable[[str], None]:
    def lost(why: str) -> None:
        reasons.append(why)
        event.set()
    return lost


OTRSP_PORT = PortSettings(baudrate=9600, write_timeout=2.0, exclusive=True, flush_on_open=True)
"""A logger's OTRSP port: 9600 baud 8N1, for this source alone, old bytes dropped."""


def _serial_transport(port: str) -> Any:
    from moas_gui.serial.port import SerialPort

    return SerialPort(port, OTRSP_PORT)


__all__ = ["DEVICE_NAME", "OTRSP_PORT", "AuxAntenna", "OtrspMap", "OtrspSource"]
