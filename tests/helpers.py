"""Helpers shared by the tests: waiting for a condition, a free port, a fake clock.

Waiting polls a condition until it holds or a time limit passes; the limits
are generous (a loaded machine is slow), a test that passes never waits for
them.
"""

from __future__ import annotations

import asyncio
import socket
import tempfile
import time
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any, TypeVar

from moas_gui.clock import FakeClock

T = TypeVar("T")

ROOT = Path(__file__).resolve().parent.parent
"""The checkout: the package, docs/ and examples/ beside tests/."""
EXAMPLES = ROOT / "examples"
"""The example station files."""

__all__ = ["EXAMPLES", "ROOT", "FakeClock", "advance_until", "free_port", "run_on", "short_runtime_dir", "until",
           "wait_for"]


async def until(condition: Callable[[], object], timeout: float = 10.0,
                what: str = "the condition", every: float = 0.01) -> None:
    """Waits, in the event loop, until ``condition()`` is true."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while not condition():
        if loop.time() > deadline:
            raise AssertionError(f"gave up waiting for {what} ({timeout:g} s)")
        await asyncio.sleep(every)


async def advance_until(clock: FakeClock, condition: Callable[[], object], limit: float = 60.0,
                        what: str = "the condition", step: float = 0.05) -> float:
    """Moves ``clock`` on by ``step`` at a time until ``condition()`` is true; returns the
    clock's time then.  ``limit`` is in the clock's seconds (no real time is waited)."""
    end = clock.now() + limit
    await clock.advance(0)
    while not condition():
        if clock.now() >= end:
            raise AssertionError(f"{what} did not come within {limit:g} s of the fake clock")
        await clock.advance(step)
    return clock.now()


async def run_on(clock: FakeClock, work: Awaitable[T], limit: float = 5.0,
                 what: str = "the work", step: float = 0.05) -> T:
    """Awaits ``work`` while moving ``clock`` on (see :func:`advance_until`): for a call
    that waits on the clock itself (a timeout, a pause) before it returns or raises."""
    task = asyncio.ensure_future(work)
    try:
        await advance_until(clock, task.done, limit, what, step)
    finally:
        if not task.done():
            task.cancel()
    return task.result()


def wait_for(condition: Callable[[], Any], timeout: float = 15.0, what: str = "",
             every: float = 0.05) -> Any:
    """Waits, blocking, until ``condition()`` is true (an OSError counts as not yet);
    returns the condition's last value."""
    end = time.monotonic() + timeout
    last: Any = None
    while time.monotonic() < end:
        try:
            last = condition()
        except OSError as exc:
            last = exc
        else:
            if last:
                return last
        time.sleep(every)
    raise AssertionError(f"{what or 'the condition'} not met in {timeout} s (last: {last!r})")


def free_port(kind: int = socket.SOCK_STREAM) -> int:
    """A port on 127.0.0.1 free a moment ago (TCP, or UDP with ``socket.SOCK_DGRAM``)."""
    with socket.socket(socket.AF_INET, kind) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def short_runtime_dir() -> Path:
    """A new private directory with a short path, for XDG_RUNTIME_DIR: the caller
    removes it (the ``runtime_dir`` fixture does)."""
    return Path(tempfile.mkdtemp(prefix="moas-run-"))
