"""Hy-Gain DCU-1 / DCU-1X: commands only, no position readback.

Bytes (4800 baud, 8N1)::

    AP1ddd;    load bearing ddd (000-359), does not start the turn
    AM1;       start turning to the loaded bearing
    AS1;       stop
    ;          reset (treated as a stop by the emulator)

The DCU-1 never answers.  So this codec works out when a turn should be
over, at :data:`ASSUMED_SPEED` along the rotator's path (Hy-Gain rotators
have their end stop at south, so 170 to 190 is the long way round), and
then reports the commanded bearing once, marked as estimated.  A stop in the
middle of a turn reports where the antenna should be by then.
"""

from __future__ import annotations

from dataclasses import dataclass

from .base import (
    DEFAULT_SPEED,
    Garbage,
    Heading,
    ModelInfo,
    Output,
    Send,
    SerialSettings,
    check_range,
    whole,
)

HYGAIN_STOP = 180.0
"""Compass bearing of the end stop of a Hy-Gain rotator."""

ASSUMED_SPEED = DEFAULT_SPEED
"""Degrees per second the driver assumes for a DCU-1 (about a minute per turn)."""

SETTLE = 1.0
"""Seconds added to every estimated turn: the motor starts, the brake engages."""

LOAD_PAUSE = 0.5
"""Seconds between ``AP1ddd;`` and ``AM1;`` (what Hamlib waits, and a DCU-1 is happy with)."""

INFO = ModelInfo(
    number=1,
    name="DCU1",
    description="Hy-Gain DCU-1 (commands only, no position readback)",
    serial=SerialSettings(4800),
    minimum=0.0,
    maximum=360.0,
    write_gap=0.5,
    reply_timeout=0.0,
    has_readback=False,
)


def to_travel(bearing: float, stop: float = HYGAIN_STOP) -> float:
    """Degrees clockwise from the counter-clockwise stop for a compass ``bearing``."""
    return (bearing - stop) % 360.0


def to_bearing(travel: float, stop: float = HYGAIN_STOP) -> float:
    """The compass bearing of a position ``travel`` degrees from the counter-clockwise stop."""
    return (travel + stop) % 360.0


def bearing_command(degrees: float) -> bytes:
    """``AP1ddd;``: whole degrees; 360 is sent as 000 (as Hamlib does for the DCU-1)."""
    value = whole(degrees) % 360
    return b"AP1%03d;" % value


@dataclass(frozen=True, slots=True)
class _Turn:
    start: float
    """When the antenna starts moving (after the load pause)."""
    origin: float | None
    """Travel position at the start, None when nobody knew where the antenna was."""
    target: float
    """Commanded bearing."""
    arrival: float
    """When the turn should be over, settling included."""


class DCU1Codec:
    """The driver's side of a DCU-1; see the module docstring."""

    info = INFO

    def __init__(self, speed: float = ASSUMED_SPEED, settle: float = SETTLE) -> None:
        self._speed = speed
        self._settle = settle
        self._known: float | None = None
        """Bearing the antenna is believed to be at when standing still (None: unknown)."""
        self._turn: _Turn | None = None

    def opening(self) -> list[Send]:
        return []

    def poll(self, now: float) -> list[Output]:
        return []

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        target = float(whole(degrees) % 360)
        origin = self._travel_now(now)
        start = now + LOAD_PAUSE
        if origin is None:
            duration = 360.0 / self._speed  # could be anywhere: allow a full turn
        else:
            duration = abs(to_travel(target) - origin) / self._speed
        self._turn = _Turn(start, origin, target, start + duration + self._settle)
        return [Send(bearing_command(target), pause=LOAD_PAUSE), Send(b"AM1;")]

    def stop(self, now: float) -> list[Output]:
        out: list[Output] = [Send(b"AS1;")]
        if self._turn is not None:
            travel = self._travel_now(now)
            self._turn = None
            self._known = None if travel is None else to_bearing(travel)
            if self._known is not None:
                out.append(Heading(float(whole(self._known) % 360), estimated=True))
        return out

    def receive(self, data: bytes, now: float) -> list[Output]:
        if not data:
            return []
        return [Garbage(bytes(data), "a DCU-1 never sends anything")]

    def deadline(self) -> float | None:
        return None if self._turn is None else self._turn.arrival

    def tick(self, now: float) -> list[Output]:
        if self._turn is None or now < self._turn.arrival:
            return []
        target = self._turn.target
        self._turn = None
        self._known = target
        return [Heading(target, estimated=True)]

    def _travel_now(self, now: float) -> float | None:
        """Estimated travel position at ``now``, or None when nobody knows."""
        turn = self._turn
        if turn is None:
            return None if self._known is None else to_travel(self._known)
        if turn.origin is None:
            return None
        goal = to_travel(turn.target)
        moved = max(0.0, now - turn.start) * self._speed
        if moved >= abs(goal - turn.origin):
            return goal
        return turn.origin + moved if goal > turn.origin else turn.origin - moved


__all__ = ["HYGAIN_STOP", "INFO", "DCU1Codec", "bearing_command", "to_bearing", "to_travel"]
