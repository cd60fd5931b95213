"""Keeping the event loop's own fault reports from flooding the log.

asyncio reports some faults through the loop's exception handler, and some
repeat without end: when the process runs out of file handles, every attempt
to accept a waiting client fails and is reported with its traceback, many
times a second.  :func:`guard_loop_faults` lets each kind of report through
once a minute (a :class:`~moas_gui.log_limit.LogLimiter`), with a count of those left
out; the accept failure becomes one short Warning line.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from typing import Any

from moas_gui.log_limit import LogLimiter, held_text

log = logging.getLogger(__name__)


def guard_loop_faults(loop: asyncio.AbstractEventLoop, limiter: LogLimiter) -> Callable[[], None]:
    """Installs the guard on ``loop``; returns the way to put the previous handler back."""
    previous = loop.get_exception_handler()

    def handler(loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        message = str(context.get("message", ""))
        exc = context.get("exception")
        held = limiter.allow((message, type(exc).__name__))
        if held is None:
            return
        if message.startswith("socket.accept() out of system resource"):
            log.warning("Cannot accept clients for now: %s (the system is out of file "
                        "handles or memory; trying again every second)%s",
                        exc, held_text(held))
            return
        if held:
            log.warning("%s%s", message, held_text(held))
        if previous is not None:
            previous(loop, context)
        else:
            loop.default_exception_handler(context)

    loop.set_exception_handler(handler)

    def restore() -> None:
        if loop.get_exception_handler() is handler:
            loop.set_exception_handler(previous)

    return restore


__all__ = ["guard_loop_faults"]
