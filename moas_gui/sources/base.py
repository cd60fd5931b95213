"""What every frequency source shares: the events, the Source shape, and three rules.

A *source* is one way of learning what a radio does: a logger's network
broadcasts (N1MM Logger+, DXLog.net, Win-Test), a rig daemon polled over TCP
(rigctld, flrig), an SO2R serial line (OTRSP).  Each is built in two layers:

- a **sans-IO parser**: bytes (one datagram, one reply line) in, typed values
  out, no sockets and no clock, so every bad input can be tested directly;
- a thin **asyncio part** that owns the socket or port, maps what the logger
  calls a radio to this server's station and radio numbers, and hands
  :data:`SourceEvent` values to one callback (:data:`SourceSink`).

The same sources run inside the server (the app turns their events into
engine operations) and inside ``moas-client`` on an operating computer (which
sends them to the server in the client protocol).  See docs/sources.md.

The rules every source follows, with the helpers here that implement them:

- **Bad input is dropped with one debug line per kind, rate-limited**, and
  counted (:class:`BadInputLog`); it never raises out of a source and never
  changes a switch.
- **A source that disappears is retried quietly**: one warning when it goes
  away, one info line when it is back, nothing in between but rate-limited
  debug lines (:class:`ConnectionLog`, :class:`moas_gui.retry.Pauses`).
- **Two sources for one radio: the newest wins**, and the overlap is logged
  once per pair of sources (:class:`SourceHub`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final, Protocol, TypeAlias, runtime_checkable

from moas_gui.config.rigs import DEFAULT_RETRY as CONFIG_RETRY
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.sources.log_bursts import CrowdLimiter

MAX_KHZ: Final = 300_000_000.0
"""300 GHz: above every amateur band.  A frequency at or above it is refused as absurd."""

LOG_INTERVAL: Final = 60.0
"""Seconds between two debug lines about the same kind of bad input from the same place."""


# -- events ---------------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class FrequencyReport:
    """A radio's frequencies, in this server's station and radio numbers.

    ``rx_khz`` is where it listens, ``tx_khz`` where it transmits (equal when
    not split).  ``origin`` names the source and sender (``"N1MM SO2R-PC
    (192.168.1.20)"``) for log lines and for telling two sources apart.
    """

    station: int
    radio: int
    rx_khz: float
    tx_khz: float
    origin: str
    mode: str = ""
    transmitting: bool | None = None
    """What the logger says about its own keying (a hint, not a PTT sense)."""


@dataclass(frozen=True, slots=True)
class ActiveRadio:
    """Transmit focus: ``radio`` of ``station`` is the one that transmits next (SO2R)."""

    station: int
    radio: int
    origin: str


@dataclass(frozen=True, slots=True)
class FocusRadio:
    """Receive focus: the radio of ``station`` the operator listens to."""

    station: int
    radio: int
    origin: str


@dataclass(frozen=True, slots=True)
class RunOrSearch:
    """Whether ``radio`` of ``station`` is running (calling CQ) or searching and pouncing."""

    station: int
    radio: int
    running: bool
    origin: str


@dataclass(frozen=True, slots=True)
class AuxAntenna:
    """The logger chose antenna ``antenna`` (this server's ID) for ``radio`` of ``station``
    by OTRSP AUX value ``aux`` (the OTRSP source's event; here so that the server takes
    it without loading that source where no OTRSP port is set)."""

    station: int
    radio: int
    antenna: int
    aux: int
    origin: str


SourceEvent: TypeAlias = FrequencyReport | ActiveRadio | FocusRadio | RunOrSearch
SourceSink: TypeAlias = Callable[[SourceEvent], object]
"""Where a source hands its events (the app's entry into the engine, or the client link)."""


class Bursts(Protocol):
    """What a UDP listener tells the sink's owner around each burst of datagrams: events
    handed on between :meth:`hold` and :meth:`release` are decided at the release, in the
    same loop turn as the read (not in a later turn: a quiet server pays for every turn
    of its loop, and the first byte to the switch goes out a turn sooner)."""

    def hold(self) -> None: ...

    def release(self) -> None: ...


def event_key(event: SourceEvent) -> tuple[object, ...]:
    """What a newer event of the same key replaces: a radio's frequency, a station's focus..."""
    if isinstance(event, FrequencyReport):
        return ("frequency", event.station, event.radio)
    if isinstance(event, RunOrSearch):
        return ("running", event.station, event.radio)
    return (type(event).__name__, event.station)


def check_khz(khz: float, what: str) -> float:
    """``khz`` if it can be a radio frequency; :class:`ValueError` naming ``what`` if not."""
    if not khz > 0.0 or khz >= MAX_KHZ:  # also refuses NaN
        raise ValueError(f"{what} of {khz:,.3f} kHz is not a radio frequency")
    return khz


# -- the Source shape -----------------------------------------------------------------

@runtime_checkable
class Source(Protocol):
    """One running source: started once, closed once (closing twice is harmless)."""

    kind: str
    """Short name for logs and configuration: ``n1mm``, ``wintest``, ``rigctld``..."""

    async def start(self) -> object: ...

    async def close(self) -> None: ...


# -- rule: bad input ------------------------------------------------------------------

class BadInputLog:
    """Counts dropped input by reason and writes one debug line per reason and place a
    minute, and at most :data:`~.log_bursts.CROWD_LINES` a minute per reason from all
    places together (a datagram's sender costs nothing to forge).

    ``drop("not_xml", "192.168.1.5", "not XML: ...")`` counts it and maybe logs
    ``"<kind> input from 192.168.1.5 dropped: not XML: ... (12 more like it ...)"``.
    """

    def __init__(
        self,
        logger: logging.Logger,
        kind: str,
        *,
        interval: float = LOG_INTERVAL,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._log = logger
        self._kind = kind
        self._limiter = CrowdLimiter(interval, clock)
        self.counts: dict[str, int] = {}

    def drop(self, reason: str, where: str, message: str) -> None:
        self.counts[reason] = self.counts.get(reason, 0) + 1
        held = self._limiter.allow(reason, where)
        if held is not None:
            self._log.debug("%s input from %s dropped: %s%s", self._kind, where, message,
                            held_text(held))

    @property
    def total(self) -> int:
        return sum(self.counts.values())


# -- rule: reconnect, log once, no flood ------------------------------------------------

class ConnectionLog:
    """The log lines of a source that may come and go.

    :meth:`lost` writes one warning when the source goes away (or cannot be
    reached the first time) and only rate-limited debug lines for every retry
    after it; :meth:`up` writes one info line when it is back.
    """

    def __init__(
        self,
        logger: logging.Logger,
        what: str,
        *,
        interval: float = LOG_INTERVAL,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._log = logger
        self._what = what
        self._limiter = LogLimiter(interval, clock)
        self.connected = False
        self._warned = False
        self.failures = 0
        """Failed attempts since the source was last up."""

    def up(self) -> None:
        if not self.connected:
            if self._warned:
                self._log.info("%s is back", self._what)
            else:
                self._log.info("%s connected", self._what)
        self.connected = True
        self._warned = False
        self.failures = 0

    def lost(self, reason: str) -> None:
        self.failures += 1
        was_connected, self.connected = self.connected, False
        if was_connected or not self._warned:
            self._warned = True
            self._log.warning("%s %s: %s; retrying quietly", self._what,
                              "lost" if was_connected else "cannot be reached", reason)
            return
        held = self._limiter.allow("retry")
        if held is not None:
            self._log.debug("%s still unreachable (%d attempts): %s%s", self._what,
                            self.failures, reason, held_text(held))


DEFAULT_RETRY: Final = CONFIG_RETRY
"""Seconds before the first new attempt after a source went away (then doubling)."""
RETRY_LIMIT: Final = 10.0
"""The longest pause between two attempts."""


# -- rule: two sources for one radio ---------------------------------------------------

class SourceHub:
    """Every source's events pass here on their way to one sink.

    The newest event wins: each is passed on as it comes, whatever source sent
    it.  When a radio (or a station's focus) hears from a second source, one
    info line names both, once per pair; the :attr:`overlaps` count keeps the
    rest.  A sink that raises is logged (rate-limited) and counted; the source
    that sent the event never sees the error.
    """

    def __init__(
        self,
        sink: SourceSink,
        logger: logging.Logger | None = None,
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self._sink = sink
        self._log = logger or logging.getLogger("moas_gui.sources")
        self._limiter = LogLimiter(LOG_INTERVAL, clock)
        self._pairs = CrowdLimiter(LOG_INTERVAL, clock)
        self._origin: dict[tuple[object, ...], str] = {}
        self._told: set[tuple[tuple[object, ...], frozenset[str]]] = set()
        self.delivered = 0
        self.overlaps = 0
        self.sink_errors = 0

    def __call__(self, event: SourceEvent) -> None:
        key = event_key(event)
        before = self._origin.get(key)
        if before is not None and before != event.origin:
            self.overlaps += 1
            pair = (key[1:], frozenset((before, event.origin)))
            if pair not in self._told and len(self._told) < 1024:
                self._told.add(pair)
                # an origin carries a datagram's StationName: a crowd of them is one kind
                held = self._pairs.allow("two sources", pair)
                if held is not None:
                    self._log.info(
                        "Station %d %sis reported by two sources, %s and %s: the newest "
                        "wins%s", event.station,
                        f"radio {event.radio} " if isinstance(event, (FrequencyReport,
                                                                      RunOrSearch))
                        else "", before, event.origin,
                        held_text(held, "more pairs of sources"))
        self._origin[key] = event.origin
        try:
            self._sink(event)
        except Exception:  # noqa: BLE001 - a source never stops on its sink
            self.sink_errors += 1
            if self._limiter.allow(("sink", type(event).__name__)) is not None:
                self._log.exception("A source event could not be acted on: %r", event)
            return
        self.delivered += 1

    def forget(self, origin: str) -> None:
        """A source has stopped: nothing it reported counts as an overlap any more."""
        for key in [k for k, o in self._origin.items() if o == origin]:
            del self._origin[key]


__all__ = [
    "DEFAULT_RETRY",
    "LOG_INTERVAL",
    "MAX_KHZ",
    "RETRY_LIMIT",
    "ActiveRadio",
    "AuxAntenna",
    "BadInputLog",
    "Bursts",
    "ConnectionLog",
    "FocusRadio",
    "FrequencyReport",
    "RunOrSearch",
    "Source",
    "SourceEvent",
    "SourceHub",
    "SourceSink",
    "check_khz",
    "event_key",
]
