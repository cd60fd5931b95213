"""A message said again and again is shown once, with a count.

A link that keeps failing the same way (``cannot open ...: [Errno 2] ...``)
would fill the log with one line a second.  :class:`RepeatFolder`, a filter on
a log handler, lets the first line through and holds back the same line (same
level, same words) while it repeats; the next different line, or the same one
after :data:`FOLD_SECONDS`, first brings the count::

    12:00:01  warning MOAS Rotator ...: cannot connect (...)
    12:00:41  warning MOAS Rotator ...: cannot connect (...) (said 37 more times since 12:00:01)

Nothing is lost: the count says how often, the first line says when it began.
"""

from __future__ import annotations

import logging
import time
from typing import TypeVar

__all__ = ["FOLD_SECONDS", "LineFormatter", "RepeatFolder", "fold_repeats", "lean_records"]

H = TypeVar("H", bound=logging.Handler)

FOLD_SECONDS = 60.0
"""How long a repeating line is held back before its count is shown."""


class RepeatFolder(logging.Filter):
    """See the module notes.  One per handler (it passes the count through it)."""

    def __init__(self, handler: logging.Handler, seconds: float = FOLD_SECONDS) -> None:
        super().__init__()
        self.handler = handler
        self.seconds = seconds
        self._last: tuple[str, int, str] | None = None
        self._since = 0.0
        self._held = 0
        self._held_record: logging.LogRecord | None = None

    def filter(self, record: logging.LogRecord) -> bool:
        if getattr(record, "moas_folded", False):
            return True
        key = (record.name, record.levelno, record.getMessage())
        if key == self._last:
            if record.created - self._since < self.seconds:
                self._held += 1
                self._held_record = record
                return False
            if self._held:  # the same line after a while: it comes with its count
                record.msg, record.args = self._with_count(key[2]), None
            self._since, self._held, self._held_record = record.created, 0, None
            return True
        self._flush()
        self._last, self._since = key, record.created
        return True

    def _with_count(self, message: str) -> str:
        began = time.strftime("%H:%M:%S", time.localtime(self._since))
        times = "time" if self._held == 1 else "times"
        return f"{message} (said {self._held} more {times} since {began})"

    def _flush(self) -> None:
        held, last = self._held_record, self._last
        if held is None or last is None or not self._held:
            return
        summary = logging.makeLogRecord(held.__dict__)
        summary.msg, summary.args, summary.exc_info, summary.exc_text = (
            self._with_count(last[2]), None, None, None)
        summary.moas_folded = True
        self._held, self._held_record = 0, None
        self.handler.handle(summary)


def fold_repeats(handler: H, seconds: float = FOLD_SECONDS) -> H:
    """``handler`` with a :class:`RepeatFolder`; returns it."""
    handler.addFilter(RepeatFolder(handler, seconds))
    return handler


class LineFormatter(logging.Formatter):
    """The server's log lines, ``12:00:01 INFO    message``; the time's text is made once
    a second, not for every line (a band change's Info line costs a quiet server's
    processor: ``docs/architecture.md``, Timing)."""

    def __init__(self) -> None:
        super().__init__("%(asctime)s %(levelname)-7s %(message)s", "%H:%M:%S")
        self._second = -1
        self._text = ""

    def formatTime(self, record: logging.LogRecord,
                   datefmt: str | None = None) -> str:
        second = int(record.created)
        if second != self._second:
            self._second, self._text = second, super().formatTime(record, datefmt)
        return self._text


def lean_records() -> None:
    """Log records carry what the server's handlers show and no more: not the calling
    file, line and function, the thread or the process, which no handler of the server
    prints and each of which costs every record (the switches of the Optimization notes
    of Python's logging documentation).  For the headless server (``run_headless``),
    not the tests (whose captured records may name their caller)."""
    logging._srcfile = None  # the documented switch
    logging.logThreads = False
    logging.logProcesses = False
    logging.logMultiprocessing = False
