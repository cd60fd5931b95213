"""A JSON reader that remembers where everything is, and explains mistakes.

Python's ``json`` module stops at the first mistake and cannot say on which
line a value sits.  Station builders edit these files by hand, so this reader:

* keeps the line and column of every name and value (for messages about
  meaning, like "antenna 12 does not exist", that must point somewhere);
* recovers from the mistakes the manual warns about (a missing comma, an
  extra comma before a closing bracket, ``True``/``False``, names without
  quotes, single quotes, comments) and goes on, so that one run reports all
  of them;
* reports a name given twice in one group.

It accepts nothing that strict JSON refuses: every recovery is also an error.

Whatever a file holds, reading it costs bounded time and memory: groups and
lists nest at most :data:`MAX_DEPTH` deep and a file holds at most
:data:`MAX_VALUES` values (beyond either, one problem at the place and the
reading stops); at most :data:`~.problems.SHOWN_PER_KIND` problems of a kind
are listed, the rest counted; and after :data:`MAX_SYNTAX_PROBLEMS` mistakes
the reader stops, since a file that broken is not worth reading further.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field

from .problems import Problem, ProblemList, Severity

Scalar = str | int | float | bool | None


@dataclass(slots=True, eq=False)
class Node:
    """A value of the file, with the line and column it starts at (1-based)."""

    line: int
    column: int


@dataclass(slots=True, eq=False)
class JScalar(Node):
    """A string, number, true, false or null."""

    value: Scalar


@dataclass(slots=True, eq=False)
class Member:
    """A key of a group and its value, with where the key is."""

    key: str
    line: int
    column: int
    value: Node


@dataclass(slots=True, eq=False)
class JObject(Node):
    """A group ``{ }``: its members in the file's order (a name given twice is kept twice,
    and reported)."""

    members: list[Member] = field(default_factory=list)

    def get(self, key: str) -> Member | None:
        for member in self.members:
            if member.key == key:
                return member
        return None


@dataclass(slots=True, eq=False)
class JArray(Node):
    """A list ``[ ]``: its items in order."""

    items: list[Node] = field(default_factory=list)


def describe(node: Node) -> str:
    """A value's kind in words, for messages."""
    if isinstance(node, JObject):
        return "a group { }"
    if isinstance(node, JArray):
        return "a list [ ]"
    assert isinstance(node, JScalar)
    value = node.value
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return f"the number {value}"
    return f'the text "{value}"'


class _Stop(Exception):
    """Raised when the reader cannot go on."""


class _Pairs(list[tuple[str, object]]):
    """A group as :mod:`json` read it: its names and values in order, repeats kept."""


class _Slow(Exception):
    """A group or list read whole is not plain JSON after all: read it step by step."""


def _refuse(word: str) -> object:
    raise ValueError(f"{word} is not JSON")


_DECODER = json.JSONDecoder(object_pairs_hook=_Pairs, parse_constant=_refuse)
_TOKEN = re.compile(r'[ \t\r\n,:\]}]*'
                    r'("[^"\\]*(?:\\.[^"\\]*)*"|-?[0-9][0-9.eE+\-]*|true|false|null|[{\[])')
"""Where each name and value starts (group 1), in a stretch that is plain JSON; what
lies between them is taken in the same match, which is many times quicker than
searching for the next one character by character."""
_LONGEST_INTEGER = 100
"""Integers with more digits are read as infinity (the checks then call them too large)."""
_HUGE = 10 ** _LONGEST_INTEGER


_WS = re.compile(r"[ \t\r\n\ufeff]*")
_NUMBER = re.compile(r"[+-]?\d+(\.\d+)?([eE][+-]?\d+)?")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_\-]*")
_STRING_BODY = re.compile(r'[^"\\\n]*')
_PLAIN_SCALAR = re.compile(r'"([^"\\\n]*)"|(-?(?:0|[1-9][0-9]{0,17}))(?![0-9.eE])'
                           r'|(true|false|null)(?![A-Za-z0-9_\-])')
