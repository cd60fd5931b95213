"""The tree of a text after one value on one line was replaced by another, made from the
tree before it instead of reading the whole text again.

An edit that puts a plain value (text without escapes, a whole number, true, false,
null) where a plain value stood, on one line, changes nothing of the tree but that value
and the columns of what follows it on its line.  :func:`tree_after` makes that tree: the
value's node anew, the nodes after it on its line anew (moved), their groups and lists
anew, and every other part of the tree shared with the tree before (trees are never
changed once read).  Anything else (a value over several lines, a group, an escape, a
file with mistakes) is read again whole by :func:`moas_gui.config.jsontree.parse`;
``tests/builder/test_builder_rereading.py`` holds the two to the same trees.
"""

from __future__ import annotations

from moas_gui.config.jsontree import JArray, JObject, JScalar, Member, Node, Scalar


class _Splice:
    """The replaced value: where it started, its new value, how far what followed it on
    its line moved, and whether it was found in the tree."""

    def __init__(self, line: int, column: int, value: Scalar, delta: int) -> None:
        self.line = line
        self.column = column
        self.value = value
        self.delta = delta
        self.found = False

    def column_of(self, line: int, column: int) -> int:
        return column + self.delta if line == self.line and column > self.column else column

    def node(self, node: Node) -> Node:
        if node.line > self.line:
            return node
        if isinstance(node, JScalar):
            return self.scalar(node)
        if isinstance(node, JObject):
            return self.group(node)
        assert isinstance(node, JArray)
        return self.array(node)

    def scalar(self, node: JScalar) -> Node:
        if node.line != self.line or node.column < self.column:
            return node
        if node.column == self.column:
            self.found = True
            return JScalar(node.line, node.column, self.value)
        return JScalar(node.line, node.column + self.delta, node.value)

    def reaches(self, starts: list[int], index: int) -> bool:
        """Whether the part at ``index`` of a group or list (their first lines ``starts``)
        can hold anything of the replaced value's line: it starts on or before it, and
        the next part starts on or after it."""
        return starts[index] <= self.line and (index + 1 == len(starts)
                                               or starts[index + 1] >= self.line)

    def group(self, node: JObject) -> Node:
        starts = [member.line for member in node.members]
        members: list[Member] = []
        for index, member in enumerate(node.members):
            if not self.reaches(starts, index):
                members.append(member)
                continue
            value = self.node(member.value)
            column = self.column_of(member.line, member.column)
            members.append(member if value is member.value and column == member.column
                           else Member(member.key, member.line, column, value))
        column = self.column_of(node.line, node.column)
        if column == node.column and all(a is b for a, b in zip(members, node.members,
                                                                strict=True)):
            return node
        return JObject(node.line, column, members)

    def array(self, node: JArray) -> Node:
        starts = [item.line for item in node.items]
        items = [self.node(item) if self.reaches(starts, index) else item
                 for index, item in enumerate(node.items)]
        column = self.column_of(node.line, node.column)
        if column == node.column and all(a is b for a, b in zip(items, node.items, strict=True)):
            return node
        return JArray(node.line, column, items)


def tree_after(root: Node, line: int, column: int, value: Scalar, delta: int) -> Node | None:
    """The tree once the plain value that starts at ``line``, ``column`` (both from 1) in
    ``root``'s text is ``value``, written ``delta`` characters longer (or shorter) on the
    same line; None when no plain value starts there."""
    splice = _Splice(line, column, value, delta)
    after = splice.node(root)
    return after if splice.found else None


__all__ = ["tree_after"]
