"""The client's sans-IO framing: lines in pieces, replies, events and garbage."""

from __future__ import annotations

import json

from hypothesis import given
from hypothesis import strategies as st

from moas_gui.client.codec import ClientCodec, Event, Garbled, Reply


def test_lines_split_anywhere_are_put_back_together() -> None:
    codec = ClientCodec()
    data = b'{"id": 1, "ok": true, "result": {"tx": 3}}\r\n{"event": "radio", "station": 1}\n'
    out = []
    for byte in data:
        out += codec.feed(bytes([byte]))
    assert out == [Reply(1, True, {"tx": 3}),
                   Event("radio", {"event": "radio", "station": 1})]


def test_a_refusal_carries_its_code_and_sentence() -> None:
    codec = ClientCodec()
    line = b'{"id": 7, "ok": false, "error": {"code": "unavailable", "message": "in use"}}\n'
    assert codec.feed(line) == [Reply(7, False, {}, "unavailable", "in use")]


def test_garbage_is_named_by_line_and_the_next_line_still_counts() -> None:
    codec = ClientCodec()
    out = codec.feed(b'not json\n"a string"\n{"x": 1}\n\n{"id": 2, "ok": true}\n')
    assert [type(item) for item in out] == [Garbled, Garbled, Garbled, Reply]
    assert out[0].reason.startswith("line 1 is not JSON")  # type: ignore[union-attr]
    assert out[1].reason == "line 2 is a JSON str, not an object"  # type: ignore[union-attr]
    assert "line 3 is neither a reply" in out[2].reason  # type: ignore[union-attr]


def test_an_overlong_line_is_skipped_once_and_reading_resumes() -> None:
    codec = ClientCodec(max_line=100)
    out = codec.feed(b"x" * 150)
    out += codec.feed(b"y" * 150 + b'\n{"id": 1, "ok": true}\n')
    assert out == [Garbled("line 1 is longer than 100 bytes; skipped"), Reply(1, True, {})]


def test_requests_are_numbered_and_written_as_one_line() -> None:
    codec = ClientCodec()
    first, data = codec.encode("select", {"station": 1, "radio": 1, "antenna": 3})
    second, _ = codec.encode("state")
    assert (first, second) == (1, 2)
    assert data.endswith(b"\n") and data.count(b"\n") == 1
    assert json.loads(data) == {"id": 1, "cmd": "select", "station": 1, "radio": 1, "antenna": 3}


@given(st.lists(st.binary(max_size=200), max_size=20))
def test_any_bytes_give_items_never_an_exception(chunks: list[bytes]) -> None:
    codec = ClientCodec(max_line=1000)
    for chunk in chunks:
        for item in codec.feed(chunk):
            assert isinstance(item, Reply | Event | Garbled)
