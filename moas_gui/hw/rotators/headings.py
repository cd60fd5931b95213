"""Heading rules: where a rotator points, and which way it turns.

Everything that decides a rotator's path lives in this file, as plain
functions over numbers (no clock, no I/O).  Words used throughout:

heading
    A compass bearing in degrees, ``0 <= heading < 360``, clockwise from north.
position
    Degrees clockwise from the rotator's counterclockwise stop (the
    ``CCWLimit``).  A rotator with ``Rotation`` 450 has positions 0..450, so
    positions above 360 are the overlap.  This is also the number appendix B
    puts in ``ROTATE <rotator> <degrees>`` ("degrees clockwise from the
    counterclockwise stop").  For a rotator without ends (see ``bounded``) the
    position is any real number: it just counts turns.
travel
    A rotator's ``CCWLimit``, ``Rotation`` and ``HasStop``.
bounded
    The rotator has ends it cannot turn past: it has a stop (``HasStop``), or
    its ``Rotation`` is not exactly one full turn (a side mount limited to 300
    degrees, or a 450 degree rotator with overlap).  A bounded rotator never
    turns through its stop; among the positions that give the wanted heading
    it takes the one nearest to where it is.  An unbounded rotator (360
    degrees, no stop) turns the shorter way; a half turn goes clockwise.
offset
    An antenna's ``Offset``: the antenna points ``offset`` degrees clockwise
    of the rotator's heading (a yagi mounted at right angles has offset 90).

A request for a heading outside a bounded rotator's travel is clamped to the
end of travel nearer (in compass degrees) to that heading; on a tie, to the
end nearer to where the rotator is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

EPSILON = 1e-9
FULL_TURN = 360.0


def normalize(bearing: float) -> float:
    """``bearing`` folded into ``0 <= result < 360``."""
    result = math.fmod(bearing, FULL_TURN)
    if result < 0:
        result += FULL_TURN
    if result >= FULL_TURN - EPSILON:
        return 0.0
    return result


def angular_distance(a: float, b: float) -> float:
    """The smaller angle between two bearings, 0..180."""
    difference = abs(normalize(a) - normalize(b))
    return min(difference, FULL_TURN - difference)


def whole_heading(bearing: float) -> int:
    """A bearing rounded to a whole degree, 0..359 (359.6 becomes 0)."""
    return round(normalize(bearing)) % 360


def antenna_heading(rotator_heading: float, offset: float) -> float:
    """Where an antenna mounted ``offset`` degrees clockwise on the mast points."""
    return normalize(rotator_heading + offset)


def rotator_heading_for(antenna_heading_wanted: float, offset: float) -> float:
    """The rotator heading that makes an antenna with ``offset`` point as wanted."""
    return normalize(antenna_heading_wanted - offset)


@dataclass(frozen=True, slots=True)
class Travel:
    """How far a rotator can turn: from ``ccw_limit`` clockwise by ``rotation``."""

    ccw_limit: float = 0.0
    rotation: float = FULL_TURN
    has_stop: bool = False

    def __post_init__(self) -> None:
        if not (0 < self.rotation <= 2 * FULL_TURN):
            raise ValueError(
                f"Rotation must be more than 0 and at most 720 degrees, not {self.rotation:g}"
            )

    @property
    def bounded(self) -> bool:
        return self.has_stop or abs(self.rotation - FULL_TURN) > EPSILON

    def heading_at(self, position: float) -> float:
        """The compass heading of ``position``."""
        return normalize(self.ccw_limit + position)

    def positions_of(self, heading: float) -> tuple[float, ...]:
        """Every position of a bounded travel that points at ``heading``, lowest first.

        Empty when the heading is outside the travel.  For an unbounded travel
        this gives the one position in ``0 <= p < 360``.
        """
        first = normalize(heading - self.ccw_limit)
        if not self.bounded:
            return (first,)
        found: list[float] = []
        position = first
        while position <= self.rotation + EPSILON:
            found.append(min(position, self.rotation))
            position += FULL_TURN
        return tuple(found)

    def reaches(self, heading: float) -> bool:
        return bool(self.positions_of(heading))

    def clamp(self, position: float) -> float:
        """``position`` kept inside a bounded travel; unbounded positions pass."""
        if not self.bounded:
            return position
        return min(max(position, 0.0), self.rotation)

    def nearest_position(self, heading: float, near: float | None = None) -> float:
        """The position for ``heading``: of several, the one nearest ``near``
        (or the lowest); outside the travel, the nearer end (see module notes)."""
        if not self.bounded:
            first = self.positions_of(heading)[0]
            if near is None:
                return first
            return near + _signed_delta(self.heading_at(near), heading)
        candidates = self.positions_of(heading)
        if not candidates:
            candidates = self._nearest_ends(heading)
        if near is None:
            return candidates[0]
        return min(candidates, key=lambda p: (abs(p - near), p))

    def _nearest_ends(self, heading: float) -> tuple[float, ...]:
        to_ccw = angular_distance(heading, self.heading_at(0.0))
        to_cw = angular_distance(heading, self.heading_at(self.rotation))
        if abs(to_ccw - to_cw) <= EPSILON:
            return (0.0, self.rotation)
        return (0.0,) if to_ccw < to_cw else (self.rotation,)


def _signed_delta(from_heading: float, to_heading: float) -> float:
    """The shorter signed turn between two headings; a half turn is +180 (clockwise)."""
    delta = normalize(to_heading - from_heading)
    return delta if delta <= 180.0 + EPSILON else delta - FULL_TURN


@dataclass(frozen=True, slots=True)
class Turn:
    """A planned turn from one position to another (positions as in the module notes)."""

    start: float
    end: float
    clamped: bool = False
    """True when the wanted heading was outside the travel and ``end`` is an end of travel."""

    @property
    def degrees(self) -> float:
        return abs(self.end - self.start)

    @property
    def direction(self) -> int:
        """+1 clockwise, -1 counterclockwise, 0 no movement."""
        if self.degrees <= EPSILON:
            return 0
        return 1 if self.end > self.start else -1

    def position_after(self, degrees_turned: float) -> float:
        """Where the rotator is after turning ``degrees_turned`` along this turn."""
        return self.start + self.direction * min(max(degrees_turned, 0.0), self.degrees)


def plan_turn(travel: Travel, current: float, heading: float) -> Turn:
    """The turn from position ``current`` to compass ``heading``.

    Bounded: ends at the reachable position nearest ``current`` (so it never
    crosses the stop, and uses the overlap when that is shorter); a heading
    outside the travel ends at the nearer end of travel.  Unbounded: the
    shorter way round.
    """
    if not travel.bounded:
        return Turn(current, current + _signed_delta(travel.heading_at(current), heading))
    start = travel.clamp(current)
    clamped = not travel.reaches(heading)
    return Turn(start, travel.nearest_position(heading, near=start), clamped)


def window_base(travel: Travel, low: float) -> float:
    """Where position 0 sits on an unwrapped azimuth scale whose lowest value is
    ``low`` (Hamlib's ``min_az``): the first of ``CCWLimit + k*360`` not below it.

    On such a scale (rotctld's, for example) 0 is north, values run past 360
    for the overlap and below 0 for a stop west of north: a rotator with its
    stop at south on a -180..180 scale has base -180, so west is -90.
    """
    base = travel.ccw_limit - FULL_TURN * math.floor((travel.ccw_limit - low) / FULL_TURN)
    return base if base >= low - EPSILON else base + FULL_TURN


def azimuth_of(travel: Travel, position: float, low: float, high: float,
               near: float | None = None) -> float:
    """``position`` written on the unwrapped scale ``low..high`` (clamped into it).

    For an unbounded rotator ``near`` is the azimuth last read on that scale:
    the daemon moves along its scale, so the value that turns the shorter way
    is the one within half a turn of ``near`` (when the scale has it).
    """
    if travel.bounded:
        azimuth = window_base(travel, low) + position
    elif near is not None:
        azimuth = near + _signed_delta(normalize(near), travel.heading_at(position))
    else:
        azimuth = normalize(travel.heading_at(position))
    others = [azimuth - FULL_TURN, azimuth + FULL_TURN]
    if near is not None:
        others.sort(key=lambda other: abs(other - near))
    for candidate in (azimuth, *others):
        if low - EPSILON <= candidate <= high + EPSILON:
            return candidate
    return min(max(azimuth, low), high)


def position_of(travel: Travel, azimuth: float, low: float, near: float | None = None) -> float:
    """The position an unwrapped ``azimuth`` (scale starting at ``low``) stands for."""
    if travel.bounded:
        position = azimuth - window_base(travel, low)
        if -EPSILON <= position <= travel.rotation + EPSILON:
            return travel.clamp(position)
    return travel.nearest_position(normalize(azimuth), near=near)


def closest_direction(directions: tuple[float, ...], heading: float) -> float | None:
    """Of an electrical rotator's fixed directions, the one closest to ``heading``
    (ties: the lowest); ``None`` when there are none."""
    if not directions:
        return None
    return min(directions, key=lambda d: (round(angular_distance(d, heading), 9), normalize(d)))


__all__ = [
    "Travel", "Turn", "angular_distance", "antenna_heading", "azimuth_of", "closest_direction",
    "normalize", "plan_turn", "position_of", "rotator_heading_for", "whole_heading",
    "window_base",
]
