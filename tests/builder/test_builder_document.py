"""The builder's model layer on real files: every example station and the manual's own
examples (tests/builder/manual, copied from chapter 6 with their spacing, trailing
blanks and mixed indentation), edited value by value.

What must hold: an unchanged file saves to the same bytes; one edit changes only the
lines of that value; undo and redo are exact; saving is atomic and keeps FILE.bak; the
checks' findings point at the field they are about, in --check's words.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from moas_gui.builder import Document, EditError, backup_of
from moas_gui.builder.checking import check_text
from moas_gui.builder.spans import plain
from moas_gui.config import parse_config
from moas_gui.config.jsontree import JArray, JObject, JScalar, Node

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.moas"))
MANUAL = sorted((Path(__file__).parent / "manual").glob("*.moas"))
FILES = EXAMPLES + MANUAL


def test_there_are_eight_examples_and_the_manual_s() -> None:
    assert len(EXAMPLES) == 8
    assert MANUAL


def scalars(node: Node, path: tuple[str | int, ...] = ()) -> list[tuple[tuple[str | int, ...], object]]:
    """Every plain value of a tree with its path."""
    if isinstance(node, JScalar):
        return [(path, node.value)]
    out = []
    if isinstance(node, JObject):
        for member in node.members:
            out += scalars(member.value, (*path, member.key))
    elif isinstance(node, JArray):
        for i, item in enumerate(node.items):
            out += scalars(item, (*path, i))
    return out


def other(value: object) -> object:
    """A different value of the same kind."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 7
    if isinstance(value, float):
        return value + 0.5
    if isinstance(value, str):
        return value + " x"
    return 1


def changed_lines(before: str, after: str) -> tuple[list[str], list[str]]:
    """The lines of ``before`` and of ``after`` between their common first and last lines."""
    old, new = before.splitlines(keepends=True), after.splitlines(keepends=True)
    head = 0
    while head < min(len(old), len(new)) and old[head] == new[head]:
        head += 1
    tail = 0
    while tail < min(len(old), len(new)) - head and old[-1 - tail] == new[-1 - tail]:
        tail += 1
    return old[head : len(old) - tail], new[head : len(new) - tail]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_an_unchanged_file_saves_to_the_same_bytes(path: Path, tmp_path: Path) -> None:
    copy = tmp_path / path.name
    copy.write_bytes(path.read_bytes())
    doc = Document.open(copy)
    assert not doc.modified and doc.diff() == ""
    doc.save()
    assert copy.read_bytes() == path.read_bytes()
    assert backup_of(copy).read_bytes() == path.read_bytes()


