"""Writing replies and events (moas_gui.net.messages)."""

from __future__ import annotations

import json

import pytest

from moas_gui import __version__
from moas_gui.net.backend import ErrorCode
from moas_gui.net.messages import (
    MessageEncodeError,
    encode,
    event,
    hello_result,
    reply_error,
    reply_ok,
)


def test_a_reply_is_one_json_line_with_the_id_echoed() -> None:
    line = reply_ok([1, "a"], {"tx": 3, "rx": None})
    assert line.endswith(b"\n") and line.count(b"\n") == 1
    assert json.loads(line) == {"id": [1, "a"], "ok": True, "result": {"tx": 3, "rx": None}}


def test_an_error_reply_carries_code_and_message() -> None:
    line = reply_error(7, ErrorCode.UNAVAILABLE, "Antenna 4 (40 Beam) is in use")
    assert json.loads(line) == {
        "id": 7, "ok": False,
        "error": {"code": "unavailable", "message": "Antenna 4 (40 Beam) is in use"},
    }


def test_an_event_puts_its_name_first_and_ignores_an_event_key_in_the_body() -> None:
    line = event("radio", {"event": "bogus", "station": 1, "radio": 2})
    assert line.startswith(b'{"event": "radio"')
    assert json.loads(line) == {"event": "radio", "station": 1, "radio": 2}


def test_only_the_contracts_events_can_be_written() -> None:
    with pytest.raises(MessageEncodeError, match="'weather' is not an event"):
        event("weather", {})


def test_text_is_written_as_utf8() -> None:
    line = encode({"message": "Antenne Süd ☃"})
    assert "Antenne Süd ☃".encode() in line


def test_a_lone_surrogate_from_a_client_is_escaped_so_the_line_stays_utf8() -> None:
    request_id = json.loads('"\\ud800x"')
    line = reply_ok(request_id, {})
    line.decode("utf-8")
    assert json.loads(line)["id"] == request_id


@pytest.mark.parametrize("bad", [{1, 2}, float("nan"), object()])
def test_a_value_that_is_not_json_raises_a_clear_error(bad: object) -> None:
    with pytest.raises(MessageEncodeError, match="cannot write dict as JSON"):
        encode({"value": bad})


def test_hello_names_the_server_its_version_and_the_protocol() -> None:
    assert hello_result() == {"server": "moas-gui", "version": __version__, "protocol": 1}
