"""The configuration reader's bounds: nesting, values and problems cost little whatever
the file holds, and a file read at once (plain JSON) gives the same tree, with the same
places, as one read step by step."""

from __future__ import annotations

import json
from pathlib import Path

from moas_gui.config import parse_config
from moas_gui.config.jsontree import (
    MAX_DEPTH,
    MAX_SYNTAX_PROBLEMS,
    MAX_VALUES,
    JArray,
    JObject,
    JScalar,
    Node,
    parse,
)
from moas_gui.config.problems import SHOWN_PER_KIND

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def shape(node: Node | None) -> object:
    """A node's tree with every place, to compare two readings."""
    if isinstance(node, JObject):
        return ("{", node.line, node.column,
                [(m.key, m.line, m.column, shape(m.value)) for m in node.members])
    if isinstance(node, JArray):
        return ("[", node.line, node.column, [shape(item) for item in node.items])
    assert isinstance(node, JScalar)
    return (node.line, node.column, node.value)


def test_deep_nesting_is_one_problem_at_its_place() -> None:
    for text in ('{"a":' * 100_000, "[" * 100_000, '{"a": [\n' * 40_000):
        root, problems = parse(text)
        assert root is None
        assert len(problems) == 1, problems
        assert f"nested more than {MAX_DEPTH} deep" in problems[0].message
        # the group or list that goes one level too deep
        opened = [i for i, char in enumerate(text) if char in "{["][MAX_DEPTH]
        line = text.count("\n", 0, opened) + 1
        column = opened - (text.rfind("\n", 0, opened) + 1) + 1
        assert (problems[0].line, problems[0].column) == (line, column)


def test_nesting_up_to_the_limit_is_read() -> None:
    text = "[" * MAX_DEPTH + "]" * MAX_DEPTH
    root, problems = parse(text)
    assert problems == [] and isinstance(root, JArray)


def test_problems_of_a_kind_are_counted_after_a_few() -> None:
    text = "{" + "a 1, " * 300 + "}"
    _root, problems = parse(text)
    unquoted = [p for p in problems if "names must be in double quotes" in p.message]
    assert len(unquoted) == SHOWN_PER_KIND + 1
    summary = unquoted[-1]
    assert "more like this" in summary.message
    assert f"and {300 - SHOWN_PER_KIND - 1:,} more like this" in summary.message
    assert summary.line == 1 and summary.column == 1 + 1 + 5 * SHOWN_PER_KIND


def test_a_file_of_nothing_but_mistakes_stops_the_reading() -> None:
    root, problems = parse("{" + "a{,}" * 1_000_000)
    assert root is None
    assert len(problems) < 100
    assert any(f"after {MAX_SYNTAX_PROBLEMS:,} mistakes" in p.message for p in problems)


def test_too_many_values_is_one_problem_at_the_first_too_many() -> None:
    for text in ('{"A": [' + "1,\n" * (MAX_VALUES + 5) + "1]}",     # read at once
                 '{"A": [' + "1,\n" * (MAX_VALUES + 5) + "1,]}"):   # step by step
        root, problems = parse(text)
        assert root is None
        assert len(problems) == 1, problems
        assert f"more than {MAX_VALUES:,} values" in problems[0].message
        # the group is value 1, the list value 2, so item n is value n + 2
        assert (problems[0].line, problems[0].column) == (MAX_VALUES - 1, 1)


def test_validation_problems_are_counted_after_a_few() -> None:
    data = json.loads((EXAMPLES / "multi-multi-20.moas").read_text())
    for antenna in data["Antennas"]:
        antenna["ShortName"] = 7
    result = parse_config(json.dumps(data, indent=1))
    short = [p for p in result.problems if '"ShortName"' in p.message]
    assert len(data["Antennas"]) > SHOWN_PER_KIND + 1
    assert len(short) == SHOWN_PER_KIND + 1
    more = len(data["Antennas"]) - SHOWN_PER_KIND - 1
    assert f"and {more:,} more like this" in short[-1].message
    assert not result.ok


def test_plain_json_read_at_once_matches_step_by_step_reading() -> None:
    for path in sorted(EXAMPLES.glob("*.moas")):
        text = path.read_text()
        fast, fast_problems = parse(text)
        # a comment at the very end makes the file not plain JSON: the whole file is then
        # read step by step, with the same tree and places (and that one problem)
        slow, slow_problems = parse(text + "\n// end")
        assert fast_problems == []
        assert [p.message for p in slow_problems] == [
            "JSON has no comments: remove the '//' comment"]
        assert shape(fast) == shape(slow), path.name


def test_odd_but_plain_values_are_read_alike() -> None:
    text = ('{"a": [1e999, -0, 1.5E3, "\\u00e9\\n\\"", true, null, false, '
            f'{"9" * 150}, -{"9" * 150}, {{}}, [], {{"b": {{"c": [[]]}}}}]}}')
    fast, problems = parse(text)
    slow, slow_problems = parse(text + " // x")
    assert problems == [] and len(slow_problems) == 1
    assert shape(fast) == shape(slow)
