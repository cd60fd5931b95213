"""A rule of the codebase: no class of the switch layer above 300 lines or 25 methods.

The switch session, its link and their parts (``moas_gui/hw/moas2/``, the emulator
aside) are each kept to one job a reader can hold at once: a class that grows past
300 lines (its ``class`` line to its last) or 25 methods (every ``def`` in its body,
properties included) is cut into a part of its own (docs/switch.md, "The session's
parts").  Measured from the source with :mod:`ast`, in process.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

from import_reader import nodes

ROOT = Path(__file__).resolve().parent.parent.parent
LAYER = ROOT / "moas_gui" / "hw" / "moas2"
MAX_LINES = 300
MAX_METHODS = 25


def too_big(source: str | Iterable[ast.AST], filename: str) -> list[str]:
    """``file:line Class (N lines, M methods)`` for every class of ``source`` (a module's
    text, or its nodes) above either limit (classes nested in functions or classes
    included)."""
    found = []
    for node in ast.walk(ast.parse(source)) if isinstance(source, str) else source:
        if not isinstance(node, ast.ClassDef):
            continue
        lines = (node.end_lineno or node.lineno) - node.lineno + 1
        methods = sum(isinstance(b, ast.FunctionDef | ast.AsyncFunctionDef) for b in node.body)
        if lines > MAX_LINES or methods > MAX_METHODS:
            found.append(f"{filename}:{node.lineno} {node.name} ({lines} lines, "
                         f"{methods} methods)")
    return found


def _class(name: str, methods: int, padding: int = 0) -> str:
    body = [f"    def m{i}(self) -> int:\n        return {i}\n" for i in range(methods)]
    return f"class {name}:\n" + "".join(body) + "".join(f"    x{i} = {i}\n" for i in range(padding))


def test_a_class_one_method_over_is_named() -> None:
    source = _class("AtTheLimit", MAX_METHODS) + _class("OneTooMany", MAX_METHODS + 1)
    line = _class("AtTheLimit", MAX_METHODS).count("\n") + 1
    assert too_big(source, "made.py") == [
        f"made.py:{line} OneTooMany ({2 * (MAX_METHODS + 1) + 1} lines, 26 methods)"]


def test_a_class_one_line_over_is_named_and_async_methods_count() -> None:
    at = _class("Long", 1, padding=MAX_LINES - 3)
    assert too_big(at, "at.py") == []
    over = _class("Longer", 1, padding=MAX_LINES - 2)
    assert too_big(over, "over.py") == ["over.py:1 Longer (301 lines, 1 methods)"]
    many = "class Waits:\n" + "".join(
        f"    async def w{i}(self) -> None:\n        pass\n" for i in range(MAX_METHODS + 1))
    assert too_big(many, "waits.py") == ["waits.py:1 Waits (53 lines, 26 methods)"]


def test_a_class_of_the_old_sessions_shape_is_caught() -> None:
    """The session as issue 41 found it: one class of 636 lines and 49 methods."""
    folded = _class("SwitchSession", 49, padding=636 - 1 - 2 * 49)
    assert too_big(folded, "session.py") == ["session.py:1 SwitchSession (636 lines, 49 methods)"]


def test_no_class_of_the_switch_layer_is_above_the_limits() -> None:
    found = []
    for path in sorted(LAYER.rglob("*.py")):
        if "emulator" in path.relative_to(LAYER).parts:
            continue
        found += too_big(nodes(path), str(path.relative_to(ROOT)))
    assert not found, (f"classes above {MAX_LINES} lines or {MAX_METHODS} methods: cut each "
                       "into parts with one job each\n" + "\n".join(found))
