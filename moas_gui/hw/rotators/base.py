"""What every kind of rotator shares: its status, the view clients see, the
driver seam, errors and timing.

Errors, by who caused them::

    RotatorError (code, sentence)     a rotate/stop request that cannot be served
      code "not_found"                no such rotator
      code "bad_request"              the heading is not a number
      code "unavailable"              the rotator exists but cannot turn now
                                      (offline, unusable configuration, refused)

    peer sent nonsense                never raised: a log line naming the
                                      rotator and the peer, and the link carries on
    peer went away                    never raised: the rotator shows
                                      ``online: false`` and the link reconnects

A driver is the one seam per kind (Test, Electrical, Serial, RotatorGenius,
Hamlib): ``start``, ``close``, ``rotate(heading)``, ``stop()``, and a
``publish`` callback it calls with a new :class:`RotatorStatus` whenever
something changes.
"""

from __future__ import annotations

import logging
import math
import os
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields, replace
from typing import Any

from moas_gui.clock import LOOP_CLOCK, Clock
from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.errors import RequestRefused
from moas_gui.retry import Backoff

from .headings import Travel, whole_heading

log = logging.getLogger(__name__)

ERROR_CODES = ("not_found", "unavailable", "bad_request")


class RotatorError(RequestRefused):
    """A rotate or stop request that cannot be served; ``code`` is a client-protocol code."""

    def __init__(self, code: str, message: str) -> None:
        if code not in ERROR_CODES:
            raise ValueError(f"unknown rotator error code {code!r}")
        super().__init__(message)
        self.code = code
        self.message = message


@dataclass(frozen=True, slots=True)
class RotatorStatus:
    """What a driver knows about its rotator, in compass degrees."""

    heading: float | None = None
    target: float | None = None
    moving: bool = False
    online: bool = False


@dataclass(frozen=True, slots=True)
class RotatorView:
    """One entry of the client protocol's ``rotators`` list.

    Besides the contract's fields it carries what a compass needs to draw the
    travel: ``long``, ``ccw_limit``, ``rotation``, ``has_stop`` and
    ``electrical`` (a switched array such as a 4-square)."""

    id: int
    short: str
    heading: int | None
    target: int | None
    moving: bool
    online: bool
    long: str = ""
    ccw_limit: int = 0
    rotation: int = 360
    has_stop: bool = False
    electrical: bool = False

    @classmethod
    def of(cls, rotator: Rotator, status: RotatorStatus) -> RotatorView:
        return cls(
            id=rotator.id,
            short=rotator.label,
            heading=None if status.heading is None else whole_heading(status.heading),
            target=None if status.target is None else whole_heading(status.target),
            moving=status.moving,
            online=status.online,
            long=rotator.long_name or rotator.label,
            ccw_limit=rotator.ccw_limit,
            rotation=rotator.rotation,
            has_stop=rotator.has_stop,
            electrical=rotator.control is RotatorControl.ELECTRICAL,
        )

    def to_json(self) -> dict[str, object]:
        return {
            "id": self.id, "short": self.short, "heading": self.heading,
            "target": self.target, "moving": self.moving, "online": self.online,
            "long": self.long, "ccw_limit": self.ccw_limit, "rotation": self.rotation,
            "has_stop": self.has_stop, "electrical": self.electrical,
        }


@dataclass(frozen=True, slots=True)
class Timing:
    """Every delay the rotator code uses, in seconds, and the clock it reads and waits
    on; tests pass shorter delays, or a :class:`~moas_gui.clock.FakeClock`."""

    reconnect_min: float = 0.5
    """First wait before reconnecting to a peer that went away; doubles each time."""
    reconnect_max: float = 10.0
    connect_timeout: float = 3.0
    reply_timeout: float = 2.0
    """How long a peer may take to answer one command before the link is reset."""
    test_speed: float = 10.0
    """Degrees per second of a Test rotator (6.9)."""
    test_tick: float = 0.2
    """How often a turning Test rotator reports its heading."""
    arrival_tolerance: float = 2.0
    """A turn is over when the rotator is this close to its target."""
    stall_polls: int = 4
    stall_min: float = 5.0
    """A turn is over, short of its target, when the heading has not changed for
    ``max(stall_polls * poll, stall_min)``."""
    restart_min: float = 1.0
    """First wait before starting again a local MOAS Rotator program that died."""
    restart_max: float = 30.0
    clock: Clock = LOOP_CLOCK

    @property
    def reconnect(self) -> Backoff:
        """The pauses between attempts to reach a peer that went away."""
        return Backoff(first=self.reconnect_min, factor=2.0, most=self.reconnect_max)