"""The common values, read at once: text without escapes, whole numbers, words."""
_PLAIN_KEY = re.compile(r'"([^"\\\n]*)"[ \t\r\n]*:')
"""The common start of a member: a name without escapes and its colon."""
_ESCAPES = {'"': '"', "\\": "\\", "/": "/", "b": "\b", "f": "\f", "n": "\n", "r": "\r", "t": "\t"}
_CLOSERS = {"{": "}", "[": "]"}
MAX_DEPTH = 64
"""Groups and lists inside each other, at most (a station's file needs under 10)."""
MAX_VALUES = 100_000
"""Values (names not counted) in one file, at most: ten times the largest example
station (multi-multi-20.moas has about 9,000)."""
MAX_SYNTAX_PROBLEMS = 1000
"""Mistakes of JSON after which the reader stops."""


def _without_leading_zeros(unsigned: str) -> str:
    """``unsigned`` (digits, maybe a fraction and exponent) with its leading zeros removed."""
    whole = re.match(r"\d+", unsigned)
    assert whole is not None
    digits = whole.group().lstrip("0") or "0"
    return digits + unsigned[whole.end():]


_STRIDE = 1024


class _Lines:
    """Line and column of any place in a text, in little memory whatever its shape
    (a file of ten million empty lines, or one line ten million characters long):
    the lines before every :data:`_STRIDE` characters are counted once, the rest on
    demand."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.before = [0]
        """Line breaks before each multiple of the stride."""
        self.start = [0]
        """Where the line holding each multiple of the stride starts."""
        self.commas = [0]
        """Commas before each multiple of the stride."""
        count = start = commas = 0
        for at in range(0, len(text), _STRIDE):
            count += text.count("\n", at, at + _STRIDE)
            commas += text.count(",", at, at + _STRIDE)
            last = text.rfind("\n", at, at + _STRIDE)
            if last >= 0:
                start = last + 1
            self.before.append(count)
            self.start.append(start)
            self.commas.append(commas)

    def commas_after(self, offset: int) -> int:
        """Commas from ``offset`` to the end of the text."""
        chunk = offset // _STRIDE
        before = self.commas[chunk] + self.text.count(",", chunk * _STRIDE, offset)
        return self.commas[-1] - before

    def where(self, offset: int) -> tuple[int, int]:
        """``(line, column)`` of ``offset``, both from 1."""
        chunk = offset // _STRIDE
        at = chunk * _STRIDE
        line = self.before[chunk] + self.text.count("\n", at, offset) + 1
        last = self.text.rfind("\n", at, offset)
        start = last + 1 if last >= 0 else self.start[chunk]
        return line, offset - start + 1


class _Onward:
    """``(line, column)`` of offsets asked for in increasing order (the names and values of
    a stretch read at once): each character between them is looked at once."""

    __slots__ = ("at", "line", "start", "text")

    def __init__(self, lines: _Lines, offset: int) -> None:
        self.text = lines.text
        self.at = offset
        self.line, column = lines.where(offset)
        self.start = offset - column + 1

    def where(self, offset: int) -> tuple[int, int]:
        newlines = self.text.count("\n", self.at, offset)
        if newlines:
            self.line += newlines
            self.start = self.text.rfind("\n", self.at, offset) + 1
        self.at = offset
        return self.line, offset - self.start + 1


class _Parser:
    """Reads one configuration text into a tree, collecting every problem on the way."""

    def __init__(self, text: str, filename: str) -> None:
        self.text = text
        self.filename = filename
        self.pos = 0
        self.problems = ProblemList(filename)
        self.lines = _Lines(text)
        self.where = self.lines.where
        self.depth = 0
        self.values = 0
        self.wasted = 0
        """Characters read in vain by :meth:`whole` (it is given up beyond a bound)."""
        self.onward = self.where
        """Positions within the stretch :meth:`whole` builds (see :class:`_Onward`)."""

    # -- positions and messages --------------------------------------------
    def error(self, offset: int, message: str) -> None:
        line, column = self.where(offset)
        self.problems.add(line, column, Severity.ERROR, message)
        if self.problems.total == MAX_SYNTAX_PROBLEMS:
            self.problems.add(line, column, Severity.ERROR,
                              f"the reading stops here, after {MAX_SYNTAX_PROBLEMS:,} mistakes: "
                              "correct those listed and check the file again")
            raise _Stop()

    def stop(self, offset: int, message: str) -> _Stop:
        self.error(offset, message)
        return _Stop()

    def shown(self, offset: int) -> str:
        if offset >= len(self.text):
            return "the end of the file"
        char = self.text[offset]
        word = _WORD.match(self.text, offset)
        if word:
            return f"'{word.group()}'"
        return repr(char) if char.isprintable() else f"character U+{ord(char):04X}"

    # -- white space and comments ------------------------------------------
    def skip(self) -> None:
        text = self.text
        while True:
            self.pos = _WS.match(text, self.pos).end()  # type: ignore[union-attr]
            if text[self.pos : self.pos + 1] != "/":
                return
            if text.startswith("//", self.pos):
                self.error(self.pos, "JSON has no comments: remove the '//' comment")
                end = text.find("\n", self.pos)
                self.pos = len(text) if end < 0 else end
            elif text.startswith("/*", self.pos):
                self.error(self.pos, "JSON has no comments: remove the '/* */' comment")
                end = text.find("*/", self.pos + 2)
                self.pos = len(text) if end < 0 else end + 2
            else:
                return

    def peek(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    # -- values ---------------------------------------------------------------
    def value(self) -> Node:
        self.skip()
        start = self.pos
        self.values += 1
        if self.values > MAX_VALUES:
            raise self.stop(start, f"the file holds more than {MAX_VALUES:,} values, far more "
                                   "than any station needs (is this the right file?)")
        line, column = self.where(start)
        plain = _PLAIN_SCALAR.match(self.text, start)
        if plain is not None:
            self.pos = plain.end()
            text, whole, word = plain.groups()
            if text is not None:
                return JScalar(line, column, text)
            if whole is not None:
                return JScalar(line, column, int(whole))
            return JScalar(line, column, None if word == "null" else word == "true")
        char = self.peek()
        if char == "{" or char == "[":
            whole = self.whole(start)
            if whole is not None:
                return whole
            if char == "{":
                return self.group(start, line, column)
            return self.array(start, line, column)
        if char and char in "\"'":
            return JScalar(line, column, self.string())
        if char and (char.isdigit() or char in "+-."):
            return JScalar(line, column, self.number())
        word = _WORD.match(self.text, self.pos)
        if word:
            self.pos = word.end()
            return self.bare_word(start, line, column, word.group())
        if not char:
            raise self.stop(start, "the file ends where a value was expected")
        raise self.stop(start, f"expected a value but found {self.shown(start)}")

    def bare_word(self, start: int, line: int, column: int, name: str) -> JScalar:
        """A word without quotes: true, false or null as they are; the same in other
        letter cases (and None) read as meant, with a mistake; any other word read as
        the text it is, with a mistake asking for quotes."""
        if name in ("true", "false", "null"):
            return JScalar(line, column, None if name == "null" else name == "true")
        if name.lower() in ("true", "false"):
            self.error(start, f"write {name.lower()} in lowercase, not {name}")
            return JScalar(line, column, name.lower() == "true")
        if name.lower() in ("none", "null"):
            self.error(start, f"write null in lowercase, not {name}")
            return JScalar(line, column, None)
        self.error(start, f'text must be in double quotes: write "{name}"')
        return JScalar(line, column, name)

    # -- plain JSON, read at once -------------------------------------------
    def whole(self, start: int) -> Node | None:
        """The group or list at ``start`` read by :mod:`json` at once (most files are
        plain JSON, and this is many times quicker), or ``None`` when it has a mistake:
        then it is read step by step, and its parts are tried this way in turn.  The
        time lost on tries that fail is bounded (twice the file's length)."""
        text = self.text
        if self.wasted > 2 * len(text) or self.lines.commas_after(start) > 2 * MAX_VALUES:
            return None  # (the second: far too many values to be worth making at once)
        try:
            value, end = _DECODER.raw_decode(text, start)
        except json.JSONDecodeError as exc:
            self.wasted += exc.pos - start
            return None
        except (ValueError, RecursionError):
            self.wasted += 1000
            return None
        tokens = _TOKEN.finditer(text, start, end)
        values, depth = self.values, self.depth
        self.onward = _Onward(self.lines, start).where
        try:
            node = self.build(value, tokens, self.depth)
        except _Slow:
            self.values, self.depth = values, depth
            self.wasted += end - start
            return None
        self.values -= 1  # value() counted the group or list already
        self.pos = end
        return node

    def build(self, value: object, tokens: Iterator[re.Match[str]], depth: int) -> Node:
        at = next(tokens).start(1)
        self.values += 1
        if self.values > MAX_VALUES + 1:
            raise self.stop(at, f"the file holds more than {MAX_VALUES:,} values, far more "
                                "than any station needs (is this the right file?)")
        line, column = self.onward(at)
        if type(value) is _Pairs:
            if depth >= MAX_DEPTH:
                self.enter_too_deep(at)
            group = JObject(line, column)
            members = group.members
            seen: set[str] = set()
            for key, item in value:
                if key in seen:
                    raise _Slow()  # step by step says where both are
                seen.add(key)
                key_line, key_column = self.onward(next(tokens).start(1))
                members.append(Member(key, key_line, key_column,
                                      self.build(item, tokens, depth + 1)))
            return group
        if type(value) is list:
            if depth >= MAX_DEPTH:
                self.enter_too_deep(at)
            array = JArray(line, column)
            array.items = [self.build(item, tokens, depth + 1) for item in value]
            return array
        if type(value) is int and not -_HUGE < value < _HUGE:
            value = math.copysign(math.inf, value)
        return JScalar(line, column, value)  # type: ignore[arg-type]

    def string(self) -> str:
        text = self.text
        quote = text[self.pos]
        start = self.pos
        if quote == "'":
            end = text.find("'", start + 1)
            newline = text.find("\n", start + 1)
            if end < 0 or (0 <= newline < end):
                raise self.stop(start, "a text in single quotes is not closed on its line")
            self.error(start, "use double quotes (\") around names and text, not single quotes")
            self.pos = end + 1
            return text[start + 1 : end]
        self.pos += 1
        parts: list[str] = []
        while True:
            body = _STRING_BODY.match(text, self.pos)
            assert body is not None
            parts.append(body.group())
            self.pos = body.end()
            char = self.peek()
            if char == '"':
                self.pos += 1
                return "".join(parts)
            if char == "\\":
                escape = text[self.pos + 1 : self.pos + 2]
                if escape in _ESCAPES:
                    parts.append(_ESCAPES[escape])
                    self.pos += 2
                elif escape == "u" and re.fullmatch(r"[0-9a-fA-F]{4}", text[self.pos + 2 : self.pos + 6]):
                    parts.append(chr(int(text[self.pos + 2 : self.pos + 6], 16)))
                    self.pos += 6
                else:
                    self.error(self.pos, "unknown escape in text: write \\\\ for a backslash")
                    parts.append("\\")
                    self.pos += 1
                continue
            raise self.stop(start, "a text in quotes is not closed on its line (missing \")")

    def number(self) -> int | float:
        start = self.pos
        match = _NUMBER.match(self.text, self.pos)
        if not match:
            raise self.stop(start, f"expected a number but found {self.shown(start)}")
        literal = match.group()
        self.pos = match.end()
        sign = "-" if literal.startswith("-") else ""
        unsigned = literal.lstrip("+-")
        if literal.startswith("+"):
            self.error(start, f"numbers cannot start with '+': write {literal[1:]}")
        if len(unsigned) > 1 and unsigned[0] == "0" and unsigned[1].isdigit():
            self.error(start, "numbers cannot have leading zeros: write "
                              f"{sign}{_without_leading_zeros(unsigned)}")
        if not unsigned.isdigit():
            return float(literal)
        if len(unsigned) > _LONGEST_INTEGER:
            # Valid JSON, but no configuration value is near this size; Python refuses to
            # convert such text (and it would take long), so it stands for "too large".
            return float(f"{sign}inf")
        return int(literal)

    def opened(self, line: int) -> str:
        return f"opened on line {line}"

    def group(self, start: int, line: int, column: int) -> JObject:
        node = JObject(line, column)
        self.enter(start)
        self.pos += 1
        seen: dict[str, int] = {}
        last_end = self.pos
        expecting_member = True
        while True:
            self.skip()
            char = self.peek()
            if char == "}":
                self.pos += 1
                self.depth -= 1
                return node
            if not char:
                raise self.stop(start, f"the group '{{' {self.opened(line)} is never closed with '}}'")
            if char == ",":
                if expecting_member:
                    self.error(self.pos, "extra comma: there is no name and value before it")
                comma = self.pos
                self.pos += 1
                self.skip()
                if self.peek() == "}":
                    self.error(comma, "extra comma after the last value of the group: remove it")
                expecting_member = True
                last_end = self.pos
                continue
            if char == "]":
                raise self.stop(self.pos, f"found ']' but the group '{{' {self.opened(line)} needs '}}'")
            if not expecting_member:
                self.error(last_end, self.missing_comma(last_end))
            key_at = self.pos
            key_line, key_column = self.where(key_at)
            plain = _PLAIN_KEY.match(self.text, key_at)
            if plain is not None:
                key = plain.group(1)
                self.pos = plain.end()
            else:
                key = self.key()
                self.skip()
                if self.peek() == ":":
                    self.pos += 1
                elif not self.peek():
                    raise self.stop(self.pos, f'the file ends after the name "{key}"')
                else:
                    self.error(self.pos, f"missing ':' after the name \"{key}\"")
            value = self.value()
            if key in seen:
                self.error(key_at, f"the name \"{key}\" appears twice in this group "
                                   f"(first on line {seen[key]}); keep only one")
            else:
                seen[key] = key_line
            node.members.append(Member(key, key_line, key_column, value))
            last_end = self.pos
            expecting_member = False

    def key(self) -> str:
        char = self.peek()
        if char and char in "\"'":
            return self.string()
        word = _WORD.match(self.text, self.pos)
        if word:
            self.error(self.pos, f'names must be in double quotes: write "{word.group()}"')
            self.pos = word.end()
            return word.group()
        raise self.stop(self.pos, f"expected a name in double quotes but found {self.shown(self.pos)}")

    def missing_comma(self, offset: int) -> str:
        line, _ = self.where(offset)
        return f"missing comma after the value that ends on line {line}?"

    def array(self, start: int, line: int, column: int) -> JArray:
        node = JArray(line, column)
        self.enter(start)
        self.pos += 1
        last_end = self.pos
        expecting_item = True
        while True:
            self.skip()
            char = self.peek()
            if char == "]":
                self.pos += 1
                self.depth -= 1
                return node
            if not char:
                raise self.stop(start, f"the list '[' {self.opened(line)} is never closed with ']'")
            if char == ",":
                if expecting_item:
                    self.error(self.pos, "extra comma: there is no value before it")
                comma = self.pos
                self.pos += 1
                self.skip()
                if self.peek() == "]":
                    self.error(comma, "extra comma after the last value of the list: remove it")
                expecting_item = True
                continue
            if char == "}":
                raise self.stop(self.pos, f"found '}}' but the list '[' {self.opened(line)} needs ']'")
            if not expecting_item:
                self.error(last_end, self.missing_comma(last_end))
            node.items.append(self.value())
            last_end = self.pos
            expecting_item = False

    def enter(self, offset: int) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            self.enter_too_deep(offset)

    def enter_too_deep(self, offset: int) -> None:
        raise self.stop(offset, f"groups and lists are nested more than {MAX_DEPTH} deep; "
                                "a configuration needs far fewer")


def plain_scalar(text: str) -> tuple[Scalar] | None:
    """``(value,)`` when ``text`` is exactly one of the common values the reader reads at
    once (text without escapes, a whole number of up to 18 digits, true, false, null),
    read as the reader reads it; else None."""
    found = _PLAIN_SCALAR.match(text)
    if found is None or found.end() != len(text):
        return None
    quoted, whole, word = found.groups()
    if quoted is not None:
        return (quoted,)
    if whole is not None:
        return (int(whole),)
    return (None if word == "null" else word == "true",)


def parse(text: str, filename: str = "") -> tuple[Node | None, list[Problem]]:
    """Read ``text``; return the tree (None when unreadable) and the problems found."""
    reader = _Parser(text, filename)
    try:
        reader.skip()
        if reader.pos >= len(text):
            reader.error(0, "the file is empty: a configuration is a group that starts with '{'")
            return None, reader.problems.listed()
        root = reader.value()
        reader.skip()
        if reader.pos < len(text):
            reader.error(reader.pos, f"unexpected {reader.shown(reader.pos)} after the end of the "
                                     "configuration; the whole file must be one group { ... }")
    except _Stop:
        return None, reader.problems.listed()
    return root, reader.problems.listed()


__all__ = ["MAX_DEPTH", "MAX_SYNTAX_PROBLEMS", "MAX_VALUES", "JArray", "JObject", "JScalar", "Member", "Node", "describe", "parse", "plain_scalar"]
