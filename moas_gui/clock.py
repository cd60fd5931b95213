"""The clock that timed work reads and waits on, and a fake one for tests.

Every part that waits (a Test rotator's turn, a stall timer, a restart's
back-off, an emulated switch's timers) asks a :class:`Clock` rather than
asyncio directly, so
that a test can hand it a :class:`FakeClock` and move time on at once
instead of waiting for it.  :data:`LOOP_CLOCK`, the running event loop's own
clock, is everyone's default.
"""

from __future__ import annotations

import asyncio
import contextlib
import heapq
import itertools
from collections.abc import AsyncIterator, Callable
from typing import Protocol


class Timer(Protocol):
    """A call to come, which can be called off."""

    def cancel(self) -> None: ...


class Clock(Protocol):
    """Seconds that only go forward."""

    def now(self) -> float:
        """The time now, in seconds (any origin)."""

    async def sleep(self, seconds: float) -> None:
        """Returns once ``seconds`` have passed on this clock."""

    def call_later(self, seconds: float, callback: Callable[[], None]) -> Timer:
        """Calls ``callback`` once ``seconds`` have passed on this clock."""


class LoopClock:
    """The running event loop's clock (monotonic), and ``asyncio.sleep``."""

    def now(self) -> float:
        return asyncio.get_running_loop().time()

    async def sleep(self, seconds: float) -> None:
        await asyncio.sleep(seconds)

    def call_later(self, seconds: float, callback: Callable[[], None]) -> Timer:
        return asyncio.get_running_loop().call_later(seconds, callback)


LOOP_CLOCK: Clock = LoopClock()


@contextlib.asynccontextmanager
async def timeout(clock: Clock, seconds: float) -> AsyncIterator[None]:
    """``asyncio.timeout(seconds)`` on ``clock``: once ``seconds`` have passed on it, the
    block's wait is cancelled and :class:`TimeoutError` raised."""
    loop = asyncio.get_running_loop()
    async with asyncio.timeout(None) as limit:
        timer = clock.call_later(seconds, lambda: limit.reschedule(loop.time()))
        try:
            yield
        finally:
            timer.cancel()


class FakeClock:
    """Time that moves only when a test says so, and then at once.

    :meth:`sleep` waits until :meth:`advance` has moved the time past its end,
    and a :meth:`call_later` callback is called then; sleepers and callbacks
    come in the order of their ends (then of their calls), and each one gets
    to run before time moves on to the next: the same steps as in real time,
    in no time.
    """

    SETTLE = 20
    """Event-loop turns given to woken tasks before time moves on."""

    def __init__(self, start: float = 0.0) -> None:
        self._now = start
        self._sleepers: list[tuple[float, int, asyncio.Future[None] | _FakeTimer]] = []
        self._order = itertools.count()

    def now(self) -> float:
        return self._now

    @property
    def sleepers(self) -> int:
        """How many tasks are waiting on this clock."""
        return sum(1 for _, _, waiter in self._sleepers
                   if isinstance(waiter, asyncio.Future) and not waiter.done())

    async def sleep(self, seconds: float) -> None:
        if seconds <= 0:
            await asyncio.sleep(0)
            return
        future: asyncio.Future[None] = asyncio.get_running_loop().create_future()
        heapq.heappush(self._sleepers, (self._now + seconds, next(self._order), future))
        await future

    def call_later(self, seconds: float, callback: Callable[[], None]) -> Timer:
        timer = _FakeTimer(callback)
        heapq.heappush(self._sleepers, (self._now + max(seconds, 0.0), next(self._order), timer))
        return timer

    async def advance(self, seconds: float) -> None:
        """Moves time on by ``seconds``, waking every sleeper due on the way."""
        end = self._now + seconds
        await self._settle()
        while self._sleepers and self._sleepers[0][0] <= end:
            due, _, waiter = heapq.heappop(self._sleepers)
            self._now = max(self._now, due)
            if isinstance(waiter, _FakeTimer):
                if not waiter.cancelled:
                    waiter.callback()
                    await self._settle()
            elif not waiter.done():
                waiter.set_result(None)
                await self._settle()
        self._now = max(self._now, end)
        await self._settle()

    async def _settle(self) -> None:
        for _ in range(self.SETTLE):
            await asyncio.sleep(0)


class _FakeTimer:
    __slots__ = ("callback", "cancelled")

    def __init__(self, callback: Callable[[], None]) -> None:
        self.callback = callback
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


__all__ = ["LOOP_CLOCK", "Clock", "FakeClock", "LoopClock", "Timer", "timeout"]
