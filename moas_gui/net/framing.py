"""Splitting a client's byte stream into lines: sans-IO, bounded memory.

Feed whatever the socket delivered; take back complete lines.  A line ends
with ``\\n``; a ``\\r`` just before it is dropped, so ``\\r\\n`` works too.  A
line whose content is longer than :data:`MAX_LINE` bytes is reported once as
:class:`LongLine` as soon as that is certain, and its remaining bytes are
thrown away up to its ``\\n``: the splitter never holds more than about
``MAX_LINE`` bytes, whatever a peer sends.
"""

from __future__ import annotations

from dataclasses import dataclass

MAX_LINE = 65_536
"""The longest line content, in bytes, without its ``\\r\\n`` or ``\\n``."""


@dataclass(frozen=True, slots=True)
class Line:
    """One complete line, without its ending."""

    data: bytes


@dataclass(frozen=True, slots=True)
class LongLine:
    """A line over the limit; ``size`` is how many of its bytes had arrived when
    it was given up (more may follow and are skipped)."""

    size: int


class LineSplitter:
    """Bytes in, :class:`Line` and :class:`LongLine` out, in stream order."""

    __slots__ = ("_buffer", "_limit", "_scanned", "_skipping")

    def __init__(self, limit: int = MAX_LINE) -> None:
        self._limit = limit
        self._buffer = bytearray()
        self._scanned = 0
        """Bytes of ``_buffer`` already known to hold no newline."""
        self._skipping = False
        """Inside a line already reported as long: drop bytes up to its newline."""

    @property
    def pending(self) -> int:
        """Bytes held for a line not yet complete."""
        return len(self._buffer)

    def feed(self, data: bytes) -> list[Line | LongLine]:
        out: list[Line | LongLine] = []
        if self._skipping:
            end = data.find(b"\n")
            if end < 0:
                return out
            self._skipping = False
            data = data[end + 1 :]
        buffer = self._buffer
        buffer += data
        start = 0
        while True:
            end = buffer.find(b"\n", max(start, self._scanned))
            if end < 0:
                break
            stop = end - 1 if end > start and buffer[end - 1] == 0x0D else end
            if stop - start > self._limit:
                out.append(LongLine(stop - start))
            else:
                out.append(Line(bytes(buffer[start:stop])))
            start = end + 1
            self._scanned = start
        if start:
            del buffer[:start]
        self._scanned = len(buffer)
        # One byte of slack: the last byte may be the \r of a \r\n still to come.
        if len(buffer) > self._limit + 1:
            out.append(LongLine(len(buffer)))
            buffer.clear()
            self._scanned = 0
            self._skipping = True
        return out


__all__ = ["MAX_LINE", "Line", "LineSplitter", "LongLine"]
