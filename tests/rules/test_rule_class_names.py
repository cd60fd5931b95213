"""Every class of moas_gui has a name no other class of it has: a reader (or a search)
that finds ``Band`` finds one thing.  Classes nested in a function or another class
count too.

The client's copies of the engine's views (``client/model.py``, kept in step with the
server's by ``tests/client/test_client_views_in_step.py``) carry the same names on
purpose: they are the same things seen from the other end of the protocol."""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

from import_reader import nodes

PACKAGE = Path(__file__).resolve().parents[2] / "moas_gui"

MIRRORS = {
    "client/model.py": {"AntennaView", "ButtonType", "ButtonView", "LayoutView", "RadioView",
                        "RotatorView"},
}
"""Classes that may share their name with one elsewhere: the client's copies."""

KNOWN: dict[str, set[str]] = {
}
"""Duplicates known and being removed elsewhere, by file."""


def class_names(root: Path) -> dict[str, list[str]]:
    """Every class name under ``root`` and the files (relative) that define it."""
    found: dict[str, list[str]] = defaultdict(list)
    for path in sorted(root.rglob("*.py")):
        where = path.relative_to(root).as_posix()
        for node in nodes(path):
            if isinstance(node, ast.ClassDef):
                found[node.name].append(where)
    return found


def duplicates(root: Path) -> dict[str, list[str]]:
    """Names defined more than once, less the mirrors and the known ones."""
    shared: dict[str, list[str]] = {}
    for name, places in class_names(root).items():
        counted = [p for p in places
                   if name not in MIRRORS.get(p, set()) and name not in KNOWN.get(p, set())]
        if len(counted) > 1:
            shared[name] = places
    return shared


def test_every_class_name_of_moas_gui_is_its_own() -> None:
    shared = duplicates(PACKAGE)
    assert not shared, "classes sharing a name: " + "; ".join(
        f"{name} in {', '.join(places)}" for name, places in sorted(shared.items()))


def test_the_exceptions_still_exist() -> None:
    """A mirror or a known duplicate that has gone is taken off the lists (so that the
    lists never excuse a name nobody needs excused)."""
    names = class_names(PACKAGE)
    for place, excused in (*MIRRORS.items(), *KNOWN.items()):
        for name in excused:
            assert place in names.get(name, []), f"{name} is no longer in {place}"
            assert len(names[name]) > 1, f"{name} of {place} is unique now: drop it from the list"


def test_the_rule_finds_a_second_class_of_the_same_name(tmp_path: Path) -> None:
    """A deliberately broken copy: two modules each with a ``Band``, and a nested one."""
    (tmp_path / "plan").mkdir()
    (tmp_path / "plan" / "bands.py").write_text("class Band:\n    pass\n")
    (tmp_path / "ag.py").write_text("def f():\n    class Band:\n        pass\n")
    (tmp_path / "client").mkdir()
    (tmp_path / "client" / "model.py").write_text("class RadioView:\n    pass\n")
    (tmp_path / "views.py").write_text("class RadioView:\n    pass\n")
    assert duplicates(tmp_path) == {"Band": ["ag.py", "plan/bands.py"]}