def test_line_ends_of_a_windows_file_are_kept(tmp_path: Path) -> None:
    source = MANUAL[0].read_bytes().replace(b"\n", b"\r\n")
    copy = tmp_path / "crlf.moas"
    copy.write_bytes(source)
    doc = Document.open(copy)
    doc.set(("Antennas", 0, "ShortName"), "40 Beam")
    doc.append(("Radios",), {"Station": 2, "Radio": 1, "Switches": [{"Port": 3}]})
    doc.save()
    data = copy.read_bytes()
    assert data.count(b"\n") == data.count(b"\r\n"), "a bare LF crept in"
    doc.undo()
    doc.undo()
    doc.save()
    assert copy.read_bytes() == source


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_each_value_edited_changes_only_its_line_and_undo_restores_it(path: Path) -> None:
    doc = Document.open(path)
    original = doc.text
    assert doc.root is not None
    values = scalars(doc.root)
    step = max(1, len(values) // 60)  # a spread of values of every file, all of the small ones
    for where, value in values[::step]:
        new = other(value)
        doc.set(where, new)
        assert doc.get(where) == new
        gone, came = changed_lines(original, doc.text)
        assert len(gone) == 1 and len(came) == 1, (where, gone, came)
        assert doc.undo()
        assert doc.text == original


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_list_items_added_and_removed_keep_the_rest(path: Path) -> None:
    doc = Document.open(path)
    original = doc.text
    antenna = doc.items(("Antennas",))[0]
    assert isinstance(antenna, dict)
    doc.append(("Antennas", 0, "Conflicts"), 63)
    gone, came = changed_lines(original, doc.text)
    assert len(gone) == len(came) <= 1 and 63 in doc.get(("Antennas", 0, "Conflicts"))  # type: ignore[operator]
    new_antenna = {"ID": 999, "ShortName": "New", "Control": [
        {"LowerFrequency": 14000, "UpperFrequency": 14350,
         "Stations": [{"Station": 1, "Radio": 1, "Relays": [1]}]}]}
    doc.insert(("Antennas",), 1, new_antenna)
    assert doc.get(("Antennas", 1)) == new_antenna
    assert doc.get(("Antennas", 0)) == antenna | {"Conflicts": doc.get(("Antennas", 0, "Conflicts"))}
    doc.remove(("Antennas", 1))
    doc.remove(("Antennas", 0, "Conflicts"))
    gone, came = changed_lines(original, doc.text)
    assert came == [] or all(line.strip() in ("},", "}", "],", "]") for line in came), came
    doc.undo()
    doc.undo()
    doc.undo()
    doc.undo()
    assert doc.text == original
    while doc.can_redo:
        doc.redo()
    assert doc.get(("Antennas", 0)) == {k: v for k, v in antenna.items() if k != "Conflicts"}
    assert parse_config(doc.text).problems is not None


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_unknown_names_and_order_are_kept(path: Path) -> None:
    doc = Document.open(path)
    doc.set(("Radios", 0, "MyOwnNote"), "kept")
    keys = list(doc.get(("Radios", 0)))  # type: ignore[arg-type]
    doc.set(("Radios", 0, "Station"), doc.get(("Radios", 0, "Station")))  # the same value: no edit
    assert list(doc.get(("Radios", 0))) == keys  # type: ignore[arg-type]
    assert keys[-1] == "MyOwnNote"
    assert len(doc.undo_steps) == 1
    result = parse_config(doc.text, "x.moas")
    assert any('unknown name "MyOwnNote"' in p.message for p in result.problems)


def test_new_values_follow_the_file_s_style() -> None:
    doc = Document.open(MANUAL[0])
    doc.set(("Switches", 0, "IndicateTR"), True)
    assert '    "IndicateTR" : true\n' in doc.text, "the manual's ' : ' and indentation"
    doc.append(("Radios", 1, "Always"), {"Station": 1, "Radio": 1})
    added = doc.value_text(("Radios", 1, "Always", 1))
    assert added.splitlines()[1].strip() == '"Station" : 1,', "over lines, like its sibling"
    assert added.endswith("\n        }"), "closed at the sibling's indentation"
    doc.set(("Systems",), [])
    assert doc.text.rstrip().endswith('"Systems" : []\n}')


def test_a_new_group_in_an_inline_list_stays_on_one_line() -> None:
    doc = Document.open(ROOT / "examples" / "small-station.moas")
    before = doc.text
    doc.append(("Antennas", 0, "Control", 0, "Stations"), {"Station": 2, "Radio": 1, "Relays": [9]})
    gone, came = changed_lines(before, doc.text)
    assert came == ['            {"Station": 1, "Radio": 2, "Relays": [4, 27]},\n',
                    '            {"Station": 2, "Radio": 1, "Relays": [9]}\n']
    assert gone == ['            {"Station": 1, "Radio": 2, "Relays": [4, 27]}\n']


def test_a_transaction_is_one_step_and_an_error_undoes_it() -> None:
    doc = Document.open(ROOT / "examples" / "small-station.moas")
    original = doc.text
    with doc.transaction("rename both"):
        doc.set(("Antennas", 0, "ShortName"), "A")
        doc.set(("Antennas", 1, "ShortName"), "B")
    assert len(doc.undo_steps) == 1 and doc.undo_steps[0].what == "rename both"
    doc.undo()
    assert doc.text == original
    with pytest.raises(EditError), doc.transaction("half"):
        doc.set(("Antennas", 0, "ShortName"), "A")
        doc.remove(("Antennas", 99))
    assert doc.text == original and not doc.can_undo


def test_move_reorders_a_list() -> None:
    doc = Document.open(ROOT / "examples" / "small-station.moas")
    buttons = ("Layout", 0, "Matrix", 4, "Buttons")
    first, second = doc.items(buttons)
    doc.move(buttons, 0, 1)
    assert doc.items(buttons) == [second, first]
    doc.undo()
    assert doc.items(buttons) == [first, second]


def test_saving_is_atomic_and_keeps_the_previous_version(tmp_path: Path) -> None:
    target = tmp_path / "station.moas"
    source = (ROOT / "examples" / "small-station.moas").read_bytes()
    target.write_bytes(source)
    doc = Document.open(target)
    doc.set(("TCPPort",), 12070)
    diff = doc.diff()
    assert '-  "TCPPort": 12059,\n+  "TCPPort": 12070,\n' in diff
    doc.save()
    assert backup_of(target).read_bytes() == source
    assert target.read_bytes() == source.replace(b'"TCPPort": 12059', b'"TCPPort": 12070')
    assert sorted(p.name for p in tmp_path.iterdir()) == ["station.moas", "station.moas.bak"]
    assert not doc.modified and doc.diff() == ""


def test_a_file_changed_by_someone_else_is_noticed(tmp_path: Path) -> None:
    target = tmp_path / "station.moas"
    target.write_bytes(MANUAL[0].read_bytes())
    doc = Document.open(target)
    assert not doc.changed_on_disk()
    target.write_text(target.read_text() + "\n")
    assert doc.changed_on_disk()


def test_edits_on_places_that_are_not_there_say_so() -> None:
    doc = Document.open(ROOT / "examples" / "small-station.moas")
    with pytest.raises(EditError, match=r"Antennas\[100\]"):
        doc.remove(("Antennas", 99))
    with pytest.raises(EditError, match="not a list"):
        doc.insert(("TCPPort",), 0, 1)
    broken = Document("{\n  \"Antennas\": [\n}\n")
    with pytest.raises(EditError, match="cannot be read"):
        broken.set(("TCPPort",), 1)


def test_a_missing_list_is_made_where_it_is_wanted() -> None:
    doc = Document.new()
    doc.append(("Switches",), {"ID": 1, "Port": "emulator"})
    doc.set(("TCPPort",), 12059)
    assert plain(doc.root) == {"Switches": [{"ID": 1, "Port": "emulator"}], "TCPPort": 12059}  # type: ignore[arg-type]
    assert doc.text == '{\n  "Switches": [\n    {"ID": 1, "Port": "emulator"}\n  ],\n  "TCPPort": 12059\n}\n'


def test_findings_have_check_s_words_and_point_at_their_field() -> None:
    path = ROOT / "examples" / "small-station.moas"
    doc = Document.open(path)
    doc.set(("Antennas", 0, "Rotator"), 7)
    doc.set(("Antennas", 1, "Conflicts"), [1, 42])
    doc.set(("Radios", 0, "Bogus"), 1)
    checked = check_text(doc.text, str(path), root=doc.root)
    server = parse_config(doc.text, str(path), path)
    assert [f.text for f in checked.findings] == [str(p) for p in server.problems]
    paths = {f.path: f for f in checked.findings}
    assert "uses rotator 7" in paths[("Antennas", 0, "Rotator")].message
    assert "antenna 42" in paths[("Antennas", 1, "Conflicts", 1)].message
    assert paths[("Radios", 0, "Bogus")].severity == "warning"
    assert checked.config is None and len(checked.errors) == 2


def test_the_plan_s_findings_come_too_when_asked() -> None:
    path = ROOT / "examples" / "small-station.moas"
    doc = Document.open(path)
    doc.set(("Antennas", 3, "Control", 0, "Stations"), [])  # 160 m: nobody gets the vertical
    checked = check_text(doc.text, str(path), plan_seconds=30)
    plan = [f for f in checked.findings if f.severity == "finding"]
    assert plan, checked
    assert all(f.text.startswith(f"{path}:") for f in plan)


BROKEN = Path(__file__).parent / "manual-broken" / "systems-functions.moas"
"""The manual's Systems example (6.5.1) as printed, with its missing commas and ``False``,
and its Functions examples (6.6.11)."""


def test_the_manual_s_broken_example_opens_saves_unchanged_and_is_mended(tmp_path: Path) -> None:
    copy = tmp_path / "broken.moas"
    copy.write_bytes(BROKEN.read_bytes())
    doc = Document.open(copy)
    assert [p.message for p in doc.syntax] == [
        "missing comma after the value that ends on line 6?",
        "missing comma after the value that ends on line 7?",
        "write false in lowercase, not False"]
    doc.save()
    assert copy.read_bytes() == BROKEN.read_bytes()
    doc.set(("Functions", 4, "IntParams"), [1])  # values stay editable meanwhile
    assert doc.get(("Functions", 4, "IntParams")) == [1]
    assert doc.repair() == 3 and doc.syntax == []
    gone, came = changed_lines(BROKEN.read_text(encoding="utf-8"), doc.text)
    assert came == ['    "ExclusiveAntennas" : [3, 4, 5, 6],  \n', '    "SharedAntennas" : [10, 11, 12],  \n',
                    '    "Shared" : false\n'] + came[3:]
    assert len(gone) == len(came)
    doc.undo()
    assert len(doc.syntax) == 3


def test_a_scalar_the_reader_read_with_a_mistake_is_written_again() -> None:
    doc = Document.open(BROKEN)
    doc.set(("Systems", 0, "Shared"), False)
    assert '"Shared" : false' in doc.text and len(doc.syntax) == 2


def test_mending_each_kind_of_mistake() -> None:
    doc = Document("{Antennas: [1, 2,], \"X\": True, 'y': None, \"z\": word}")
    assert doc.repair() == 6
    assert doc.text == '{"Antennas": [1, 2], "X": true, "y": null, "z": "word"}'
    assert doc.syntax == [] and doc.undo_steps[-1].what == "mend 6 JSON mistakes"
