"""Reading request lines (moas_gui.net.requests): every command, every kind of mistake."""

from __future__ import annotations

import json
from typing import Any

import pytest

from moas_gui.net.backend import ErrorCode
from moas_gui.net.requests import (
    COMMANDS,
    MAX_DEPTH,
    BadLine,
    InvalidRequest,
    Request,
    describe,
    parse_line,
    too_deep,
)


def parse(obj: Any) -> Request | InvalidRequest | BadLine | None:
    return parse_line(json.dumps(obj).encode())


def request(obj: Any) -> Request:
    parsed = parse(obj)
    assert isinstance(parsed, Request), parsed
    return parsed


def refused(obj: Any) -> InvalidRequest:
    parsed = parse(obj)
    assert isinstance(parsed, InvalidRequest), parsed
    return parsed


def bad_line(line: bytes) -> BadLine:
    parsed = parse_line(line)
    assert isinstance(parsed, BadLine), parsed
    return parsed


GOOD: dict[str, dict[str, Any]] = {
    "hello": {"client": "Button client", "station": 1, "radio": 2, "log": True},
    "state": {},
    "frequency": {"station": 1, "radio": 1, "khz": 14025.5, "tx_khz": 14030},
    "active": {"station": 1, "radio": 2},
    "focus": {"station": 2, "radio": 1},
    "select": {"station": 1, "radio": 1, "antenna": 6, "target": "rx", "exclusive": True},
    "function": {"station": 1, "radio": 1, "function": 0},
    "relative": {"station": 1, "radio": 1, "step": -1},
    "layout": {"station": 1, "radio": 1, "rows": 4, "columns": 3},
    "rotate": {"rotator": 2, "heading": 271.5},
    "stop": {"rotator": 2},
    "stop_switches": {},
    "start_switches": {},
    "reset_switches": {},
    "release": {"station": 1, "radio": 2},
}


def test_the_table_has_every_command_of_the_contract() -> None:
    assert set(COMMANDS) == set(GOOD)


@pytest.mark.parametrize("cmd", sorted(GOOD))
def test_every_command_with_good_arguments_is_a_request(cmd: str) -> None:
    parsed = request({"id": 7, "cmd": cmd, **GOOD[cmd]})
    assert parsed.id == 7 and parsed.cmd == cmd
    for name, value in GOOD[cmd].items():
        assert parsed.args[name] == value


@pytest.mark.parametrize(
    ("cmd", "arg"),
    [(cmd, a.name) for cmd, c in COMMANDS.items() for a in c.args if a.required],
)
def test_each_missing_required_argument_is_named(cmd: str, arg: str) -> None:
    args = {k: v for k, v in GOOD[cmd].items() if k != arg}
    error = refused({"id": "x", "cmd": cmd, **args})
    assert error.id == "x"
    assert error.code is ErrorCode.BAD_REQUEST
    assert error.message.startswith(f'"{arg}" is missing: {cmd} needs ')


WRONG_TYPES = [
    ("hello", "client", 5), ("hello", "client", "x" * 201), ("hello", "log", "yes"),
    ("hello", "station", "1"),
    ("frequency", "station", 1.5), ("frequency", "station", True), ("frequency", "radio", -1),
    ("frequency", "radio", 2_147_483_648), ("frequency", "khz", "14025"),
    ("frequency", "khz", -1), ("frequency", "khz", True), ("frequency", "khz", 10**400),
    ("frequency", "tx_khz", [14025]),
    ("select", "antenna", "3"), ("select", "target", "both!"), ("select", "target", 1),
    ("select", "exclusive", 1), ("function", "function", {}),
    ("relative", "step", 2), ("relative", "step", 0), ("relative", "step", 1.0),
    ("layout", "rows", 0), ("layout", "columns", 1001), ("layout", "rows", 2.5),
    ("rotate", "heading", "north"), ("rotate", "heading", 721), ("rotate", "heading", -361),
    ("rotate", "rotator", -3), ("stop", "rotator", "two"),
]


@pytest.mark.parametrize(("cmd", "arg", "value"), WRONG_TYPES)
def test_each_wrongly_typed_argument_is_named_with_what_was_given(
    cmd: str, arg: str, value: Any
) -> None:
    error = refused({"id": 1, "cmd": cmd, **GOOD[cmd], arg: value})
    assert error.code is ErrorCode.BAD_REQUEST
    assert error.message.startswith(f'"{arg}" must be ')
    assert error.message.endswith(f", not {describe(value)}")


def test_optional_arguments_take_their_defaults() -> None:
    parsed = request({"cmd": "select", "station": 1, "radio": 1, "antenna": 2})
    assert parsed.args["target"] == "both" and parsed.args["exclusive"] is False
    parsed = request({"cmd": "hello", "client": "c"})
    assert parsed.args["log"] is False and parsed.args["station"] is None
    assert request({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7000}).args[
        "tx_khz"] is None


def test_null_is_the_same_as_leaving_an_argument_out() -> None:
    parsed = request({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7000, "tx_khz": None})
    assert parsed.args["tx_khz"] is None
    error = refused({"cmd": "stop", "rotator": None})
    assert error.message.startswith('"rotator" is missing')


def test_whole_frequencies_become_floats() -> None:
    parsed = request({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7000})
    assert isinstance(parsed.args["khz"], float)


