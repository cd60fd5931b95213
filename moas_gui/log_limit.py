"""Keeping a repeating fault from writing the log without bound.

A :class:`LogLimiter` lets one line per key through every ``interval``
seconds (or ``burst`` lines) and counts the ones it holds back, so the next
line that goes through can say how many were left out (:func:`held_text`)::

    held = limiter.allow(("refused", host))
    if held is not None:
        log.warning("Refused a client from %s%s", host, held_text(held))
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Final

LOG_INTERVAL: Final = 60.0
"""Seconds between two lines about the same thing."""


class LogLimiter:
    """``burst`` log lines (one unless told) per key every ``interval`` seconds; the
    rest are counted.

    At most :attr:`MAX_KEYS` keys are remembered; when more arrive, all are
    forgotten at once (the memory stays bounded whoever sends what)."""

    MAX_KEYS = 1024

    def __init__(
        self, interval: float = LOG_INTERVAL, clock: Callable[[], float] = time.monotonic,
        burst: int = 1,
    ) -> None:
        self._interval = interval
        self._clock = clock
        self._burst = burst
        self._next: dict[object, float] = {}
        """When each key's present stretch of ``interval`` seconds ends."""
        self._used: dict[object, int] = {}
        self._held: dict[object, int] = {}

    def allow(self, key: object) -> int | None:
        """``None`` to stay quiet, else the number of lines held back since the last one."""
        now = self._clock()
        if now < self._next.get(key, float("-inf")):
            used = self._used.get(key, 1)
            if used < self._burst:
                self._used[key] = used + 1
                return 0
            self._held[key] = self._held.get(key, 0) + 1
            return None
        if len(self._next) >= self.MAX_KEYS:
            self._next.clear()
            self._used.clear()
            self._held.clear()
        self._next[key] = now + self._interval
        self._used[key] = 1
        return self._held.pop(key, 0)


def held_text(held: int, what: str = "more like it") -> str:
    """`` (N more like it since the last such line)``, or nothing when none were held."""
    return f" ({held:,} {what} since the last such line)" if held else ""


__all__ = ["LOG_INTERVAL", "LogLimiter", "held_text"]
