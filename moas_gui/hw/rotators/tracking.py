"""Is a turn still going?  For peers that only report where the rotator is.

The MOAS Rotator program and rotctld say where a rotator points, never
whether it moves or where it is going.  :class:`TurnTracker` infers both from
the heading reports and the clock (passed in):

- ``begin(target)``: a turn was asked for; moving, with that target.
- a report within ``tolerance`` of the target ends the turn (arrived: not
  moving from that moment, and coasting the last degrees does not count as
  movement; the same after ``end()``, a stop);
- no change of position for ``stall_after`` seconds ends it too (stopped short:
  a jam, a limit, a controller that gave up);
- without a turn of ours, a position that changed in the last
  ``moving_window`` seconds counts as moving (someone turns the rotator by
  hand at the controller).

Positions are compared by ``distance`` (plain difference for bounded
rotators, compass difference for unbounded ones).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

NOISE = 0.05
"""Changes smaller than this many degrees do not count as movement."""


def linear_distance(a: float, b: float) -> float:
    return abs(a - b)


@dataclass(slots=True)
class TurnTracker:
    tolerance: float
    stall_after: float
    moving_window: float
    distance: Callable[[float, float], float] = linear_distance
    target: float | None = None
    position: float | None = None
    last_change: float = float("-inf")
    settled: float | None = None
    """Where the last turn ended: coasting within ``tolerance`` of it is not movement."""

    def begin(self, target: float, now: float) -> None:
        self.target = target
        self.settled = None
        self.last_change = now
        if self.position is not None and self.distance(self.position, target) <= self.tolerance:
            self.target = None

    def end(self) -> None:
        """The turn is over (stopped): not moving from now on."""
        self.target = None
        self.settled = self.position
        self.last_change = float("-inf")

    def observe(self, position: float, now: float) -> str | None:
        """Take a report; returns ``"arrived"`` when it ends the turn."""
        changed = self.position is not None and self.distance(position, self.position) > NOISE
        coasting = self.settled is not None and \
            self.distance(position, self.settled) <= self.tolerance
        if changed and not coasting:
            self.settled = None
            self.last_change = now
        self.position = position
        if self.target is not None and self.distance(position, self.target) <= self.tolerance:
            self.end()
            return "arrived"
        return None

    def tick(self, now: float) -> str | None:
        """Call now and then; returns ``"stalled"`` when it ends the turn."""
        if self.target is not None and now - self.last_change > self.stall_after:
            self.target = None
            return "stalled"
        return None

    def moving(self, now: float) -> bool:
        return self.target is not None or now - self.last_change <= self.moving_window


__all__ = ["TurnTracker", "linear_distance"]
