"""Trying again after a failure: the back-off every link uses, and its loop.

A link to a peer (the switch's serial port, a rotator controller, the MOAS
Rotator program, a moas-gui server seen by a client) is an *attempt* run again
and again: connect, serve until the connection ends, pause, connect again.
The pauses grow by :class:`Backoff`; an attempt that got through (the peer
answered) starts them again from the first.
"""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable, Iterator
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Backoff:
    """Pauses between attempts: ``first``, then times ``factor`` each time, at most ``most``."""

    first: float = 0.25
    factor: float = 2.0
    most: float = 5.0

    def delays(self) -> Iterator[float]:
        """The pauses, from the first, for ever."""
        delay = self.first
        while True:
            yield delay
            delay = min(delay * self.factor, self.most)


class Pauses:
    """A :class:`Backoff`'s pauses one at a time, for a loop that waits in its own way:
    :meth:`next` gives the next pause, :meth:`reset` (after a success) starts again."""

    def __init__(self, backoff: Backoff) -> None:
        self.backoff = backoff
        self._delays = backoff.delays()

    def next(self) -> float:
        return next(self._delays)

    def reset(self) -> None:
        self._delays = self.backoff.delays()


Pause = Callable[[float], Awaitable[None]]
"""Waits the given seconds (``asyncio.sleep``, or a clock's ``sleep`` in tests)."""


async def keep_trying(
    attempt: Callable[[], Awaitable[bool]],
    backoff: Backoff,
    *,
    pause: Pause = asyncio.sleep,
    stopped: Callable[[], bool] = lambda: False,
) -> None:
    """Run ``attempt()`` again and again, pausing between attempts.

    ``attempt`` returns True when it got through to its peer (the pauses then
    start again from the first).  The loop ends when ``stopped()`` is true
    after an attempt or a pause, or when its task is cancelled.
    """
    delays = backoff.delays()
    while not stopped():
        if await attempt():
            delays = backoff.delays()
        if stopped():
            return
        await pause(next(delays))


__all__ = ["Backoff", "Pause", "Pauses", "keep_trying"]
