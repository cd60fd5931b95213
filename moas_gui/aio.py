"""Small asyncio helpers shared by every part that owns a background task."""

from __future__ import annotations

import asyncio
from typing import Any


async def cancel_and_wait(task: asyncio.Task[Any], poll: float = 0.2) -> None:
    """Cancel ``task`` and return once it has really ended.

    Python 3.11's ``asyncio.wait_for`` can swallow a cancellation that arrives
    together with the result it waits for (or with its error); the task then
    runs on, and a plain ``cancel(); await task`` waits forever.  This keeps
    cancelling until the task is done.  Whatever the task ended with is
    retrieved, never raised.
    """
    while not task.done():
        task.cancel()
        await asyncio.wait({task}, timeout=poll)
    if not task.cancelled():
        task.exception()


__all__ = ["cancel_and_wait"]
