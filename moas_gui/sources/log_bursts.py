"""A line that an outside party can repeat at will, written once a minute with a count.

A logger alternating its transmit focus between two radios would write one Info line a
change (half a million in 45 s).  :class:`BurstLog` writes the first line of a key at
once; the lines of that key in the next :data:`~moas_gui.log_limit.LOG_INTERVAL`
seconds are held and counted, and when the minute ends with some held, the last of them
is written with the count, so the log still ends on what is true now::

    09:00:01 Station 1: transmit focus on radio 2 (N1MM OP-PC (10.0.0.5))
    09:01:01 Station 1: transmit focus on radio 1 (N1MM OP-PC (10.0.0.5)) (the last of
             542,009 such lines since 09:00:01, held back)

A flood that goes on writes one line a minute; a quiet key is forgotten after its
minute.  The minute's end is a timer on the running event loop; without one (a
caller outside any loop) the held lines come with the next line after the minute.
At most :attr:`BurstLog.MAX_KEYS` keys are remembered (the held ones are written and
all forgotten when more arrive).

:class:`CrowdLimiter` is for lines about one sender of datagrams (whose address costs
nothing to forge): one line a minute per sender and kind, and at most
:data:`CROWD_LINES` a minute per kind from all senders together.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Final

from moas_gui.log_limit import LOG_INTERVAL, LogLimiter

__all__ = ["CROWD_LINES", "BurstLog", "CrowdLimiter"]

CROWD_LINES: Final = 10
"""Lines a minute about one kind of trouble, all senders together."""


class CrowdLimiter:
    """One line a minute per ``(kind, sender)``, at most ``crowd`` a minute per kind.

    :meth:`allow` answers as :meth:`~moas_gui.log_limit.LogLimiter.allow` does:
    ``None`` to stay quiet, else how many lines were left out (of that sender since its
    last line, and of the kind while its share was spent)."""

    def __init__(self, interval: float = LOG_INTERVAL,
                 clock: Callable[[], float] = time.monotonic, crowd: int = CROWD_LINES) -> None:
        self._each = LogLimiter(interval, clock)
        self._kinds = LogLimiter(interval, clock, burst=crowd)

    def allow(self, kind: object, sender: object) -> int | None:
        held = self._each.allow((kind, sender))
        if held is None:
            return None
        crowd = self._kinds.allow(kind)
        return None if crowd is None else held + crowd


@dataclass(slots=True)
class _Burst:
    """One key's burst: when it began, until when its lines are held, how many were
    held, the last one held, and the timer that ends it."""

    began: float
    """The wall-clock time of the first line (for the count's "since")."""
    until: float
    held: int = 0
    last: tuple[str, tuple[object, ...]] | None = None
    timer: asyncio.TimerHandle | None = field(default=None, repr=False)


class BurstLog:
    """See the module notes: one ``logger`` at one ``level``, many keys."""

    MAX_KEYS = 1024

    def __init__(self, logger: logging.Logger, level: int, *,
                 interval: float = LOG_INTERVAL,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._log = logger
        self._level = level
        self._interval = interval
        self._clock = clock
        self._bursts: dict[object, _Burst] = {}

    def line(self, key: object, message: str, *args: object) -> None:
        """Logs ``message % args`` now, or holds it as part of ``key``'s burst."""
        if not self._log.isEnabledFor(self._level):
            return
        now = self._clock()
        burst = self._bursts.get(key)
        if burst is not None and now >= burst.until:  # no timer came: the minute is over
            self._end(key)
            burst = self._bursts.get(key)
        if burst is None:
            if len(self._bursts) >= self.MAX_KEYS:
                self.close()
            self._bursts[key] = _Burst(time.time(), now + self._interval)
            self._log.log(self._level, message, *args)
            self._arm(key)
            return
        burst.held += 1
        burst.last = (message, args)

    def close(self) -> None:
        """Writes what is held and forgets every key."""
        for key in list(self._bursts):
            burst = self._bursts.pop(key)
            if burst.timer is not None:
                burst.timer.cancel()
            self._write_held(burst)

    def _arm(self, key: object) -> None:
        burst = self._bursts[key]
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            return
        burst.timer = loop.call_later(max(0.0, burst.until - self._clock()), self._end, key)

    def _end(self, key: object) -> None:
        """The minute of ``key`` is over: its held lines are written as one, and a new
        minute begins; a key with nothing held is forgotten."""
        burst = self._bursts.pop(key, None)
        if burst is None:
            return
        if burst.timer is not None:
            burst.timer.cancel()
        if self._write_held(burst):
            self._bursts[key] = _Burst(time.time(), self._clock() + self._interval)
            self._arm(key)

    def _write_held(self, burst: _Burst) -> bool:
        if not burst.held or burst.last is None:
            return False
        message, args = burst.last
        began = time.strftime("%H:%M:%S", time.localtime(burst.began))
        self._log.log(self._level, message + " (the last of %s such lines since %s, held back)",
                      *args, f"{burst.held:,}", began)
        return True
