"""The server window's log: a logging handler that feeds a read-only text view.

Records arrive from any thread; a Qt signal carries them to the widget.  The
view keeps every record it was given (up to a limit) and shows those at or
above the chosen level, so switching from Errors to Debug shows what was
logged before the switch too.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from enum import Enum

from .qt import (
    QFont,
    QFontDatabase,
    QObject,
    QTextBlockFormat,
    QTextCursor,
    QTextEdit,
    QWidget,
    Signal,
)

MAX_RECORDS = 5000
PREFIX_CHARS = len("12:34:56  warning ")
"""Characters before the message: the time, two spaces, the level and a space."""


class LogLevel(str, Enum):
    """The View menu's three log levels (manual 3.5.2-3.5.4)."""

    ERRORS = "errors"
    INFO = "info"
    DEBUG = "debug"

    @property
    def threshold(self) -> int:
        return {LogLevel.ERRORS: logging.ERROR, LogLevel.INFO: logging.INFO,
                LogLevel.DEBUG: logging.DEBUG}[self]


class _Bridge(QObject):
    record = Signal(int, str)


class QtLogHandler(logging.Handler):
    """Passes formatted records to the GUI thread through a Qt signal."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.bridge = _Bridge()
        self.setFormatter(logging.Formatter("%(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            stamp = time.strftime("%H:%M:%S", time.localtime(record.created))
            level = {logging.DEBUG: "debug", logging.INFO: "info", logging.WARNING: "warning",
                     logging.ERROR: "error", logging.CRITICAL: "error"}.get(record.levelno, "info")
            self.bridge.record.emit(record.levelno, f"{stamp}  {level:<7} {self.format(record)}")
        except RuntimeError:  # the bridge was deleted while the app shuts down
            pass


class LogView(QTextEdit):
    """A read-only log that shows records at or above :attr:`level`.

    A record too long for the window wraps with its next lines indented to
    where its message starts, so the time and level column stays clear."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setReadOnly(True)
        self.setAcceptRichText(False)
        self.document().setMaximumBlockCount(MAX_RECORDS)
        self.setFont(QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont)
                     if QFontDatabase.families() else QFont("monospace"))
        self._records: deque[tuple[int, str]] = deque(maxlen=MAX_RECORDS)
        self._level = LogLevel.INFO

    @property
    def level(self) -> LogLevel:
        return self._level

    def set_level(self, level: LogLevel) -> None:
        if level is self._level:
            return
        self._level = level
        self.clear()
        for number, text in self._records:
            if number >= level.threshold:
                self._append(text)
        self.moveCursor(QTextCursor.MoveOperation.End)

    def add_record(self, levelno: int, text: str) -> None:
        self._records.append((levelno, text))
        if levelno >= self._level.threshold:
            bar = self.verticalScrollBar()
            following = bar.value() >= bar.maximum() - 4
            self._append(text)
            if following:
                bar.setValue(bar.maximum())

    def _append(self, text: str) -> None:
        indent = self.fontMetrics().horizontalAdvance(" " * PREFIX_CHARS)
        shape = QTextBlockFormat()
        shape.setLeftMargin(indent)
        shape.setTextIndent(-indent)
        cursor = QTextCursor(self.document())
        cursor.movePosition(QTextCursor.MoveOperation.End)
        if self.document().isEmpty():
            cursor.setBlockFormat(shape)
        else:
            cursor.insertBlock(shape)
        cursor.insertText(text)

    def shown_lines(self) -> list[str]:
        text = self.toPlainText()
        return text.splitlines() if text else []


__all__ = ["LogLevel", "LogView", "QtLogHandler"]
