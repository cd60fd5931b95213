"""A rule of the codebase: no nested event loops (see docs/architecture.md).

Under qasync a dialog's or menu's ``exec()`` runs a second event loop inside
the first; called from a coroutine or a callback an asyncio task runs, it
stops every other task (the client port, the switch links, the hand-over)
until the dialog closes, and qasync then fails with "Cannot enter into task".
Questions are asked with ``open()`` and signals instead.  This test reads
every module of ``moas_gui`` and fails on any call that runs a nested loop:
``.exec()``/``.exec_()`` and the static helpers that call it (QMessageBox.question,
QFileDialog.getOpenFileName, ...), unless the call is in ``VETTED`` with a reason.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

from import_reader import nodes

PACKAGE = Path(__file__).resolve().parents[2] / "moas_gui"

VETTED: dict[str, str] = {
    # "moas_gui/some/module.py:LINE": "why this exec() never runs under a task",
    "moas_gui/ui/launch_message.py:73": "the refused launch's message window runs before "
                                        "any event loop exists, then the process exits",
}
"""Calls allowed anyway, by file and line, each with the reason it is safe."""

BLOCKING_STATICS = {
    "QMessageBox": {"question", "warning", "critical", "information", "about", "aboutQt"},
    "QFileDialog": {"getOpenFileName", "getOpenFileNames", "getSaveFileName",
                    "getExistingDirectory", "getOpenFileUrl", "getSaveFileUrl",
                    "getExistingDirectoryUrl", "getOpenFileUrls"},
    "QInputDialog": {"getText", "getInt", "getDouble", "getItem", "getMultiLineText"},
    "QColorDialog": {"getColor"},
    "QFontDialog": {"getFont"},
}


def nested_loop_calls(source: str | Iterable[ast.AST], filename: str) -> list[str]:
    """``file:line: call`` for every call in ``source`` (a module's text, or its nodes)
    that would run a nested loop."""
    found = []
    for node in ast.walk(ast.parse(source, filename)) if isinstance(source, str) else source:
        if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute):
            continue
        name = node.func.attr
        owner = node.func.value
        if name in ("exec", "exec_"):
            found.append(f"{filename}:{node.lineno}: .{name}()")
        elif isinstance(owner, ast.Name) and name in BLOCKING_STATICS.get(owner.id, ()):
            found.append(f"{filename}:{node.lineno}: {owner.id}.{name}()")
    return found


def test_the_scanner_finds_each_kind_of_nested_loop() -> None:
    sample = (
        "box.exec()\n"
        "menu.exec_(point)\n"
        "QMessageBox.question(parent, 'a', 'b')\n"
        "QFileDialog.getOpenFileName(parent)\n"
        "QInputDialog.getText(parent, 't', 'l')\n"
        "box.open()\n"
        "QMessageBox(parent).open()\n"
        "subprocess.exec_command()\n"
    )
    assert [line.split(": ", 1)[1] for line in nested_loop_calls(sample, "x.py")] == [
        ".exec()", ".exec_()", "QMessageBox.question()", "QFileDialog.getOpenFileName()",
        "QInputDialog.getText()"]


def test_no_module_runs_a_nested_event_loop() -> None:
    root = PACKAGE.parent
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        name = path.relative_to(root).as_posix()
        found += nested_loop_calls(nodes(path), name)
    unvetted = [f for f in found if ":".join(f.split(":")[:2]) not in VETTED]
    assert unvetted == [], (
        "these calls run a nested event loop; ask with open() and signals instead "
        "(docs/architecture.md):\n" + "\n".join(unvetted))
