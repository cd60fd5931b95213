"""The Electrical rotator (5.15, 6.9): a switched array such as a four-square.

Nothing moves.  ``rotate(heading)`` calls the ``select_direction`` callback
given to the manager (the server passes the engine's
``select_direction(rotator_id, heading)``, which selects the antenna of the
system whose offset is closest), and the rotator's heading becomes the
direction of that antenna: of the offsets of the antennas configured with
this rotator, the one closest to the request.  When the selection changes by
other means (a button), the server tells the manager with
``note_direction``.  ``stop`` has nothing to stop and succeeds.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

from moas_gui.config.model import Rotator

from .base import Publish, RotatorDriver, RotatorError, RotatorStatus
from .headings import Travel, closest_direction, normalize, whole_heading

log = logging.getLogger(__name__)

SelectDirection = Callable[[int, int], object]
"""``(rotator_id, heading) -> anything``; raising refuses the request."""


class ElectricalRotator(RotatorDriver):
    def __init__(
        self,
        rotator: Rotator,
        travel: Travel,
        publish: Publish,
        directions: tuple[float, ...],
        select_direction: SelectDirection | None,
    ) -> None:
        super().__init__(rotator, travel, publish)
        self.directions = tuple(sorted({normalize(d) for d in directions}))
        self.select_direction = select_direction

    async def start(self) -> None:
        if not self.directions:
            log.warning(
                "%s is Electrical but no antenna names it as its Rotator; "
                "a request will be passed on as it is", self.title,
            )
        self._set(RotatorStatus(online=True))

    def check_ready(self) -> None:
        if self.select_direction is None:
            raise self._unavailable("is Electrical but the server gave no way to select antennas")

    async def rotate(self, heading: float) -> None:
        self.turn(heading)

    def turn(self, heading: float) -> None:
        """Select the direction now (nothing here waits)."""
        self.check_ready()
        assert self.select_direction is not None
        chosen = closest_direction(self.directions, heading)
        try:
            self.select_direction(self.rotator.id, whole_heading(heading))
        except RotatorError:
            raise
        except Exception as exc:  # the engine's refusal, passed on as a sentence
            log.info("%s: selecting direction %.0f refused: %s", self.name, heading, exc)
            raise self._unavailable(f"cannot point at {heading:.0f} degrees: {exc}") from exc
        self.note_direction(heading if chosen is None else chosen)

    async def stop(self) -> None:
        return None

    def note_direction(self, heading: float) -> None:
        """The array now points at ``heading`` (whatever made it so)."""
        self._set(RotatorStatus(heading=normalize(heading), online=True))


__all__ = ["ElectricalRotator", "SelectDirection"]
