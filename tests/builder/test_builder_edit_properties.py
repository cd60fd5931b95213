"""Any sequence of edits keeps the file valid JSON with exactly the values asked for,
and undo takes every one back to the same bytes (Hypothesis, deterministic: conftest)."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moas_gui.builder import Document
from moas_gui.builder.spans import plain

ROOT = Path(__file__).resolve().parents[2]
SMALL = (ROOT / "examples" / "small-station.moas").read_text(encoding="utf-8")
TEXTS = {
    "small-station": SMALL,
    "manual-so2r": (Path(__file__).parent / "manual" / "so2r-40m-beam.moas").read_text(encoding="utf-8"),
    "one-line": json.dumps(json.loads(SMALL), separators=(",", ":")),
    "tabs-crlf": json.dumps(json.loads(SMALL), indent="\t").replace("\n", "\r\n") + "\r\n",
}
"""The examples as written, and one written on one line, and with tabs and CRLF."""

VALUES = st.one_of(st.integers(-5, 70000), st.booleans(), st.text("ab \"\\é", max_size=6),
                   st.lists(st.integers(0, 63), max_size=3),
                   st.fixed_dictionaries({"Station": st.integers(1, 3), "Radio": st.integers(1, 2)}))


def places(value: Any, path: tuple[str | int, ...] = ()) -> list[tuple[tuple[str | int, ...], Any]]:
    out = [(path, value)]
    if isinstance(value, dict):
        for key, child in value.items():
            out += places(child, (*path, key))
    elif isinstance(value, list):
        for index, child in enumerate(value):
            out += places(child, (*path, index))
    return out


def at(data: Any, path: tuple[str | int, ...]) -> Any:
    for step in path:
        data = data[step]
    return data


@pytest.mark.parametrize("name", sorted(TEXTS))
@settings(max_examples=25)
@given(data=st.data())
def test_edits_keep_the_file_valid_and_undo_restores_it(name: str, data: st.DataObject) -> None:
    doc = Document(TEXTS[name])
    original = doc.text
    expected = copy.deepcopy(plain(doc.root))  # type: ignore[arg-type]
    for _ in range(data.draw(st.integers(1, 8))):
        where = places(expected)
        kind = data.draw(st.sampled_from(["set", "insert", "remove", "member"]))
        if kind == "set":
            target, _ = data.draw(st.sampled_from([w for w in where if w[0]]))
            value = data.draw(VALUES)
            doc.set(target, value)
            parent = at(expected, target[:-1])
            parent[target[-1]] = value
        elif kind == "insert":
            lists = [w for w in where if isinstance(w[1], list)]
            target, items = data.draw(st.sampled_from(lists))
            index = data.draw(st.integers(0, len(items)))
            value = data.draw(VALUES)
            doc.insert(target, index, value)
            items.insert(index, value)
        elif kind == "remove":
            target, _ = data.draw(st.sampled_from([w for w in where if w[0]]))
            doc.remove(target)
            del at(expected, target[:-1])[target[-1]]
        else:
            groups = [w for w in where if isinstance(w[1], dict)]
            target, group = data.draw(st.sampled_from(groups))
            key = data.draw(st.sampled_from(["New", "Other", "ID"]))
            value = data.draw(VALUES)
            doc.set((*target, key), value)
            group[key] = value
        assert doc.syntax == [], doc.text
        assert plain(doc.root) == expected  # type: ignore[arg-type]
    final = doc.text
    while doc.can_undo:
        doc.undo()
    assert doc.text == original
    while doc.can_redo:
        doc.redo()
    assert doc.text == final
    if name == "one-line":
        assert "\n" not in doc.text, "a file on one line stays on one line"
    if "\r\n" in original:
        assert doc.text.count("\n") == doc.text.count("\r\n"), "a bare LF crept in"
