"""N1MM Logger+'s rotor window, served: rotor commands in, headings out, over UDP.

The server plays N1MM's rotor program for the configured rotators:

- it listens on the rotor command port (12040 unless configured) and turns
  or stops the rotator whose name is the command's ``<rotor>``: a rotator's
  ``ShortName`` or ``LongName``, compared without case (``*`` names the only
  rotator when there is exactly one).  The turn goes through the callbacks
  the app gives, i.e. the server's rotator manager, like every other request;
- it sends every rotator's heading as ``name @ tenths`` to each configured
  destination (``host:port``, N1MM listening on 13010), at once when a heading
  changes and again every ``interval`` seconds, so a rotor window that starts
  later fills in.

Bad datagrams are dropped with one rate-limited debug line each; a name that
is not a rotator, likewise.  Each command obeyed is an Info line, at once and then one
a minute per rotator, the last of a burst with its count.  See docs/sources.md for the N1MM settings.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable, Iterable, Mapping
from typing import Final

from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.sources.base import BadInputLog
from moas_gui.sources.log_bursts import BurstLog
from moas_gui.sources.n1mm_rotor_packet import (
    DEFAULT_COMMAND_PORT,
    DEFAULT_HEADING_PORT,
    N1MMRotorError,
    RotorStop,
    RotorTurn,
    heading_report,
    parse_rotor_command,
)
from moas_gui.sources.udp import DatagramSource

log = logging.getLogger(__name__)

INTERVAL: Final = 1.5
"""Seconds between two rounds of heading reports (compatible rotor programs use 1.5 s)."""

TurnCallback = Callable[[int, float], object]
"""``turn(rotator_id, heading)``: may raise; the error is logged, rate-limited."""
StopCallback = Callable[[int], object]
HeadingsCallback = Callable[[], Iterable[tuple[int, float | None]]]
"""Every rotator's id and current heading (``None`` while unknown)."""


def parse_destination(text: str, default_port: int = DEFAULT_HEADING_PORT) -> tuple[str, int]:
    """``"192.168.1.20:13010"`` (or a bare host, port 13010) as ``(host, port)``."""
    host, colon, port_text = text.strip().rpartition(":")
    if not colon:
        host, port_text = text.strip(), str(default_port)
    if not host or not port_text.isdigit() or not 1 <= int(port_text) <= 65535:
        raise ValueError(f"{text!r} is not host:port (such as 192.168.1.20:13010)")
    return host, int(port_text)


