"""The Test rotator (6.9): a simulated rotator that turns at ten degrees a second.

Motion is computed from the clock (``Timing.clock``), so a heading is exact whenever
it is read; while turning, the heading is published every ``Timing.test_tick``
seconds.  It starts at its counterclockwise stop and is always online.
"""

from __future__ import annotations

import asyncio
import logging

from moas_gui.aio import cancel_and_wait
from moas_gui.config.model import Rotator

from .base import Publish, RotatorDriver, RotatorStatus, Timing
from .headings import Travel, Turn, plan_turn

log = logging.getLogger(__name__)


class SimulatedRotator(RotatorDriver):
    def __init__(self, rotator: Rotator, travel: Travel, publish: Publish, timing: Timing) -> None:
        super().__init__(rotator, travel, publish)
        self.timing = timing
        self.position = 0.0
        """Where the rotator was when the current turn began (or is, when still)."""
        self._turn: Turn | None = None
        self._turn_began = 0.0
        self._task: asyncio.Task[None] | None = None

    async def start(self) -> None:
        self._set(RotatorStatus(heading=self.travel.heading_at(self.position), online=True))

    async def close(self) -> None:
        self._freeze()
        await self._cancel_task()

    def travel_position(self) -> float | None:
        return self.current_position()

    def current_position(self) -> float:
        if self._turn is None:
            return self.position
        elapsed = self.timing.clock.now() - self._turn_began
        return self._turn.position_after(elapsed * self.timing.test_speed)

    async def rotate(self, heading: float) -> None:
        current = self.current_position()
        turn = plan_turn(self.travel, current, heading)
        if turn.clamped:
            log.info(
                "%s cannot point at %.0f degrees; turning to the end of its travel (%.0f)",
                self.title, heading, self.travel.heading_at(turn.end),
            )
        self.position = turn.start
        if turn.direction == 0:
            self._turn = None
            self._publish_now()
            return
        self._turn = turn
        self._turn_began = self.timing.clock.now()
        self._publish_now()
        if self._task is None or self._task.done():
            self._task = asyncio.create_task(self._run(), name=f"{self.name} turning")

    async def stop(self) -> None:
        self._freeze()
        self._publish_now()

    def _freeze(self) -> None:
        if self._turn is not None:
            self.position = self.current_position()
            self._turn = None

    def _publish_now(self) -> None:
        turn = self._turn
        self._set(RotatorStatus(
            heading=self.travel.heading_at(self.current_position()),
            target=None if turn is None else self.travel.heading_at(turn.end),
            moving=turn is not None,
            online=True,
        ))

    async def _run(self) -> None:
        while self._turn is not None:
            await self.timing.clock.sleep(self.timing.test_tick)
            turn = self._turn
            if turn is None:
                break
            elapsed = self.timing.clock.now() - self._turn_began
            if elapsed * self.timing.test_speed >= turn.degrees:
                self.position = turn.end if self.travel.bounded else turn.end % 360.0
                self._turn = None
            self._publish_now()

    async def _cancel_task(self) -> None:
        task, self._task = self._task, None
        if task is not None and not task.done():
            await cancel_and_wait(task)


__all__ = ["SimulatedRotator"]
