"""The JSON reader: positions, and the classic mistakes explained and survived."""

from __future__ import annotations

import json

from hypothesis import example, given, settings
from hypothesis import strategies as st

from moas_gui.config.jsontree import JArray, JObject, JScalar, Node, parse


def messages(text: str) -> list[tuple[int, int, str]]:
    _, problems = parse(text, "t.moas")
    return [(p.line, p.column, p.message) for p in problems]


def plain(node: Node) -> object:
    if isinstance(node, JObject):
        return {m.key: plain(m.value) for m in node.members}
    if isinstance(node, JArray):
        return [plain(i) for i in node.items]
    assert isinstance(node, JScalar)
    return node.value


def test_values_remember_their_line_and_column() -> None:
    root, problems = parse('{\n  "Relays" : [ 1,\n    20 ]\n}')
    assert problems == []
    assert isinstance(root, JObject)
    member = root.get("Relays")
    assert member is not None and (member.line, member.column) == (2, 3)
    assert isinstance(member.value, JArray)
    assert [(i.line, i.column) for i in member.value.items] == [(2, 16), (3, 5)]


def test_missing_comma_between_groups_is_pointed_at_the_end_of_the_first() -> None:
    text = '{"People": [\n  {"First": "Paul"}\n  {"First": "Charlotte" "Last": "R"}\n]}'
    found = messages(text)
    assert found[0][:2] == (2, 20)
    assert "missing comma" in found[0][2]
    assert found[1][:2] == (3, 24)
    assert len(found) == 2


def test_trailing_comma_in_a_list_and_a_group_is_reported_where_the_comma_is() -> None:
    found = messages('{"Relays": [0, 1, ],\n "X": 1,\n}')
    assert [(line, col) for line, col, _ in found] == [(1, 17), (2, 8)]
    assert all("extra comma" in m for _, _, m in found)


def test_capitalised_booleans_are_explained_and_read_as_booleans() -> None:
    root, problems = parse('{"Shared": False, "Enabled": True}')
    assert [p.message for p in problems] == [
        "write false in lowercase, not False", "write true in lowercase, not True"]
    assert plain(root) == {"Shared": False, "Enabled": True}  # type: ignore[arg-type]


def test_unquoted_names_and_single_quotes_are_explained() -> None:
    found = messages("{ID: 4, 'Name': 'x'}")
    assert found[0] == (1, 2, 'names must be in double quotes: write "ID"')
    assert "single quotes" in found[1][2] and found[1][:2] == (1, 9)


def test_duplicate_names_in_one_group_are_errors_with_the_first_line() -> None:
    found = messages('{"Buttons": [],\n "Buttons": []}')
    assert found == [(2, 2, ('the name "Buttons" appears twice in this group (first on line 1); '
                              'keep only one'))]


def test_numbers_with_leading_zeros_or_plus_are_explained() -> None:
    found = messages('{"A": 01, "B": +30}')
    assert [m for _, _, m in found] == ["numbers cannot have leading zeros: write 1",
                                        "numbers cannot start with '+': write 30"]


def test_comments_are_reported_and_skipped() -> None:
    root, problems = parse('{\n // my antennas\n "A": 1 /* one */\n}')
    assert [(p.line, p.column) for p in problems] == [(2, 2), (3, 9)]
    assert plain(root) == {"A": 1}  # type: ignore[arg-type]


def test_an_unclosed_group_names_the_line_that_opened_it() -> None:
    found = messages('{\n "A": {\n  "B": 1\n}')
    assert found == [(1, 1, "the group '{' opened on line 1 is never closed with '}'")]


def test_a_wrong_closing_bracket_is_explained() -> None:
    found = messages('{"A": [1, 2}\n}')
    assert found == [(1, 12, "found '}' but the list '[' opened on line 1 needs ']'")]


def test_empty_file_and_text_after_the_end() -> None:
    assert messages("   \n") == [(1, 1, ("the file is empty: a configuration is a group that "
                                         "starts with '{'"))]
    assert "after the end" in messages('{"A": 1} }')[0][2]


def test_unclosed_text_is_reported_on_its_line() -> None:
    found = messages('{"Name": "40 Beam,\n "ID": 4}')
    assert found[0][:2] == (1, 10) and "not closed" in found[0][2]


def test_deep_nesting_is_refused_without_a_crash() -> None:
    found = messages("[" * 1000 + "]" * 1000)
    assert "nested more than 64 deep" in found[0][2]


json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-2**31, 2**31 - 1) | st.text(max_size=8)
    | st.floats(allow_nan=False, allow_infinity=False),
    lambda children: st.lists(children, max_size=4)
    | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=20)


@settings(max_examples=200, deadline=None)
@given(json_values, st.sampled_from([None, 2]))
def test_valid_json_reads_exactly_as_the_json_module_reads_it(value: object, indent: int | None) -> None:
    text = json.dumps(value, indent=indent, ensure_ascii=False)
    root, problems = parse(text)
    assert problems == []
    assert root is not None and plain(root) == json.loads(text)


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=200))
@example("{A")  # found by benchmarks/bench_properties.py: a file cut short after a bare name
def test_any_text_gives_problems_or_a_tree_never_an_exception(text: str) -> None:
    root, problems = parse(text)
    assert root is not None or problems
    for p in problems:
        assert p.line >= 1 and p.column >= 1 and p.message


def test_a_file_cut_short_after_a_name_or_a_colon_is_explained() -> None:
    assert messages('{"Antennas"') == [(1, 12, 'the file ends after the name "Antennas"')]
    assert messages('{"TCPPort":') == [(1, 12, "the file ends where a value was expected")]
    assert messages('{"TCPPort": ') == [(1, 13, "the file ends where a value was expected")]


def test_a_file_cut_anywhere_gives_problems_never_an_exception() -> None:
    text = '{"Antennas": [{"ID": 1, "Name": "20 m \\u0041", "On": true, "X": -1.5e3}],\n "N": null}'
    for end in range(len(text)):
        root, problems = parse(text[:end])
        assert root is None and problems, text[:end]
        assert all(p.line >= 1 and p.column >= 1 for p in problems)


def test_an_integer_of_thousands_of_digits_is_read_without_a_crash() -> None:
    root, problems = parse('{"TCPPort": ' + "9" * 5000 + ', "B": -' + "1" * 5000 + "}")
    assert problems == []
    assert plain(root) == {"TCPPort": float("inf"), "B": float("-inf")}  # type: ignore[arg-type]


def test_leading_zeros_are_explained_for_any_number() -> None:
    found = messages('{"A": 01e999, "B": -007.5, "C": 00, "D": 0012}')
    assert [m for _, _, m in found] == ["numbers cannot have leading zeros: write 1e999",
                                        "numbers cannot have leading zeros: write -7.5",
                                        "numbers cannot have leading zeros: write 0",
                                        "numbers cannot have leading zeros: write 12"]