class N1MMRotorServer(DatagramSource):
    """The rotor program N1MM's rotor window talks to."""

    kind = "n1mm-rotor"
    label = "N1MM rotor"

    def __init__(
        self,
        names: Mapping[int, Iterable[str]],
        *,
        turn: TurnCallback,
        stop: StopCallback,
        headings: HeadingsCallback,
        destinations: Iterable[tuple[str, int]] = (),
        port: int = DEFAULT_COMMAND_PORT,
        host: str = "0.0.0.0",
        interval: float = INTERVAL,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__()
        self._ids: dict[str, int] = {}
        self._names: dict[int, str] = {}
        for rotator_id, labels in names.items():
            for label in labels:
                if label and label.casefold() not in self._ids:
                    self._ids[label.casefold()] = rotator_id
                    self._names.setdefault(rotator_id, label)
        self._turn = turn
        self._stop = stop
        self._headings = headings
        self._destinations = list(destinations)
        self._port = port
        self._host = host
        self._interval = interval
        self.bad = BadInputLog(log, self.label, clock=clock)
        self._said = BurstLog(log, logging.INFO, clock=clock)
        """The commands obeyed: at once, then one line a minute per rotator with a count."""
        self._limiter = LogLimiter(60.0, clock)
        self._sent: dict[int, bytes] = {}
        self._ticker: asyncio.Task[None] | None = None
        self.received = self.turns = self.stops = self.ignored = self.reports = 0

    # -- commands ---------------------------------------------------------------------
    def rotator_of(self, name: str) -> int | None:
        if name == "*" and len(self._names) == 1:
            return next(iter(self._names))
        return self._ids.get(name.casefold())

    def handle(self, data: bytes, address: str) -> RotorTurn | RotorStop | None:
        self.received += 1
        try:
            command = parse_rotor_command(data)
        except N1MMRotorError as exc:
            if exc.reason == "not_rotor":
                self.ignored += 1
            else:
                self.bad.drop(exc.reason, address, str(exc))
            return None
        rotator_id = self.rotator_of(command.rotor)
        if rotator_id is None:
            known = ", ".join(sorted(self._names.values())) or "none configured"
            self.bad.drop("unknown_rotor", f"{address} {command.rotor!r}",
                          f"no rotator is named {command.rotor!r} (rotators: {known})")
            return None
        try:
            if isinstance(command, RotorStop):
                self.stops += 1
                self._said.line(("command", rotator_id), "N1MM rotor window (%s): stop %s",
                                address, command.rotor)
                self._stop(rotator_id)
            else:
                self.turns += 1
                self._said.line(("command", rotator_id),
                                "N1MM rotor window (%s): turn %s to %.1f", address,
                                command.rotor, command.azimuth)
                self._turn(rotator_id, command.azimuth)
        except Exception as exc:  # noqa: BLE001 - a refused turn is the manager's to explain
            held = self._limiter.allow(("refused", rotator_id))
            if held is not None:
                log.warning("N1MM rotor window: %s of %s refused: %s%s",
                            "stop" if isinstance(command, RotorStop) else "turn",
                            command.rotor, exc, held_text(held))
        return command

    # -- heading reports --------------------------------------------------------------
    def heading_changed(self, rotator_id: int, heading: float | None) -> None:
        """Send this rotator's heading now if it differs from the last one sent."""
        self._report(rotator_id, heading, only_changes=True)

    def send_headings(self) -> None:
        """One round: every rotator with a known heading, to every destination."""
        for rotator_id, heading in self._headings():
            self._report(rotator_id, heading, only_changes=False)

    def _report(self, rotator_id: int, heading: float | None, *, only_changes: bool) -> None:
        name = self._names.get(rotator_id)
        # the selector loop's datagram transport does not derive from DatagramTransport
        sendto: Callable[[bytes, tuple[str, int]], None] | None = getattr(
            self._transport, "sendto", None)
        if name is None or heading is None or not self._destinations or sendto is None:
            return
        data = heading_report(name, heading)
        if only_changes and self._sent.get(rotator_id) == data:
            return
        self._sent[rotator_id] = data
        for destination in self._destinations:
            try:
                sendto(data, destination)
                self.reports += 1
            except OSError as exc:
                held = self._limiter.allow(("send", destination))
                if held is not None:
                    log.debug("N1MM rotor window: heading to %s:%d not sent: %s%s",
                              destination[0], destination[1], exc, held_text(held))

    async def _tick(self) -> None:
        while True:
            self.send_headings()
            await asyncio.sleep(self._interval)

    # -- life -------------------------------------------------------------------------
    async def start(self, port: int | None = None, host: str | None = None) -> int:
        host = self._host if host is None else host
        bound = await self.bind(self._port if port is None else port, host)
        self._ticker = asyncio.create_task(self._tick(), name="N1MM rotor headings")
        targets = ", ".join(f"{h}:{p}" for h, p in self._destinations) or "nowhere"
        log.info("N1MM rotor window: commands on UDP %s:%d for %s; headings to %s", host, bound,
                 ", ".join(sorted(self._names.values())) or "no rotators", targets)
        return bound

    async def close(self) -> None:
        if self._ticker is not None:
            self._ticker.cancel()
            try:
                await self._ticker
            except asyncio.CancelledError:
                pass
            self._ticker = None
        self._said.close()
        await super().close()




__all__ = ["INTERVAL", "N1MMRotorServer", "parse_destination"]
