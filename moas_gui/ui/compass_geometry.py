"""The compass's arithmetic, with no Qt: where a click points, where the
rotator cannot go, and how an antenna's offset moves both.

Headings are compass degrees, clockwise from north, ``0 <= h < 360``.  Screen
coordinates grow right and down, as in Qt.  Words as in the manual (6.9):

travel
    ``CCWLimit`` (the counterclockwise stop's heading) and ``Rotation`` (how
    far it turns clockwise from there).  Less than 360 leaves a *dead zone* it
    cannot point into; more than 360 gives an *overlap* it can reach two ways.
    ``HasStop`` with a full turn puts a stop at ``CCWLimit`` it never crosses.
offset
    An antenna mounted ``offset`` degrees clockwise on the mast points at the
    rotator's heading plus the offset.  The compass shows the antenna's
    direction; the ``rotate`` request carries the rotator's heading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "TravelMarks",
    "antenna_heading",
    "heading_at",
    "normalize",
    "point_at",
    "qt_arc",
    "rotator_heading",
    "travel_marks",
]

FULL_TURN = 360.0
DEAD_CENTRE = 6.0
"""Clicks closer than this many pixels to the centre point nowhere."""


def normalize(bearing: float) -> float:
    """``bearing`` folded into ``0 <= result < 360``."""
    result = math.fmod(bearing, FULL_TURN)
    if result < 0:
        result += FULL_TURN
    return 0.0 if result >= FULL_TURN - 1e-9 else result


def heading_at(cx: float, cy: float, x: float, y: float) -> float | None:
    """The heading from the centre ``(cx, cy)`` towards the point ``(x, y)``;
    None at the very centre, where no direction is meant."""
    dx, dy = x - cx, y - cy
    if math.hypot(dx, dy) < DEAD_CENTRE:
        return None
    return normalize(math.degrees(math.atan2(dx, -dy)))


def point_at(cx: float, cy: float, radius: float, heading: float) -> tuple[float, float]:
    """The point ``radius`` away from the centre in the direction ``heading``."""
    angle = math.radians(heading)
    return cx + radius * math.sin(angle), cy - radius * math.cos(angle)


def antenna_heading(rotator_heading: float, offset: float) -> float:
    return normalize(rotator_heading + offset)


def rotator_heading(antenna_heading_wanted: float, offset: float) -> float:
    return normalize(antenna_heading_wanted - offset)


@dataclass(frozen=True, slots=True)
class TravelMarks:
    """What the compass draws for a rotator's travel, in antenna headings.

    Arcs are ``(start, span)``: from ``start`` clockwise over ``span`` degrees.
    """

    dead: tuple[float, float] | None = None
    overlap: tuple[float, float] | None = None
    stop: float | None = None


def travel_marks(ccw_limit: float | None, rotation: float | None, has_stop: bool,
                 offset: float = 0.0) -> TravelMarks:
    """The dead zone, overlap and stop of a travel (nothing when it is unknown)."""
    if ccw_limit is None or rotation is None or rotation <= 0:
        return TravelMarks()
    start = antenna_heading(ccw_limit, offset)
    if rotation < FULL_TURN:
        return TravelMarks(dead=(normalize(start + rotation), FULL_TURN - rotation), stop=start)
    overlap = None
    if rotation > FULL_TURN:
        overlap = (start, min(rotation - FULL_TURN, FULL_TURN))
    stop = start if has_stop or rotation > FULL_TURN else None
    return TravelMarks(overlap=overlap, stop=stop)


def qt_arc(start: float, span: float) -> tuple[int, int]:
    """A clockwise compass arc as Qt's ``(startAngle, spanAngle)`` in 1/16 degree
    (Qt counts counterclockwise from three o'clock)."""
    return round((90.0 - start) * 16), round(-span * 16)
