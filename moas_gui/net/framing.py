"""The client protocol's lines: one JSON object per line, read with the shared framer.

A line ends with ``\\n``; a ``\\r`` just before it is dropped, so ``\\r\\n``
works too.  A line whose content is longer than :data:`MAX_LINE` bytes is
reported once as :class:`~moas_gui.line_framer.LongLine` as soon as that is
certain, and its remaining bytes are thrown away up to its ``\\n``: a
connection never holds more than about ``MAX_LINE`` bytes of a line, whatever
a peer sends.  The cutting itself is :mod:`moas_gui.line_framer`'s, as for
every line protocol of moas-gui.
"""

from __future__ import annotations

from moas_gui.line_framer import Line, LineEnd, LineFramer, LongLine

MAX_LINE = 65_536
"""The longest request line content, in bytes, without its ``\\r\\n`` or ``\\n``."""


def request_framer(limit: int = MAX_LINE) -> LineFramer:
    """A framer for one connection's lines (requests at the server, replies at a client)."""
    return LineFramer(limit, LineEnd.LF)


__all__ = ["MAX_LINE", "Line", "LineFramer", "LongLine", "request_framer"]
