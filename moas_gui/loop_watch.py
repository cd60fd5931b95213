"""The server watches its own event loop: how late it runs, and what held it.

The loop that answers clients also drives the switches, so a turn of it that takes long
delays every relay change and every switch's ping.  :class:`LoopWatch` keeps a timer
that expects to run every :data:`EVERY` seconds (100 ms); how late it runs is the
loop's *lag* at that moment.  The largest lag since the watch started is
:attr:`LoopWatch.largest` (the status shows it: ``ServerStatus.loop_lag_ms``, the
client protocol's snapshot ``loop_lag_ms``).

A lag over :data:`LOG_OVER` (100 ms) writes one Warning line, at most one a minute
with the count of the others left out, saying what the loop was running.  To know
that without timing every callback (which would cost on every turn), a small thread
of its own sleeps until the timer would be a look overdue (:data:`LOOK_AFTER` seconds
after it last ran: it wakes about once a period, not every :data:`LOOK_EVERY`, as it
costs a quiet server's processor at each wake); once the timer is overdue, the thread
takes one look at the loop thread's stack (as text, :func:`faulthandler.dump_traceback`
into a scratch file): the code that holds the loop, caught in the act.  A stall too short for the thread to see (under
about 150 ms), or inside code that keeps every other thread out, says so instead::

    watch = LoopWatch()
    watch.start()            # in the running loop
    ...
    watch.largest            # seconds
    watch.stop()
"""

from __future__ import annotations

import asyncio
import contextlib
import faulthandler
import logging
import os
import sys
import threading
import time
from dataclasses import dataclass
from typing import IO, Final

from moas_gui.log_limit import LogLimiter, held_text

log = logging.getLogger(__name__)

EVERY: Final = 0.1
"""Seconds between two runs of the timer, as asked of the loop."""

LOG_OVER: Final = 0.1
"""A lag longer than this (seconds) is logged."""

LOOK_EVERY: Final = 0.05
"""Seconds between two looks of the watching thread."""

LOOK_AFTER: Final = EVERY + LOOK_EVERY
"""Seconds since the timer last ran after which the thread looks at what runs (its
period and one look more)."""

SHOWN_FRAMES: Final = 3
"""Frames of the loop thread's stack a log line names, innermost first."""


@dataclass(frozen=True, slots=True)
class Seen:
    """What the watching thread saw the loop run, during the stall after turn ``turn``."""

    turn: int
    what: str