def test_unknown_arguments_are_ignored_for_later_protocol_versions() -> None:
    parsed = request({"cmd": "stop", "rotator": 1, "gently": True})
    assert dict(parsed.args) == {"rotator": 1}


def test_without_an_id_the_id_is_null() -> None:
    assert request({"cmd": "state"}).id is None
    assert refused({"cmd": "nope"}).id is None


@pytest.mark.parametrize("request_id", ["abc", 1.5, [1, {"a": None}], {"n": 1}, False, -3])
def test_any_json_id_is_kept(request_id: Any) -> None:
    assert request({"id": request_id, "cmd": "state"}).id == request_id


@pytest.mark.parametrize(
    ("step", "index"), [(None, None), (1, 0)],
)
def test_relative_needs_exactly_one_of_step_and_index(step: Any, index: Any) -> None:
    error = refused({"cmd": "relative", "station": 1, "radio": 1, "step": step, "index": index})
    assert error.code is ErrorCode.BAD_REQUEST
    assert "exactly one of" in error.message


def test_relative_by_index_is_a_request() -> None:
    parsed = request({"cmd": "relative", "station": 1, "radio": 1, "index": 2})
    assert parsed.args["index"] == 2 and parsed.args["step"] is None


def test_an_unknown_command_lists_the_known_ones() -> None:
    error = refused({"id": 3, "cmd": "selekt"})
    assert error.code is ErrorCode.UNKNOWN_CMD
    assert '"selekt"' in error.message and "select" in error.message


def test_a_very_long_unknown_command_name_is_shortened_in_the_message() -> None:
    error = refused({"cmd": "z" * 5000})
    assert error.code is ErrorCode.UNKNOWN_CMD and len(error.message) < 300


def test_a_missing_command_is_a_bad_request() -> None:
    error = refused({"id": 9, "station": 1})
    assert error.code is ErrorCode.BAD_REQUEST and error.message.startswith('"cmd" is missing')


def test_a_command_that_is_not_a_string_is_a_bad_request() -> None:
    error = refused({"id": 9, "cmd": ["state"]})
    assert error.code is ErrorCode.BAD_REQUEST and "must be a string, not a list" in error.message


@pytest.mark.parametrize(
    ("line", "words"),
    [
        (b"hello", "not JSON: Expecting value at column 1"),
        (b'{"cmd": "state"', "not JSON"),
        (b'{"cmd": "state",}', "not JSON"),
        (b"[1, 2]", "but a list, not an object"),
        (b'"state"', 'but the string "state", not an object'),
        (b"42", "but 42, not an object"),
        (b"null", "but null, not an object"),
        (b'{"cmd": "rotate", "rotator": 1, "heading": NaN}', "NaN is not a JSON value"),
        (b'{"id": Infinity}', "Infinity is not a JSON value"),
        (b'{"id": ' + b"9" * 5000 + b"}", "not JSON this server accepts"),
        (b"\xff\xfe{}", "not UTF-8 text (byte 1 is 0xff)"),
        (b'{"cmd": "st\xc3"}', "not UTF-8 text (byte 12 is 0xc3)"),
        (b"[" * 50_000 + b"]" * 50_000, "nested too deeply"),
        (b'{"a":' * 20_000 + b"1" + b"}" * 20_000, "nested too deeply"),
        (b'{"id": 1e999, "cmd": "state"}', "1e999 is too large for a number"),
        (b'{"id": -1E400, "cmd": "state"}', "-1E400 is too large for a number"),
        (b'{"id": ' + b"[" * 980 + b"]" * 980 + b', "cmd": "state"}', "nested too deeply"),
        (b"[" * (MAX_DEPTH + 1) + b"]" * (MAX_DEPTH + 1), f"over {MAX_DEPTH} levels"),
    ],
)
def test_a_line_that_is_not_a_json_object_is_a_bad_line(line: bytes, words: str) -> None:
    assert words in bad_line(line).message


def test_nesting_up_to_the_limit_is_read_and_brackets_in_strings_do_not_count() -> None:
    deepest = b'{"id": ' + b"[" * (MAX_DEPTH - 1) + b"]" * (MAX_DEPTH - 1) + b', "cmd": "state"}'
    parsed = parse_line(deepest)
    assert isinstance(parsed, Request) and parsed.cmd == "state"
    text = json.dumps({"id": "[{" * 5000 + '\\"[', "cmd": "state"})
    assert not too_deep(text)
    parsed = parse_line(text.encode())
    assert isinstance(parsed, Request) and parsed.id.startswith("[{[{")
    assert too_deep("[" * (MAX_DEPTH + 1)) and not too_deep("[]" * 10_000)


@pytest.mark.parametrize("line", [b"", b"   ", b"\t", b"\r"])
def test_a_blank_line_is_not_a_request(line: bytes) -> None:
    assert parse_line(line) is None


def test_utf8_text_in_arguments_is_read() -> None:
    parsed = request({"cmd": "hello", "client": "Ströme ☃"})
    assert parsed.args["client"] == "Ströme ☃"


@pytest.mark.parametrize(
    ("value", "text"),
    [(None, "null"), (True, "true"), (False, "false"), (3, "3"), (2.5, "2.5"),
     (10**30, "a 31-digit number"), ("abc", 'the string "abc"'),
     ("x" * 30, 'the string "' + "x" * 24 + '..."'), ([], "a list"), ({}, "an object")],
)
def test_values_are_described_shortly_with_their_json_type(value: Any, text: str) -> None:
    assert describe(value) == text
