"""The Win-Test source: STATUS broadcasts in, radio frequencies out.

Win-Test stations broadcast their status on UDP (port 9871 unless changed in
Win-Test's network settings).  Every computer of a Win-Test network hears
every other's STATUS, so frames are always mapped by the sending station's
name (Win-Test's "station name", field 0 of the frame) to this server's
station and radio, given by the configuration's ``WinTest`` list or, in
``moas-client``, by the command line.  Frames from names not listed are
ignored (one debug line per name a minute).

A :class:`~moas_gui.sources.base.FrequencyReport` goes out when a radio's
frequency changes.  Win-Test's STATUS has no published transmit frequency,
transmit state or radio number, so the report's transmit frequency is the
receive frequency and no focus events are sent (see docs/sources.md).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from typing import Final

from moas_gui.log_limit import LogLimiter
from moas_gui.sources.base import BadInputLog, FrequencyReport, SourceSink
from moas_gui.sources.udp import DatagramSource
from moas_gui.sources.wintest_frame import (
    DEFAULT_PORT,
    WinTestFrameError,
    parse_status,
)

log = logging.getLogger(__name__)

IGNORED_REASONS: Final = frozenset({"not_status"})
"""Frames that are simply not ours (QSOs, gab...): counted, never logged."""


def _key(name: str) -> str:
    return name.strip().casefold()


class WinTestListener(DatagramSource):
    """Receives Win-Test STATUS broadcasts for the named stations."""

    kind = "wintest"
    label = "Win-Test"

    def __init__(
        self,
        stations: Mapping[str, tuple[int, int]],
        on_event: SourceSink,
        *,
        port: int = DEFAULT_PORT,
        host: str = "0.0.0.0",
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        super().__init__()
        self._stations = {_key(name): where for name, where in stations.items()}
        self._on_event = on_event
        self._port = port
        self._host = host
        self.bad = BadInputLog(log, self.label, clock=clock)
        self._unknown = BadInputLog(log, self.label, clock=clock)
        self._limiter = LogLimiter(60.0, clock)
        self._last: dict[tuple[int, int], float] = {}
        self._batch: dict[tuple[int, int], FrequencyReport] | None = None
        self.received = self.delivered = self.superseded = self.ignored = 0
        self.callback_errors = 0

    def handle(self, data: bytes, address: str) -> FrequencyReport | None:
        """Take one datagram; return the report it makes, if any."""
        self.received += 1
        try:
            status = parse_status(data)
        except WinTestFrameError as exc:
            if exc.reason in IGNORED_REASONS:
                self.ignored += 1
            else:
                self.bad.drop(exc.reason, address, str(exc))
            return None
        where = self._stations.get(_key(status.station_name))
        if where is None:
            self._unknown.drop("unknown", f"{address} {status.station_name!r}",
                               f"station name {status.station_name!r} is not in WinTest")
            return None
        if status.khz is None or self._last.get(where) == status.khz:
            return None
        self._last[where] = status.khz
        report = FrequencyReport(where[0], where[1], status.khz, status.khz,
                                 f"Win-Test {status.station_name} ({address})")
        if self._batch is not None:
            if self._batch.pop(where, None) is not None:
                self.superseded += 1
            self._batch[where] = report
        else:
            self._deliver(report)
        return report

    def _deliver(self, report: FrequencyReport) -> None:
        self.delivered += 1
        try:
            self._on_event(report)
        except Exception:
            self.callback_errors += 1
            if self._limiter.allow("sink") is not None:
                log.exception("Win-Test: acting on %r failed", report)

    def begin_burst(self) -> None:
        self._batch = {}

    def end_burst(self) -> None:
        batch, self._batch = self._batch, None
        for report in (batch or {}).values():
            self._deliver(report)

    def forget(self) -> None:
        """Make the next STATUS of every station count as a change."""
        self._last.clear()

    async def start(self, port: int | None = None, host: str | None = None) -> int:
        host = self._host if host is None else host
        bound = await self.bind(self._port if port is None else port, host)
        log.info("Listening for Win-Test on UDP %s:%d (%d station name%s)", host, bound,
                 len(self._stations), "" if len(self._stations) == 1 else "s")
        return bound


__all__ = ["DEFAULT_PORT", "WinTestListener"]