TIMING_HOOK = "MOAS_GUI_TEST_ROTATOR_TIMING"
"""The environment variable through which tests shorten a server process's rotator
delays (see docs/rotators.md, "Test hook")."""


def timing_from_hook(text: str) -> Timing:
    """:class:`Timing` with the delays ``text`` names changed: ``name=seconds`` pairs
    separated by commas (``reconnect_min=0.05,restart_min=0.1``).  Raises ValueError
    naming the pair that is not a known delay with a positive number."""
    changes: dict[str, Any] = {}  # float values, for the float fields named in `delays`
    delays = {f.name for f in fields(Timing) if f.name not in ("clock", "stall_polls")}
    for pair in filter(None, (p.strip() for p in text.split(","))):
        name, _, value = pair.partition("=")
        name = name.strip()
        if name not in delays:
            raise ValueError(f"{pair!r}: {name!r} is not a rotator delay "
                             f"(known: {', '.join(sorted(delays))})")
        try:
            seconds = float(value)
        except ValueError:
            raise ValueError(f"{pair!r}: {value.strip()!r} is not a number of seconds") from None
        if not 0 < seconds < math.inf:
            raise ValueError(f"{pair!r}: a delay must be a positive number of seconds")
        changes[name] = seconds
    return replace(Timing(), **changes)


def rotator_timing_from_environment(environ: Mapping[str, str] = os.environ) -> Timing | None:
    """The test hook's delays (:data:`TIMING_HOOK`), or None when it is not set.
    Raises ValueError naming the variable and the pair it cannot take."""
    text = environ.get(TIMING_HOOK)
    if not text:
        return None
    try:
        return timing_from_hook(text)
    except ValueError as exc:
        raise ValueError(f"{TIMING_HOOK}: {exc}") from None


def describe(rotator: Rotator) -> str:
    """``rotator 3 (Tribander)``: how log lines and errors name a rotator."""
    name = rotator.short_name or rotator.long_name
    return f"rotator {rotator.id} ({name})" if name else f"rotator {rotator.id}"


Publish = Callable[[RotatorStatus], None]


class RotatorDriver(ABC):
    """The seam for one kind of rotator."""

    def __init__(self, rotator: Rotator, travel: Travel, publish: Publish) -> None:
        self.rotator = rotator
        self.travel = travel
        self._publish = publish
        self._status = RotatorStatus()

    @property
    def name(self) -> str:
        return describe(self.rotator)

    @property
    def title(self) -> str:
        """The name at the start of a sentence: ``Rotator 3 (Tribander)``."""
        return self.name[:1].upper() + self.name[1:]

    @property
    def status(self) -> RotatorStatus:
        return self._status

    def _set(self, status: RotatorStatus) -> None:
        if status != self._status:
            self._status = status
            self._publish(status)

    def _unavailable(self, why: str) -> RotatorError:
        return RotatorError("unavailable", f"{self.title} {why}")

    def check_ready(self) -> None:
        """Raise ``RotatorError("unavailable", ...)`` when a request could not be
        served now (offline, unusable); cheap and synchronous."""

    def forget_turn(self) -> None:
        """Drop any turn waiting to be resumed (a stop was asked for)."""

    def travel_position(self) -> float | None:
        """Where on its travel the rotator is (degrees clockwise from the CCW
        stop, see :mod:`.headings`), or None when not known."""
        return None

    async def start(self) -> None:
        """Begin work (connect, poll); returns at once, never raises for a peer's fault."""

    async def close(self) -> None:
        """Stop all work and release sockets and tasks."""

    @abstractmethod
    async def rotate(self, heading: float) -> None:
        """Turn to compass ``heading`` (already checked to be a number 0..360)."""

    @abstractmethod
    async def stop(self) -> None:
        """Stop turning."""


class UnusableRotator(RotatorDriver):
    """A rotator whose configuration cannot work; says why on every request."""

    def __init__(self, rotator: Rotator, travel: Travel, publish: Publish, why: str) -> None:
        super().__init__(rotator, travel, publish)
        self.why = why

    def check_ready(self) -> None:
        raise self._unavailable(f"cannot be used: {self.why}")

    async def start(self) -> None:
        log.error("%s cannot be used: %s", self.title, self.why)

    async def rotate(self, heading: float) -> None:
        raise self._unavailable(f"cannot be used: {self.why}")

    async def stop(self) -> None:
        raise self._unavailable(f"cannot be used: {self.why}")


__all__ = [
    "ERROR_CODES",
    "TIMING_HOOK",
    "Publish",
    "RotatorDriver",
    "RotatorError",
    "RotatorStatus",
    "RotatorView",
    "Timing",
    "UnusableRotator",
    "describe",
    "rotator_timing_from_environment",
    "timing_from_hook",
]