class LoopWatch:
    """The loop's lag, measured by a timer every ``every`` seconds (see the module notes)."""

    def __init__(self, every: float = EVERY, log_over: float = LOG_OVER,
                 limiter: LogLimiter | None = None) -> None:
        self.every = every
        self.log_over = log_over
        self.look_after = every + LOOK_EVERY
        """Seconds since the timer last ran after which the thread looks (:data:`LOOK_AFTER`)."""
        self.limiter = limiter if limiter is not None else LogLimiter()
        self.largest = 0.0
        """The largest lag seen since the watch was made, in seconds."""
        self.turns = 0
        """How many times the timer has run."""
        self.looks = 0
        """How many stacks the watching thread has read (one a stall at most)."""
        self.wakes = 0
        """How many times the watching thread has woken (about one a period)."""
        self._loop: asyncio.AbstractEventLoop | None = None
        self._timer: asyncio.TimerHandle | None = None
        self._expected = 0.0
        self._last_run = time.monotonic()
        """When the timer last ran (the thread's clock: read from another thread)."""
        self._seen: Seen | None = None
        self._loop_thread = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def largest_ms(self) -> int:
        return round(self.largest * 1000)

    @property
    def running(self) -> bool:
        return self._timer is not None

    def start(self, loop: asyncio.AbstractEventLoop | None = None) -> None:
        """Starts watching ``loop`` (the running one); again is harmless."""
        if self._timer is not None:
            return
        self._loop = loop if loop is not None else asyncio.get_running_loop()
        self._loop_thread = threading.get_ident()
        self._last_run = time.monotonic()
        self._expected = self._loop.time() + self.every
        self._timer = self._loop.call_at(self._expected, self._run)
        self._stop.clear()
        self._thread = threading.Thread(target=self._look_forever, name="loop watch",
                                        daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stops watching (the largest lag is kept)."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=1.0)

    # -- on the loop -------------------------------------------------------------------
    def _run(self) -> None:
        loop = self._loop
        if loop is None or self._timer is None:
            return
        now = loop.time()
        lag = max(0.0, now - self._expected)
        self.turns += 1
        self._last_run = time.monotonic()
        self.largest = max(self.largest, lag)
        if lag > self.log_over:
            self._report(lag)
        self._expected = now + self.every
        self._timer = loop.call_at(self._expected, self._run)

    def _report(self, lag: float) -> None:
        seen = self._seen
        what = (seen.what if seen is not None and seen.turn == self.turns - 1 else
                "what it ran was not seen (too short a stall for the watching thread, or "
                "code that kept every other thread out)")
        held = self.limiter.allow("loop lag")
        if held is not None:
            log.warning(
                "The event loop ran %d ms late (switches and clients waited that long; "
                "the largest since start: %d ms): %s%s",
                round(lag * 1000), self.largest_ms, what,
                held_text(held, "more late turns over "
                          f"{round(self.log_over * 1000)} ms"))

    # -- the watching thread --------------------------------------------------------------
    def _look_forever(self) -> None:
        with scratch_file() as sink:
            while not self._stop.wait(self._until_overdue()):
                self.wakes += 1
                turn = self.turns
                seen = self._seen
                if seen is not None and seen.turn == turn:
                    continue  # this stall already looked at
                if time.monotonic() - self._last_run < self.look_after:
                    continue
                self._seen = Seen(turn, loop_stack(sink, self._loop_thread))
                self.looks += 1

    def _until_overdue(self) -> float:
        """How long the thread sleeps: until the timer would be a look overdue, not
        polling meanwhile (the timer runs every ``every`` seconds, so the thread wakes
        about once a period, not once a :data:`LOOK_EVERY`); during a stall already
        looked at, a look's period."""
        overdue = self._last_run + self.look_after - time.monotonic()
        return max(LOOK_EVERY if overdue <= 0 else overdue, 0.001)


def scratch_file() -> IO[bytes]:
    """An unnamed file for :func:`loop_stack`'s dumps: a file in memory on Linux
    (``memfd_create``), else a temporary file (:mod:`tempfile`, which loads :mod:`shutil`
    and its compressors: a Linux start does without them)."""
    if sys.platform == "linux":
        with contextlib.suppress(OSError):
            return open(os.memfd_create("moas-loop-stack", os.MFD_CLOEXEC), "w+b")
    import tempfile  # only where there is no memory file

    return tempfile.TemporaryFile()


def loop_stack(sink: IO[bytes], thread: int) -> str:
    """``running F (file:line), called from ...``: the innermost frames of ``thread``'s
    stack, read as text (:func:`faulthandler.dump_traceback` into ``sink``, a scratch
    file).  Text, not frames: a frame held here could outlive its call and free what it
    held on this thread (a Qt object freed off Qt's thread breaks its timers)."""
    sink.seek(0)
    sink.truncate()
    faulthandler.dump_traceback(sink, all_threads=True)
    sink.seek(0)
    text = sink.read(1 << 20).decode("utf-8", "replace")
    return describe(_thread_frames(text, thread))


def _thread_frames(text: str, thread: int) -> list[tuple[str, str, str]]:
    """``(function, file, line)`` of ``thread``'s frames, innermost first, from
    :mod:`faulthandler`'s dump."""
    frames: list[tuple[str, str, str]] = []
    inside = False
    for line in text.splitlines():
        if not line.startswith(" "):
            head = line.split()
            ident = next((word for word in head if word.startswith("0x")), None)
            inside = ident is not None and int(ident, 16) == thread
            continue
        if inside and line.strip().startswith("File "):
            path, _, rest = line.strip()[len('File "'):].partition('", line ')
            number, _, function = rest.partition(" in ")
            frames.append((function, path, number))
    return frames


def describe(frames: list[tuple[str, str, str]]) -> str:
    """``running F (file:line), called from ...`` for the innermost frames of a stack."""
    if not frames:
        return "the loop's thread was not found"
    parts = [f"{function} ({_short(path)}:{number})"
             for function, path, number in frames[:SHOWN_FRAMES]]
    return "running " + ", called from ".join(parts)


def _short(path: str) -> str:
    """A source file's path from its package on (``moas_gui/net/server.py``,
    ``asyncio/events.py``)."""
    parts = path.replace("\\", "/").split("/")
    for anchor in ("moas_gui", "site-packages", "tests", "benchmarks"):
        if anchor in parts:
            index = len(parts) - 1 - parts[::-1].index(anchor)
            return "/".join(parts[index:])
    return "/".join(parts[-2:])


__all__ = ["EVERY", "LOG_OVER", "LOOK_AFTER", "LOOK_EVERY", "LoopWatch", "describe", "loop_stack"]
