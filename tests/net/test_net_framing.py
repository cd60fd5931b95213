"""Splitting a client's bytes into lines (moas_gui.net.framing)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from moas_gui.net.framing import MAX_LINE, Line, LineFramer, LongLine, request_framer


def feed_all(splitter: LineFramer, *chunks: bytes) -> list[Line | LongLine]:
    out: list[Line | LongLine] = []
    for chunk in chunks:
        out += splitter.feed(chunk)
    return out


def test_lines_end_with_newline_and_a_carriage_return_before_it_is_dropped() -> None:
    assert feed_all(request_framer(), b'{"a":1}\n{"b":2}\r\n') == [
        Line(b'{"a":1}'), Line(b'{"b":2}')
    ]


def test_a_line_without_its_newline_waits_for_the_rest() -> None:
    splitter = request_framer()
    assert splitter.feed(b'{"cmd":') == []
    assert splitter.pending == 7
    assert splitter.feed(b'"state"}\n') == [Line(b'{"cmd":"state"}')]
    assert splitter.pending == 0


def test_a_carriage_return_split_from_its_newline_is_still_dropped() -> None:
    assert feed_all(request_framer(), b"abc\r", b"\n") == [Line(b"abc")]


def test_a_carriage_return_inside_a_line_is_kept() -> None:
    assert feed_all(request_framer(), b"a\rb\n") == [Line(b"a\rb")]


def test_empty_lines_are_returned_empty() -> None:
    assert feed_all(request_framer(), b"\n\r\n") == [Line(b""), Line(b"")]


def test_a_line_of_exactly_the_limit_is_accepted_even_with_crlf() -> None:
    body = b"x" * MAX_LINE
    assert feed_all(request_framer(), body + b"\r\n") == [Line(body)]
    assert feed_all(request_framer(), body[:1000], body[1000:], b"\r", b"\n") == [Line(body)]


def test_a_line_one_byte_over_the_limit_is_long() -> None:
    out = feed_all(request_framer(), b"x" * (MAX_LINE + 1) + b"\n")
    assert out == [LongLine(MAX_LINE + 1)]


def test_a_long_line_is_reported_before_its_end_arrives_and_only_once() -> None:
    splitter = request_framer()
    first = splitter.feed(b"[" * (MAX_LINE + 2))
    assert len(first) == 1 and isinstance(first[0], LongLine)
    assert splitter.pending == 0
    for _ in range(20):
        assert splitter.feed(b"[" * 100_000) == []
        assert splitter.pending == 0
    assert splitter.feed(b"]]]\n{}\n") == [Line(b"{}")]


def test_the_line_after_a_long_one_is_served_normally() -> None:
    out = feed_all(request_framer(), b"y" * 200_000 + b'\n{"cmd":"state"}\n')
    assert out == [LongLine(200_000), Line(b'{"cmd":"state"}')]


def test_a_smaller_limit_can_be_chosen() -> None:
    assert feed_all(request_framer(limit=4), b"abcd\nabcde\n") == [Line(b"abcd"), LongLine(5)]


@given(
    st.lists(st.binary(max_size=300).map(lambda b: b.replace(b"\n", b"")), max_size=20),
    st.lists(st.integers(min_value=1, max_value=97), min_size=1, max_size=50),
)
def test_how_the_bytes_are_cut_into_chunks_never_changes_the_lines(
    lines: list[bytes], cuts: list[int]
) -> None:
    stream = b"".join(line + b"\n" for line in lines)
    whole = request_framer(limit=200).feed(stream)
    splitter = request_framer(limit=200)
    pieces: list[Line | LongLine] = []
    position, i = 0, 0
    while position < len(stream):
        size = cuts[i % len(cuts)]
        pieces += splitter.feed(stream[position : position + size])
        position, i = position + size, i + 1
        assert splitter.pending <= 201
    contents = [b[:-1] if b.endswith(b"\r") else b for b in lines]
    expected = [Line(c) for c in contents if len(c) <= 200]
    assert [p for p in pieces if isinstance(p, Line)] == expected
    assert [p for p in whole if isinstance(p, Line)] == expected
    assert sum(isinstance(p, LongLine) for p in pieces) == len(lines) - len(expected)
