"""Cutting a byte stream into text lines: sans-IO, bounded memory, one rule for all.

Every line protocol of moas-gui reads its input through :class:`LineFramer`:
the client protocol (JSON lines, both ends), the MOAS Rotator protocol (both
ends), rigctld's replies, OTRSP and the FlexRadio API.  Each chooses only two things:

``limit``
    the longest line content accepted, in bytes, without its ending;
``ends``
    what ends a line (:class:`LineEnd`): ``LF`` (a CR just before the LF is
    part of the ending, so CR LF works too; a CR elsewhere is content) or
    ``CR_OR_LF`` (a CR, an LF or a CR LF pair each end one line).

Feed whatever arrived; take back, in stream order:

* :class:`Line` -- one complete line, without its ending.  Empty lines are
  returned too (each protocol decides whether they mean anything);
* :class:`LongLine` -- a line whose content is longer than ``limit``.  It is
  reported exactly once, as soon as that is certain (its end need not have
  arrived), with how many of its bytes were seen and the first
  :data:`HEAD` of them for a message.  The rest of that line, up to its
  ending, is thrown away without being held.

Between two calls the framer never holds more than ``limit + 1`` bytes (the
one extra is a CR that may turn out to start a CR LF), whatever a peer sends.
How the stream is cut into ``feed`` calls never changes what comes out.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from enum import Enum

HEAD = 40
"""How many leading bytes of a long line :class:`LongLine` keeps, for a message."""

_CR = 0x0D
_LF = 0x0A
_CR_OR_LF = re.compile(rb"[\r\n]")


class LineEnd(Enum):
    """What ends a line."""

    LF = "LF, or CR LF"
    """A line feed; a carriage return just before it belongs to the ending."""
    CR_OR_LF = "CR, LF or CR LF"
    """A carriage return or a line feed; a CR LF pair is one ending."""


@dataclass(frozen=True, slots=True)
class Line:
    """One complete line, without its ending."""

    data: bytes


@dataclass(frozen=True, slots=True)
class LongLine:
    """A line over the limit, given up.

    ``size`` is how many of its content bytes had arrived when it was given up
    (more may follow; they are skipped).  ``head`` is its first bytes, for a
    message only: two long lines of the same size compare equal.
    """

    size: int
    head: bytes = field(default=b"", compare=False)


class LineFramer:
    """Bytes in, :class:`Line` and :class:`LongLine` out, in stream order."""

    __slots__ = ("_after_cr", "_buffer", "_lf_only", "_scanned", "_skipping", "ends", "limit")

    def __init__(self, limit: int, ends: LineEnd = LineEnd.LF) -> None:
        if limit < 0:
            raise ValueError(f"a line limit cannot be negative ({limit})")
        self.limit = limit
        self.ends = ends
        self._lf_only = ends is LineEnd.LF
        self._buffer = bytearray()
        self._scanned = 0
        """Bytes of ``_buffer`` already known to hold no ending."""
        self._skipping = False
        """Inside a line already reported as long: drop bytes up to its ending."""
        self._after_cr = False
        """(``CR_OR_LF``) The last ending was a CR at the end of a feed: an LF
        opening the next one belongs to it."""

    @property
    def pending(self) -> int:
        """Bytes held for a line not yet complete."""
        return len(self._buffer)

    def feed(self, data: bytes) -> list[Line | LongLine]:
        """Everything ``data`` completes (or proves too long), in stream order."""
        out: list[Line | LongLine] = []
        lf_only = self._lf_only
        if self._after_cr and data:
            self._after_cr = False
            if data[0] == _LF:
                data = data[1:]
        if self._skipping:
            end = self._find(data, 0)
            if end < 0:
                return out
            self._skipping = False
            data = data[end + 1 if lf_only else self._next_start(data, end):]
        buffer = self._buffer
        buffer += data
        limit = self.limit
        start = 0
        while True:
            scan = max(self._scanned, start)
            end = buffer.find(b"\n", scan) if lf_only else self._find(buffer, scan)
            if end < 0:
                break
            if lf_only:
                stop = end - 1 if end > start and buffer[end - 1] == _CR else end
                following = end + 1
            else:
                stop = end
                following = self._next_start(buffer, end)
            if stop - start > limit:
                out.append(LongLine(stop - start, bytes(buffer[start:start + HEAD])))
            else:
                out.append(Line(bytes(buffer[start:stop])))
            start = following
        if start:
            del buffer[:start]
        self._scanned = len(buffer)
        if len(buffer) > limit and not (
                lf_only and len(buffer) == limit + 1 and buffer[-1] == _CR):
            # Certain now: even a CR LF next could not bring the content within the limit.
            out.append(LongLine(len(buffer), bytes(buffer[:HEAD])))
            buffer.clear()
            self._scanned = 0
            self._skipping = True
        return out

    def _find(self, data: bytes | bytearray, start: int) -> int:
        """Where the next ending starts at or after ``start``; -1 if none has come."""
        if self.ends is LineEnd.LF:
            return data.find(b"\n", start)
        match = _CR_OR_LF.search(data, start)
        return -1 if match is None else match.start()

    def _next_start(self, data: bytes | bytearray, end: int) -> int:
        """Where the line after the ending at ``end`` starts."""
        if self.ends is LineEnd.LF or data[end] == _LF:
            return end + 1
        if end + 1 == len(data):
            self._after_cr = True
            return end + 1
        return end + 2 if data[end + 1] == _LF else end + 1


__all__ = ["HEAD", "Line", "LineEnd", "LineFramer", "LongLine"]
