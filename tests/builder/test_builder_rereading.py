"""An edit that puts a plain value where a value stood on one line gets its tree from the
tree before it (moas_gui/builder/rereading.py) instead of reading the whole text again:
that tree must be the one the reader makes of the text, place by place, on every example
and the manual's, on a file written on one line (where everything after the value moves)
and with tabs and CRLF; and an edit it cannot make that way is read whole."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from moas_gui.builder import Document, document
from moas_gui.config.jsontree import JArray, JObject, JScalar, Node, parse

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted((ROOT / "examples").glob("*.moas")) + sorted((Path(__file__).parent / "manual").glob("*.moas"))
SMALL = (ROOT / "examples" / "small-station.moas").read_text(encoding="utf-8")


def shape(node: Node | None) -> Any:
    """Every node's kind, place and value, and every name's place."""
    if node is None:
        return None
    if isinstance(node, JScalar):
        return ("scalar", node.line, node.column, type(node.value).__name__, node.value)
    if isinstance(node, JObject):
        return ("group", node.line, node.column,
                [(m.key, m.line, m.column, shape(m.value)) for m in node.members])
    assert isinstance(node, JArray)
    return ("list", node.line, node.column, [shape(item) for item in node.items])


def scalars(node: Node, path: tuple[str | int, ...] = ()) -> list[tuple[tuple[str | int, ...], object]]:
    if isinstance(node, JScalar):
        return [(path, node.value)]
    if isinstance(node, JObject):
        return [found for m in node.members for found in scalars(m.value, (*path, m.key))]
    assert isinstance(node, JArray)
    return [found for i, item in enumerate(node.items) for found in scalars(item, (*path, i))]


def other(value: object, turn: int) -> object:
    """A different plain value, longer or shorter by turns (so what follows moves both ways)."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value * 1000 + 7 if turn % 2 else value // 10
    if isinstance(value, str):
        return value + " longer" if turn % 2 else value[:1]
    return 5 if turn % 2 else "text"


class Reads:
    """Counts the whole-text readings of the builder's documents."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.count = 0

        def counted(text: str, filename: str = "") -> Any:
            self.count += 1
            return parse(text, filename)
        monkeypatch.setattr(document, "parse", counted)


def same_as_read(doc: Document) -> None:
    root, problems = parse(doc.text, str(doc.path or ""))
    assert problems == doc.syntax == []
    assert shape(doc.root) == shape(root)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_values_edited_one_by_one_give_the_reader_s_tree(path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    doc = Document.open(path)
    reads = Reads(monkeypatch)
    assert doc.root is not None
    values = scalars(doc.root)
    for turn, (where, value) in enumerate(values[:: max(1, len(values) // 8)]):
        doc.set(where, other(value, turn))
        same_as_read(doc)
    assert reads.count == 0, "every one of these edits is made from the tree before it"
    while doc.can_undo:
        doc.undo()
    same_as_read(doc)


@pytest.mark.parametrize("text", [
    json.dumps(json.loads(SMALL), separators=(",", ":")),
    json.dumps(json.loads(SMALL), indent="\t").replace("\n", "\r\n") + "\r\n",
], ids=["one-line", "tabs-crlf"])
def test_a_file_on_one_line_and_one_with_tabs_and_crlf(text: str,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    doc = Document(text)
    reads = Reads(monkeypatch)
    assert doc.root is not None
    for turn, (where, value) in enumerate(scalars(doc.root)[::9]):
        doc.set(where, other(value, turn))
        same_as_read(doc)
    assert reads.count == 0
    while doc.can_redo or doc.can_undo:
        if not doc.undo():
            break
    assert doc.text == text


def test_what_cannot_be_made_from_the_tree_before_is_read_whole(
        monkeypatch: pytest.MonkeyPatch) -> None:
    doc = Document(SMALL)
    reads = Reads(monkeypatch)
    doc.set(("Antennas", 0, "ShortName"), 'a "quoted" name')  # an escape
    doc.set(("Antennas", 0, "Rotator"), 1.5)  # not a whole number
    doc.set(("Antennas", 0, "Conflicts"), [1, 2])  # a list where a value stood
    doc.set(("Antennas", 0, "Control", 0), 3)  # a plain value where a group stood
    assert reads.count == 4
    same_as_read(doc)
    broken = Document(SMALL.replace('"ShortName": "Tribander",', '"ShortName": "Tribander"', 1))
    assert broken.syntax
    broken.set(("TCPPort",), 12070)  # a file with a mistake: read whole, the mistake kept
    assert reads.count == 6 and broken.syntax and broken.get(("TCPPort",)) == 12070
