"""A station's ``.moas`` file as the builder edits it: the user's text, changed value by value.

The text is the document.  Each edit finds the value's place in the positioned tree
(:mod:`moas_gui.config.jsontree`), replaces that value's characters alone (or inserts or
removes one list item or one group member with its comma) and reads the text again (a
plain value put in place of a value on one line: its tree is made from the tree before,
:mod:`.rereading`).  Nothing is ever written out afresh from a model, so the user's order, spacing, line
ends, unknown names and everything the builder does not touch stay as they were: an
unchanged file saves to the same bytes, and one edit changes the lines of that value.

Every edit is one :class:`EditStep` of splices, so undo and redo are exact; a
:meth:`Document.transaction` makes several edits one step.  The readings of the last few
texts are kept, so an undo or a redo back to one of them reads nothing again (a reading
is never changed once made).  Saving is atomic
(:func:`moas_gui.files.write_atomic`) and keeps the previous file as ``FILE.moas.bak``.
"""

from __future__ import annotations

import contextlib
import difflib
import json
import re
from collections import OrderedDict
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path as FilePath

from moas_gui.config.jsontree import JArray, JObject, Node, parse, plain_scalar
from moas_gui.config.loader import MAX_BYTES
from moas_gui.config.problems import Problem
from moas_gui.errors import MoasError
from moas_gui.files import write_atomic

from .rereading import tree_after
from .spans import LineStarts, Path, find, plain, value_end

NEW_STATION = "{\n}\n"
"""The text of a station that has nothing yet (the guide fills it)."""
KEPT_READINGS = 16
KEPT_CHARACTERS = 1_000_000
"""The readings of at most this many recent texts are kept, together at most this long
(the current text's always)."""


class EditError(MoasError, ValueError):
    """An edit that cannot be made (a place that is not there, a file that cannot be read)."""


@dataclass(frozen=True, slots=True)
class Splice:
    """``old`` at ``start`` became ``new``."""

    start: int
    old: str
    new: str


@dataclass(frozen=True, slots=True)
class EditStep:
    """One edit as the user sees it (undone and redone whole)."""

    what: str
    splices: tuple[Splice, ...]


@dataclass(frozen=True, slots=True)
class Style:
    """How the file writes what the builder adds: the indentation step, the text between
    a name and its value, and the line end."""

    unit: str = "  "
    colon: str = ": "
    newline: str = "\n"
    flat: bool = False
    """The file is one line: what is added stays on it."""

    @classmethod
    def of(cls, text: str) -> Style:
        unit = re.search(r"\n([ \t]+)\S", text)
        colon = re.search(r'"([ \t]*:[ \t]*)', text)
        return cls(unit.group(1) if unit else "  ", colon.group(1) if colon else ": ",
                   "\r\n" if "\r\n" in text else "\n", "\n" not in text.rstrip("\r\n"))


@dataclass(frozen=True, slots=True)
class TextReading:
    """What one text reads as: its tree and problems, its line starts and its style."""

    root: Node | None
    syntax: list[Problem]
    lines: LineStarts
    style: Style


