"""A rotator link's TCP connection, made again whenever it ends.

Every rotator peer on TCP (a Rotator Genius, a rotctld, a MOAS Rotator
program) is served the same way: connect, run a session until the connection
ends, pause (``Timing.reconnect``: 0.5 s, 1 s, 2 s ... up to
``reconnect_max``; from the first again after a connection that was made),
connect again.  Each outage is one warning: the session's line for a
connection lost, or "cannot connect" for a peer never reached; the attempts
after it are logged at debug level until it answers.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable

from moas_gui.retry import keep_trying

from .base import Timing

Session = Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]


async def keep_connected(
    host: str, port: int, session: Session, timing: Timing, *,
    where: str, log: logging.Logger, limit: int = 2**16,
) -> None:
    """Run ``session`` on a connection to ``host``:``port``, for ever (until cancelled).

    ``where`` names the peer at the start of log lines; ``limit`` is the
    stream's line limit.
    """
    failures = 0

    async def attempt() -> bool:
        nonlocal failures
        try:
            reader, writer = await asyncio.wait_for(
                asyncio.open_connection(host, port, limit=limit), timing.connect_timeout
            )
        except (OSError, TimeoutError) as exc:
            level = logging.WARNING if failures == 0 else logging.DEBUG
            log.log(level, "%s: cannot connect (%s); will keep trying", where,
                    exc or "timed out")
            failures += 1
            return False
        failures = 0
        await session(reader, writer)
        failures = 1  # the session logged the loss: this outage's failed attempts go to debug
        return True

    await keep_trying(attempt, timing.reconnect, pause=timing.clock.sleep)


__all__ = ["Session", "keep_connected"]
