"""Where each value of a positioned tree starts and ends in its text.

:mod:`moas_gui.config.jsontree` keeps each value's line and column and nothing more,
which keeps the server's loader as quick as it is.  The builder needs the offsets of a
value's first and last character to replace its text alone; it finds them here, only
for the values it edits: the start from the line and column, the end by reading the
value's text (strings, brackets and their nesting).
"""

from __future__ import annotations

import bisect
import json
import re

from moas_gui.config.jsontree import JArray, JObject, JScalar, Member, Node

Path = tuple[str | int, ...]
"""Where a value is: member names and list indexes from the file's top group,
e.g. ``("Antennas", 0, "Control", 1, "Stations", 0, "Relays")``."""

_SCALAR_END = re.compile(r"""[^\s,:\]\}\[\{"'/]*""")
_DECODER = json.JSONDecoder()


class LineStarts:
    """Offsets of the lines of one text, to turn a line and column into an offset."""

    def __init__(self, text: str) -> None:
        self.starts = [0] + [m.end() for m in re.finditer("\n", text)]

    def offset(self, line: int, column: int) -> int:
        """The offset of ``line``, ``column`` (both from 1)."""
        return self.starts[line - 1] + column - 1

    def line_of(self, offset: int) -> int:
        """The line (from 1) holding ``offset``."""
        return bisect.bisect_right(self.starts, offset)


def _string_end(text: str, start: int) -> int:
    quote = text[start]
    at = start + 1
    while at < len(text):
        char = text[at]
        if char == "\\":
            at += 2
            continue
        if char == quote or char == "\n":
            return at + 1
        at += 1
    return len(text)


def _container_end(text: str, start: int) -> int:
    depth = 0
    at = start
    while at < len(text):
        char = text[at]
        if char in "\"'":
            at = _string_end(text, at)
            continue
        if char in "[{":
            depth += 1
        elif char in "]}":
            depth -= 1
            if depth == 0:
                return at + 1
        at += 1
    return len(text)


def value_end(text: str, start: int) -> int:
    """The offset just past the value that starts at ``start``."""
    char = text[start : start + 1]
    if char in ("{", "["):
        try:
            return int(_DECODER.raw_decode(text, start)[1])  # plain JSON: quick
        except ValueError:
            return _container_end(text, start)
    if char in ('"', "'"):
        return _string_end(text, start)
    match = _SCALAR_END.match(text, start)
    assert match is not None
    return max(match.end(), start + 1)


def child(node: Node, step: str | int) -> Node | None:
    """The value of member ``step`` of a group, or item ``step`` of a list."""
    if isinstance(step, str) and isinstance(node, JObject):
        member = node.get(step)
        return None if member is None else member.value
    if isinstance(step, int) and isinstance(node, JArray) and 0 <= step < len(node.items):
        return node.items[step]
    return None


def member_of(node: Node, key: str) -> Member | None:
    return node.get(key) if isinstance(node, JObject) else None


def find(root: Node | None, path: Path) -> Node | None:
    """The value at ``path`` (None when it is not there)."""
    node = root
    for step in path:
        if node is None:
            return None
        node = child(node, step)
    return node


def plain(node: Node) -> object:
    """The value as Python data (groups as dicts in the file's order)."""
    if isinstance(node, JScalar):
        return node.value
    if isinstance(node, JArray):
        return [plain(item) for item in node.items]
    assert isinstance(node, JObject)
    return {member.key: plain(member.value) for member in node.members}


class PlaceIndex:
    """Every value's and every name's place (line, column) to the path of the value,
    so that a problem reported at a place can be shown at the field it is about."""

    def __init__(self, root: Node | None) -> None:
        self._paths: dict[tuple[int, int], Path] = {}
        if root is not None:
            self._walk(root, ())
        self._sorted = sorted(self._paths)

    def _walk(self, root: Node, base: Path) -> None:
        stack: list[tuple[Node, Path]] = [(root, base)]
        while stack:
            node, path = stack.pop()
            self._paths.setdefault((node.line, node.column), path)
            if isinstance(node, JObject):
                for member in node.members:
                    self._paths.setdefault((member.line, member.column), (*path, member.key))
                stack.extend((m.value, (*path, m.key)) for m in node.members)
            elif isinstance(node, JArray):
                stack.extend((item, (*path, i)) for i, item in enumerate(node.items))

    def path_at(self, line: int, column: int) -> Path:
        """The path of the value (or name) at ``line``, ``column``; for a place between
        values (a missing comma), the value just before it; ``()`` for the whole file."""
        if line <= 0:
            return ()
        exact = self._paths.get((line, column))
        if exact is not None:
            return exact
        at = bisect.bisect_right(self._sorted, (line, column)) - 1
        return self._paths[self._sorted[at]] if at >= 0 else ()

    def path_on_line(self, line: int) -> Path:
        """The path of the first value (or name) on ``line``; ``()`` when none is."""
        at = bisect.bisect_left(self._sorted, (line, 0))
        if line <= 0 or at >= len(self._sorted) or self._sorted[at][0] != line:
            return ()
        return self._paths[self._sorted[at]]


__all__ = ["LineStarts", "Path", "PlaceIndex", "child", "find", "member_of", "plain", "value_end"]