def _tidy(value: object) -> object:
    """Whole numbers given as floats written as whole numbers (14000, not 14000.0)."""
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return int(value)
    if isinstance(value, dict):
        return {str(k): _tidy(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_tidy(v) for v in value]
    return value


def wants_lines(value: object) -> bool:
    """Whether a new value is written over several lines: a list holding groups, and a
    group holding groups or lists of groups; flat groups and lists of numbers on one."""
    if isinstance(value, list):
        return any(isinstance(v, dict) for v in value)
    if isinstance(value, dict):
        return any(isinstance(v, dict) or (isinstance(v, list) and wants_lines(v))
                   for v in value.values())
    return False


def render(value: object, style: Style, indent: str, lines: bool | None = None) -> str:
    """``value`` as JSON text in the file's style, its later lines at ``indent``."""
    value = _tidy(value)
    if lines is None:
        lines = wants_lines(value)
    if not lines or style.flat or not isinstance(value, (dict, list)) or not value:
        return json.dumps(value, ensure_ascii=False, separators=(", ", style.colon.strip("\t") or ":"))
    inner = indent + style.unit
    if isinstance(value, dict):
        parts = [f"{inner}{json.dumps(k, ensure_ascii=False)}{style.colon}{render(v, style, inner)}"
                 for k, v in value.items()]
        opener, closer = "{", "}"
    else:
        parts = [inner + render(v, style, inner) for v in value]
        opener, closer = "[", "]"
    return opener + style.newline + ("," + style.newline).join(parts) + style.newline + indent + closer


class Document:
    """One station file being edited (see the module docstring)."""

    def __init__(self, text: str, path: FilePath | None = None, saved: str | None = None) -> None:
        self.path = path
        self.text = text
        self.saved: str | None = text if saved is None else saved
        """The text as it is on disk (None: not saved yet)."""
        self.undo_steps: list[EditStep] = []
        self.redo_steps: list[EditStep] = []
        self.listeners: list[Callable[[Document], None]] = []
        """Called after every change of the text (an edit, undo, redo, a save)."""
        self.saves = 0
        self._open: list[Splice] | None = None
        self._readings: OrderedDict[tuple[str, str], TextReading] = OrderedDict()
        self._read()

    # -- opening -----------------------------------------------------------------------
    @classmethod
    def open(cls, path: str | FilePath) -> Document:
        """The file at ``path`` (:class:`OSError` or :class:`EditError` when unreadable)."""
        path = FilePath(path)
        if path.stat().st_size > MAX_BYTES:
            raise EditError(f"{path}: the file is larger than {MAX_BYTES // 1_048_576} MB; "
                            "a configuration is refused above that")
        data = path.read_bytes()
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise EditError(f"{path}: the file is not UTF-8 text (byte {exc.start}); "
                            "save it as UTF-8") from None
        return cls(text, path)

    @classmethod
    def new(cls, path: str | FilePath | None = None) -> Document:
        """A station with nothing yet, to be saved at ``path``."""
        doc = cls(NEW_STATION, None if path is None else FilePath(path))
        doc.saved = None
        return doc

    def _read(self, quick: Callable[[], TextReading | None] = lambda: None) -> None:
        """Read the text (again): a reading kept of it, else ``quick()``'s, else the
        whole text read."""
        key = (self.text, str(self.path or ""))
        reading = self._readings.pop(key, None) or quick()
        if reading is None:
            root, syntax = parse(*key)
            reading = TextReading(root, syntax, LineStarts(self.text), Style.of(self.text))
        self._readings[key] = reading
        kept = sum(len(text) for text, _name in self._readings)
        while len(self._readings) > 1 and (len(self._readings) > KEPT_READINGS
                                           or kept > KEPT_CHARACTERS):
            (text, _name), _ = self._readings.popitem(last=False)
            kept -= len(text)
        self.root, self.syntax = reading.root, reading.syntax
        self.lines, self.style = reading.lines, reading.style

    # -- reading -------------------------------------------------------------------------
    @property
    def modified(self) -> bool:
        return self.text != self.saved

    @property
    def syntax_problems(self) -> list[Problem]:
        return list(self.syntax)

    @property
    def readable(self) -> bool:
        """Whether the text reads as a station's group ``{ ... }`` (mistakes the reader
        recovers from and all), so that its values can be edited."""
        return isinstance(self.root, JObject)

    def node(self, path: Path) -> Node | None:
        return find(self.root, path)

    def has(self, path: Path) -> bool:
        return self.node(path) is not None

    def get(self, path: Path, default: object = None) -> object:
        """The value at ``path`` as Python data, or ``default`` when it is not there."""
        node = self.node(path)
        return default if node is None else plain(node)

    def items(self, path: Path) -> list[object]:
        """The items of the list at ``path`` (none when there is no list there)."""
        node = self.node(path)
        return [plain(item) for item in node.items] if isinstance(node, JArray) else []

    def count(self, path: Path) -> int:
        node = self.node(path)
        return len(node.items) if isinstance(node, JArray) else 0

    def start(self, node: Node) -> int:
        return self.lines.offset(node.line, node.column)

    def span(self, path: Path) -> tuple[int, int]:
        """The offsets of the first character of the value at ``path`` and just past its last."""
        node = self._need(path)
        start = self.start(node)
        return start, value_end(self.text, start)

    def value_text(self, path: Path) -> str:
        start, end = self.span(path)
        return self.text[start:end]

    def line_of(self, path: Path) -> int:
        node = self.node(path)
        return node.line if node is not None else 0

    def _need(self, path: Path) -> Node:
        if not self.readable:
            raise EditError("the file cannot be read as JSON (a station is one group { ... }); "
                            "correct the mistakes listed first")
        node = find(self.root, path)
        if node is None:
            raise EditError(f"there is no {_shown(path)} in the file")
        return node

    def _indent(self, offset: int) -> str:
        line_start = self.text.rfind("\n", 0, offset) + 1
        head = self.text[line_start:offset]
        return head[: len(head) - len(head.lstrip(" \t"))]

    # -- editing ---------------------------------------------------------------------------
    def set(self, path: Path, value: object, what: str = "") -> None:
        """Give the value at ``path`` (a member that is not there is added; so are the
        groups that lead to it)."""
        if not path:
            raise EditError("the whole file is not one value to set")
        node = self.node(path) if self.readable else None
        if node is None:
            self._add(path, value, what)
            return
        start, end = self.span(path)
        old = self.text[start:end]
        lines = ("\n" in old) if isinstance(value, (dict, list)) and old[:1] in "[{" else None
        new = render(value, self.style, self._indent(start), lines)
        same = plain(node) == _tidy(value) and type(plain(node)) is type(_tidy(value))
        if same and (isinstance(value, (dict, list)) or old == new):
            return  # (a scalar written as JSON does not, "False", is written again)
        self._splice(Splice(start, old, new), what or f"set {_shown(path)}")

    def _add(self, path: Path, value: object, what: str) -> None:
        parent_path, last = path[:-1], path[-1]
        parent = self._need(parent_path) if not parent_path else self.node(parent_path)
        if parent is None:
            if not isinstance(last, str):
                raise EditError(f"there is no {_shown(parent_path)} in the file")
            self._add(parent_path, {last: value}, what)
            return
        if isinstance(parent, JObject) and isinstance(last, str):
            self._insert_member(parent_path, parent, last, value, what)
        elif isinstance(parent, JArray) and last == len(parent.items):
            self.insert(parent_path, len(parent.items), value, what)
        else:
            raise EditError(f"there is no {_shown(path)} in the file")

    def insert(self, path: Path, index: int, value: object, what: str = "") -> None:
        """Put ``value`` into the list at ``path`` at ``index`` (its length: at the end)."""
        node = self._need(path)
        if not isinstance(node, JArray):
            raise EditError(f"{_shown(path)} is not a list")
        spans = [(self.start(item), value_end(self.text, self.start(item))) for item in node.items]
        self._insert_element(node, spans, path, index, lambda indent, lines:
                             render(value, self.style, indent, lines),
                             wants_lines(value), what or f"add to {_shown(path)}")

    def append(self, path: Path, value: object, what: str = "") -> None:
        """Put ``value`` at the end of the list at ``path`` (a list that is not there is made)."""
        if self.readable and self.node(path) is None:
            self.set(path, [value], what or f"add to {_shown(path)}")
            return
        self.insert(path, self.count(path), value, what)

    def _insert_member(self, path: Path, node: JObject, key: str, value: object, what: str) -> None:
        spans = [(self.lines.offset(m.line, m.column),
                  value_end(self.text, self.start(m.value))) for m in node.members]
        colon = self.style.colon

        def text(indent: str, lines: bool) -> str:
            return f"{json.dumps(key, ensure_ascii=False)}{colon}{render(value, self.style, indent)}"
        self._insert_element(node, spans, path, len(spans), text,
                             wants_lines(value) or not path,
                             what or f"set {_shown((*path, key))}")

    def _insert_element(self, node: Node, spans: list[tuple[int, int]], path: Path, index: int,
                        text: Callable[[str, bool], str], lines: bool, what: str) -> None:
        nl = self.style.newline
        opener = self.start(node)
        if not spans:
            closer = value_end(self.text, opener) - 1
            base = self._indent(opener)
            inner = self.text[opener + 1 : closer]
            if (lines and not self.style.flat) or "\n" in inner:
                new = nl + base + self.style.unit + text(base + self.style.unit, lines) + nl + base
            else:
                new = text(base, False)
            self._splice(Splice(opener + 1, inner, new), what)
            return
        index = max(0, min(index, len(spans)))
        if len(spans) >= 2:
            sep = self.text[spans[0][1] : spans[1][0]]
        elif "\n" in self.text[opener + 1 : spans[0][0]]:
            sep = "," + nl + self._indent(spans[0][0])
        else:
            sep = ", "
        indent = sep.rsplit("\n", 1)[1] if "\n" in sep else self._indent(spans[0][0])
        item_lines = any("\n" in self.text[s:e] for s, e in spans) or lines
        new = text(indent, item_lines)
        if index == len(spans):
            self._splice(Splice(spans[-1][1], "", sep + new), what)
        else:
            self._splice(Splice(spans[index][0], "", new + sep), what)

    def remove(self, path: Path, what: str = "") -> None:
        """Take away the list item or group member at ``path`` (with its comma)."""
        if not path:
            raise EditError("the whole file cannot be removed")
        self._need(path)
        parent = self._need(path[:-1])
        last = path[-1]
        if isinstance(parent, JObject):
            spans = [(self.lines.offset(m.line, m.column), value_end(self.text, self.start(m.value)))
                     for m in parent.members]
            index = [m.key for m in parent.members].index(str(last))
        else:
            assert isinstance(parent, JArray) and isinstance(last, int)
            spans = [(self.start(i), value_end(self.text, self.start(i))) for i in parent.items]
            index = last
        if len(spans) == 1:
            opener = self.start(parent)
            closer = value_end(self.text, opener) - 1
            start, end = opener + 1, closer
        elif index > 0:
            start, end = spans[index - 1][1], spans[index][1]
        else:
            start, end = spans[0][0], spans[1][0]
        self._splice(Splice(start, self.text[start:end], ""), what or f"remove {_shown(path)}")

    def move(self, path: Path, index: int, to: int, what: str = "") -> None:
        """Move item ``index`` of the list at ``path`` to place ``to``."""
        items = self.items(path)
        if not 0 <= index < len(items) or not 0 <= to < len(items) or index == to:
            return
        value = items[index]
        with self.transaction(what or f"move item {index + 1} of {_shown(path)}"):
            self.remove((*path, index))
            self.insert(path, to, value)

    @contextlib.contextmanager
    def transaction(self, what: str) -> Iterator[None]:
        """Every edit inside is one step of undo and redo (all undone on an error)."""
        if self._open is not None:
            yield
            return
        self._open = []
        try:
            yield
        except BaseException:
            done, self._open = self._open, None
            for splice in reversed(done):
                self._apply(Splice(splice.start, splice.new, splice.old))
            self._changed()
            raise
        done, self._open = self._open, None
        if done:
            self._record(EditStep(what, tuple(done)))

    def _splice(self, splice: Splice, what: str) -> None:
        self._apply(splice)
        if self._open is not None:
            self._open.append(splice)
            return
        self._record(EditStep(what, (splice,)))

    def _record(self, step: EditStep) -> None:
        self.undo_steps.append(step)
        self.redo_steps.clear()
        self._changed()

    def _apply(self, splice: Splice) -> None:
        end = splice.start + len(splice.old)
        before = self.text
        assert before[splice.start:end] == splice.old, "the text is not what the edit expects"
        self.text = before[: splice.start] + splice.new + before[end:]
        self._read(lambda: self._scalar_replaced(before, splice))

    def _scalar_replaced(self, before: str, splice: Splice) -> TextReading | None:
        """The reading of the text after ``splice``, made from the reading before it
        (:mod:`.rereading`) when the splice put a plain value in place of a value on one
        line of a text without mistakes; else None (the text is read whole)."""
        if self.syntax or self.root is None or "\n" in splice.old or "\r" in splice.old:
            return None
        value = plain_scalar(splice.new)
        if value is None or value_end(before, splice.start) != splice.start + len(splice.old):
            return None
        line = self.lines.line_of(splice.start)
        column = splice.start - self.lines.starts[line - 1] + 1
        root = tree_after(self.root, line, column, value[0], len(splice.new) - len(splice.old))
        if root is None:
            return None
        return TextReading(root, [], LineStarts(self.text), Style.of(self.text))

    def _changed(self) -> None:
        for listener in list(self.listeners):
            listener(self)

    def repair(self) -> int:
        """Mend the JSON mistakes the reader recovers from and says how to mend (a missing
        comma, an extra comma, True/False/None in other letter cases, names and texts
        without double quotes), in one undo step; returns how many were mended."""
        fixes = sorted((f for f in map(self._fix_of, self.syntax) if f is not None),
                       key=lambda f: f.start, reverse=True)
        if not fixes:
            return 0
        with self.transaction(f"mend {len(fixes)} JSON mistake{'s' if len(fixes) != 1 else ''}"):
            for fix in fixes:
                self._splice(Splice(fix.start, self.text[fix.start:fix.start + len(fix.old)],
                                    fix.new), "")
        return len(fixes)

    def _fix_of(self, problem: Problem) -> Splice | None:
        if problem.line <= 0:
            return None
        at = self.lines.offset(problem.line, problem.column)
        message = problem.message
        if message.startswith("missing comma after the value"):
            return Splice(at, "", ",")
        if message.startswith("extra comma after the last value") and self.text[at:at + 1] == ",":
            return Splice(at, ",", "")
        if message.startswith("use double quotes") and self.text[at:at + 1] == "'":
            end = self.text.find("'", at + 1)
            if end > at:
                return Splice(at, self.text[at:end + 1],
                              json.dumps(self.text[at + 1:end], ensure_ascii=False))
            return None
        wanted = re.match(r'(?:write (true|false|null) in lowercase, not (\w+))|'
                          r'(?:(?:names|text) must be in double quotes: write "([^"]*)")', message)
        if wanted is None:
            return None
        if wanted.group(1):
            return Splice(at, wanted.group(2), wanted.group(1))
        word = wanted.group(3)
        if self.text.startswith(word, at):
            return Splice(at, word, json.dumps(word, ensure_ascii=False))
        return None

    # -- undo and redo -----------------------------------------------------------------------
    @property
    def can_undo(self) -> bool:
        return bool(self.undo_steps)

    @property
    def can_redo(self) -> bool:
        return bool(self.redo_steps)

    def undo(self) -> str:
        """Undo the last step; returns what it was (empty when there is nothing to undo)."""
        if not self.undo_steps:
            return ""
        step = self.undo_steps.pop()
        for splice in reversed(step.splices):
            self._apply(Splice(splice.start, splice.new, splice.old))
        self.redo_steps.append(step)
        self._changed()
        return step.what

    def redo(self) -> str:
        if not self.redo_steps:
            return ""
        step = self.redo_steps.pop()
        for splice in step.splices:
            self._apply(splice)
        self.undo_steps.append(step)
        self._changed()
        return step.what

    # -- saving ----------------------------------------------------------------------------
    def diff(self, context: int = 2) -> str:
        """What saving will change, as a unified diff (empty: nothing)."""
        name = str(self.path or "new station")
        old = (self.saved or "").splitlines(keepends=True)
        new = self.text.splitlines(keepends=True)
        lines = difflib.unified_diff(old, new, f"{name} (on disk)", f"{name} (to be saved)",
                                     n=context)
        return "".join(line if line.endswith("\n") else line + "\n" for line in lines)

    def changed_on_disk(self) -> bool:
        """Whether the file on disk is no longer what this document read or saved."""
        if self.path is None or self.saved is None:
            return False
        try:
            return self.path.read_bytes() != self.saved.encode("utf-8")
        except OSError:
            return True

    def save(self, path: str | FilePath | None = None) -> FilePath:
        """Write the text to ``path`` (this document's own by default) atomically; an
        existing file there is kept first as ``FILE.bak`` (``station.moas.bak``)."""
        target = FilePath(path) if path is not None else self.path
        if target is None:
            raise EditError("say where to save the new station")
        if target.exists():
            write_atomic(backup_of(target), target.read_bytes())
        write_atomic(target, self.text.encode("utf-8"))
        self.path = target
        self.saved = self.text
        self.saves += 1
        self._changed()
        return target


def backup_of(path: FilePath) -> FilePath:
    """Where saving keeps the previous version of ``path``."""
    return path.with_name(path.name + ".bak")


def _shown(path: Path) -> str:
    """A path in words for messages: ``Antennas[1].Control[0].Stations``."""
    out = ""
    for step in path:
        out += f"[{step + 1}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out or "file"


shown = _shown

__all__ = [
    "NEW_STATION",
    "Document",
    "EditError",
    "EditStep",
    "Splice",
    "Style",
    "TextReading",
    "backup_of",
    "render",
    "shown",
    "wants_lines",
]
