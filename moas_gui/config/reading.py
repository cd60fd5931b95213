"""Turning located JSON values into typed values, with a sentence for each mistake.

A *kind* is a function ``(node, reading, label) -> value`` that returns
:data:`BAD` after recording an error.  A :class:`GroupSpec` lists the names a
group may hold, each with its attribute, kind, whether it is required and its
default; :meth:`Reading.group` applies it and remembers where every built
object came from, so later checks can point at the right line.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .jsontree import JArray, JObject, JScalar, Member, Node, describe
from .problems import ProblemList, Severity

INT32_MIN = -2_147_483_648
INT32_MAX = 2_147_483_647
SHOWN_ITEM_PROBLEMS = 5
"""A list of plain values reports this many wrong items, then how many more there are."""


class _Bad:
    def __repr__(self) -> str:
        return "BAD"


BAD: Any = _Bad()
"""Returned by a kind when the value was wrong (the error is already recorded)."""

Kind = Callable[[Node, "Reading", str], Any]


class Reading:
    """Collects problems and remembers which JSON group each object came from."""

    def __init__(self, filename: str) -> None:
        self.filename = filename
        self.problems = ProblemList(filename)
        """Every problem found (a few of each kind listed, the rest counted)."""
        self._origin: dict[int, JObject] = {}
        self._keep: list[object] = []
        self._items: dict[int, dict[object, JScalar]] = {}

    # -- messages --------------------------------------------------------------
    def error(self, node: Node | Member | None, message: str) -> None:
        self._add(node, Severity.ERROR, message)

    def warning(self, node: Node | Member | None, message: str) -> None:
        self._add(node, Severity.WARNING, message)

    def _add(self, node: Node | Member | None, severity: Severity, message: str) -> None:
        line, column = (node.line, node.column) if node is not None else (0, 0)
        self.problems.add(line, column, severity, message)

    # -- where objects came from ------------------------------------------------
    def remember(self, obj: object, node: JObject) -> None:
        self._origin[id(obj)] = node
        self._keep.append(obj)

    def node_of(self, obj: object) -> JObject | None:
        return self._origin.get(id(obj))

    def at(self, obj: object, key: str | None = None, value: object = None) -> Node | Member | None:
        """The place of ``obj`` (or of its ``key``, or of ``value`` inside that list)."""
        node = self._origin.get(id(obj))
        if node is None or key is None:
            return node
        member = node.get(key)
        if member is None:
            return node
        if value is not None and isinstance(member.value, JArray):
            item = self._first_items(member.value).get(value)
            if item is not None:
                return item
        if value is not None and isinstance(member.value, JScalar):
            return member.value
        return member

    def _first_items(self, array: JArray) -> dict[object, JScalar]:
        """Each value of ``array`` to its first item (built once, so a lookup is quick)."""
        index = self._items.get(id(array))
        if index is None:
            index = {}
            for item in array.items:
                if isinstance(item, JScalar) and item.value is not None \
                        and not isinstance(item.value, bool):
                    index.setdefault(item.value, item)
            self._items[id(array)] = index
        return index

    # -- groups ----------------------------------------------------------------
    def group(self, node: Node, spec: GroupSpec, label: str) -> Any:
        if not isinstance(node, JObject):
            self.error(node, f"{label} must be a group {{ ... }}, not {describe(node)}")
            return BAD
        values: dict[str, Any] = {}
        ok = True
        for member in node.members:
            field_spec = spec.fields.get(member.key)
            if field_spec is None:
                self.warning(member, _unknown(member.key, spec, label))
                continue
            value = field_spec.kind(member.value, self, f'"{member.key}" of {label}')
            if value is BAD:
                # The error is recorded; an optional value falls back to its default so
                # that the rest of the file is still checked, a required one drops the group.
                ok = ok and not field_spec.required
            elif field_spec.attr:
                values[field_spec.attr] = value
        for key, field_spec in spec.fields.items():
            if field_spec.required and node.get(key) is None:
                self.error(node, f'{label} needs "{key}" ({field_spec.meaning})')
                ok = False
        if not ok:
            return BAD
        try:
            obj = spec.build(values)
        except ValueError as exc:  # a builder's own consistency check
            self.error(node, f"{label}: {exc}")
            return BAD
        self.remember(obj, node)
        return obj


def _unknown(key: str, spec: GroupSpec, label: str) -> str:
    import difflib  # only for a key the file misspelt

    close = difflib.get_close_matches(key, list(spec.fields), n=1, cutoff=0.6)
    hint = f' (did you mean "{close[0]}"?)' if close else ""
    return f'unknown name "{key}" in {label}{hint}; it is ignored'


@dataclass(frozen=True, slots=True)
class Field:
    """How one key of a group is read: the attribute it fills (None: read and checked
    only), its kind, whether the group needs it, and what it means (for the message when
    it is missing)."""

    attr: str | None
    kind: Kind
    required: bool = False
    meaning: str = ""


@dataclass(frozen=True, slots=True)
class GroupSpec:
    """How a group is read: its keys, and what builds the object from their values."""

    fields: dict[str, Field]
    build: Callable[[dict[str, Any]], object]


# -- kinds ----------------------------------------------------------------------
def _scalar(node: Node) -> JScalar | None:
    return node if isinstance(node, JScalar) else None


def integer(low: int = INT32_MIN, high: int = INT32_MAX, what: str = "a whole number") -> Kind:
    def kind(node: Node, reading: Reading, label: str) -> Any:
        scalar = _scalar(node)
        value = scalar.value if scalar else None
        if scalar is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            if isinstance(node, JArray) and len(node.items) == 1:
                reading.error(node, f"{label} must be a single number, not a list")
            elif scalar is not None and isinstance(value, str) and value.strip().lstrip("-").isdigit():
                reading.error(node, f'{label} must be a number without quotes: write {value.strip()}, not "{value}"')
            else:
                reading.error(node, f"{label} must be {what}, not {describe(node)}")
            return BAD
        if isinstance(value, float) and math.isinf(value):
            reading.error(node, f"{label} is far too {'large' if value > 0 else 'small'}; "
                                f"it must be from {low:,} to {high:,}")
            return BAD
        if isinstance(value, float) and not value.is_integer():
            reading.error(node, f"{label} must be {what}, not {value}")
            return BAD
        number = int(value)
        if number < INT32_MIN or number > INT32_MAX:
            reading.error(node, f"{label} is {number}, beyond the largest number a configuration "
                                f"may hold ({INT32_MAX:,})")
            return BAD
        if not low <= number <= high:
            reading.error(node, f"{label} is {number}; it must be from {low} to {high}")
            return BAD
        return number
    return kind


def number(low: float = 0, high: float = INT32_MAX) -> Kind:
    def kind(node: Node, reading: Reading, label: str) -> Any:
        scalar = _scalar(node)
        value = scalar.value if scalar else None
        if scalar is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            if scalar is not None and isinstance(value, str):
                try:
                    float(value)
                except ValueError:
                    pass
                else:
                    reading.error(node, f'{label} must be a number without quotes: write {value}, not "{value}"')
                    return BAD
            reading.error(node, f"{label} must be a number, not {describe(node)}")
            return BAD
        if not low <= value <= high:
            shown = f"far too {'large' if value > 0 else 'small'}" if math.isinf(value) \
                else f"{value}"
            reading.error(node, f"{label} is {shown}; it must be from {low:g} to {high:g}")
            return BAD
        return value
    return kind


def boolean(node: Node, reading: Reading, label: str) -> Any:
    scalar = _scalar(node)
    if scalar is None or not isinstance(scalar.value, bool):
        hint = ""
        if scalar is not None and isinstance(scalar.value, str) and scalar.value.lower() in ("true", "false"):
            hint = f": write {scalar.value.lower()} without quotes"
        reading.error(node, f"{label} must be true or false, not {describe(node)}{hint}")
        return BAD
    return scalar.value


def text(node: Node, reading: Reading, label: str) -> Any:
    scalar = _scalar(node)
    if scalar is None or not isinstance(scalar.value, str):
        reading.error(node, f'{label} must be a text in double quotes, not {describe(node)}')
        return BAD
    return scalar.value


def one_of(*choices: str) -> Kind:
    def kind(node: Node, reading: Reading, label: str) -> Any:
        value = text(node, reading, label)
        if value is BAD:
            return BAD
        if value not in choices:
            match = [c for c in choices if c.lower() == value.lower()]
            hint = f' (names are case-sensitive: write "{match[0]}")' if match else ""
            listed = ", ".join(f'"{c}"' for c in choices)
            reading.error(node, f'{label} is "{value}"; it must be one of {listed}{hint}')
            return BAD
        return value
    return kind


def list_of(item: Kind, convert: Callable[[list[Any]], Any] = tuple) -> Kind:
    def kind(node: Node, reading: Reading, label: str) -> Any:
        if not isinstance(node, JArray):
            if isinstance(node, JScalar) and node.value is not None:
                shown = describe(node).replace("the number ", "").replace("the text ", "")
                reading.error(node, f"{label} must be a list, even of one value: write [{shown}]")
            else:
                reading.error(node, f"{label} must be a list [ ... ], not {describe(node)}")
            return BAD
        values = []
        failed = 0
        first_hidden: Node | None = None
        for index, child in enumerate(node.items):
            # Plain values wrong by the thousand are one mistake: show a few, then count.
            hide = failed >= SHOWN_ITEM_PROBLEMS and not isinstance(child, JObject)
            reading.problems.muted += hide
            try:
                value = item(child, reading, f"item {index + 1} of {label}")
            finally:
                reading.problems.muted -= hide
            if value is not BAD:  # the error is recorded; check the rest without it
                values.append(value)
            elif not isinstance(child, JObject):
                failed += 1
                if hide:
                    first_hidden = first_hidden or child
        if first_hidden is not None:
            reading.error(first_hidden, f"{failed - SHOWN_ITEM_PROBLEMS:,} more items of "
                                        f"{label} are wrong too (the first of them is here)")
        return convert(values)
    return kind


def group_of(spec: GroupSpec, what: str) -> Kind:
    def kind(node: Node, reading: Reading, label: str) -> Any:
        return reading.group(node, spec, f"this {what}")
    return kind


def ignored(node: Node, reading: Reading, label: str) -> Any:
    """Accepted and not used (information for clients, e.g. template data)."""
    return None


__all__ = [
    "BAD",
    "INT32_MAX",
    "INT32_MIN",
    "Field",
    "GroupSpec",
    "Kind",
    "Reading",
    "boolean",
    "group_of",
    "ignored",
    "integer",
    "list_of",
    "number",
    "one_of",
    "text",
]
