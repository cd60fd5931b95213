"""The one line framer every line protocol reads through (moas_gui.line_framer).

The properties hold for both line-end policies: how the bytes are cut into
``feed`` calls never changes what comes out, and between calls the framer
never holds more than ``limit + 1`` bytes.  The examples pin what each policy
calls an ending and what a too-long line yields.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.line_framer import HEAD, Line, LineEnd, LineFramer, LongLine


def feed_all(framer: LineFramer, *chunks: bytes) -> list[Line | LongLine]:
    out: list[Line | LongLine] = []
    for chunk in chunks:
        out += framer.feed(chunk)
    return out


def shape(items: list[Line | LongLine]) -> list[bytes | None]:
    """The lines, with ``None`` for each long line (its size is how much had come when it
    was given up, which depends on how the bytes were cut)."""
    return [item.data if isinstance(item, Line) else None for item in items]


def one_byte_at_a_time(framer: LineFramer, data: bytes) -> list[Line | LongLine]:
    return feed_all(framer, *(data[i:i + 1] for i in range(len(data))))


# ---- what ends a line ---------------------------------------------------------------------

def test_lf_policy_ends_lines_at_lf_and_drops_a_cr_just_before_it() -> None:
    framer = LineFramer(100, LineEnd.LF)
    assert framer.feed(b"one\ntwo\r\nthr\ree\n\n") == [
        Line(b"one"), Line(b"two"), Line(b"thr\ree"), Line(b"")]


def test_lf_policy_keeps_a_lone_cr_waiting_for_its_line_feed() -> None:
    framer = LineFramer(100, LineEnd.LF)
    assert framer.feed(b"abc\r") == []
    assert framer.pending == 4
    assert framer.feed(b"\n") == [Line(b"abc")]


def test_cr_or_lf_policy_takes_each_of_cr_lf_and_crlf_as_one_ending() -> None:
    framer = LineFramer(100, LineEnd.CR_OR_LF)
    assert framer.feed(b"a\rb\nc\r\nd\n\re") == [
        Line(b"a"), Line(b"b"), Line(b"c"), Line(b"d"), Line(b"")]
    assert framer.pending == 1


def test_cr_or_lf_policy_joins_a_cr_and_an_lf_split_across_feeds() -> None:
    framer = LineFramer(100, LineEnd.CR_OR_LF)
    assert framer.feed(b"TX1\r") == [Line(b"TX1")]
    assert framer.feed(b"") == []
    assert framer.feed(b"\nTX2\r") == [Line(b"TX2")]
    assert framer.feed(b"\r") == [Line(b"")]


# ---- the limit ------------------------------------------------------------------------------

@pytest.mark.parametrize("ends", list(LineEnd))
def test_a_line_of_exactly_the_limit_is_a_line_and_one_more_byte_is_long(ends: LineEnd) -> None:
    assert LineFramer(8, ends).feed(b"12345678\n") == [Line(b"12345678")]
    assert LineFramer(8, ends).feed(b"123456789\n") == [LongLine(9)]


def test_lf_policy_waits_on_limit_plus_a_cr_since_a_crlf_may_follow() -> None:
    framer = LineFramer(8, LineEnd.LF)
    assert framer.feed(b"12345678\r") == []
    assert framer.feed(b"\n") == [Line(b"12345678")]
    assert LineFramer(8, LineEnd.LF).feed(b"12345678x") == [LongLine(9)]


@pytest.mark.parametrize("ends", list(LineEnd))
def test_a_long_line_is_reported_once_before_its_end_and_the_next_line_is_read(
        ends: LineEnd) -> None:
    framer = LineFramer(16, ends)
    first = framer.feed(b"x" * 20)
    assert first == [LongLine(20)]
    assert first[0].head == b"x" * 20
    assert framer.pending == 0
    for _ in range(50):
        assert framer.feed(b"y" * 1000) == []
        assert framer.pending == 0
    assert framer.feed(b"yyy\nnext\n") == [Line(b"next")]


def test_a_long_line_keeps_its_first_bytes_for_the_message() -> None:
    framer = LineFramer(50, LineEnd.LF)
    text = bytes(range(65, 65 + 60))
    (long_line,) = framer.feed(text + b"\n")
    assert isinstance(long_line, LongLine)
    assert long_line.size == 60
    assert long_line.head == text[:HEAD]


def test_a_long_line_that_ends_with_a_cr_is_skipped_with_its_lf() -> None:
    framer = LineFramer(4, LineEnd.CR_OR_LF)
    assert framer.feed(b"abcdef") == [LongLine(6)]
    assert framer.feed(b"gh\r") == []
    assert framer.feed(b"\nok\r") == [Line(b"ok")]


def test_a_negative_limit_is_refused() -> None:
    with pytest.raises(ValueError, match="negative"):
        LineFramer(-1)


# ---- properties -----------------------------------------------------------------------------

PIECES = st.lists(st.sampled_from([b"a", b"bc", b"\r", b"\n", b"\r\n", b"x" * 7, b"\xff"]),
                  max_size=60)


@given(PIECES, st.lists(st.integers(min_value=1, max_value=13), min_size=1, max_size=30),
       st.sampled_from(list(LineEnd)), st.integers(min_value=0, max_value=12))
def test_any_cut_of_the_same_bytes_gives_the_same_items_and_the_bound_holds(
        pieces: list[bytes], cuts: list[int], ends: LineEnd, limit: int) -> None:
    stream = b"".join(pieces)
    whole = LineFramer(limit, ends).feed(stream)
    framer = LineFramer(limit, ends)
    out: list[Line | LongLine] = []
    position = i = 0
    while position < len(stream):
        size = cuts[i % len(cuts)]
        out += framer.feed(stream[position:position + size])
        assert framer.pending <= limit + 1
        position, i = position + size, i + 1
    assert shape(out) == shape(whole)
    assert shape(one_byte_at_a_time(LineFramer(limit, ends), stream)) == shape(whole)


@given(st.lists(st.binary(max_size=40).map(lambda b: b.replace(b"\n", b"").replace(b"\r", b"")),
                max_size=15),
       st.sampled_from([b"\n", b"\r\n"]), st.sampled_from(list(LineEnd)))
def test_every_line_within_the_limit_comes_back_and_every_longer_one_is_one_long_line(
        lines: list[bytes], ending: bytes, ends: LineEnd) -> None:
    limit = 20
    stream = b"".join(line + ending for line in lines)
    out = one_byte_at_a_time(LineFramer(limit, ends), stream)
    assert shape(out) == [line if len(line) <= limit else None for line in lines]
    # Fed a byte at a time, a long line is given up at the first byte that proves it long.
    assert all(item.size == limit + 1 for item in out if isinstance(item, LongLine))


@given(st.binary(max_size=3000), st.sampled_from(list(LineEnd)),
       st.integers(min_value=0, max_value=64))
def test_the_buffer_stays_bounded_whatever_arrives(data: bytes, ends: LineEnd,
                                                     limit: int) -> None:
    framer = LineFramer(limit, ends)
    for start in range(0, len(data), 97):
        for item in framer.feed(data[start:start + 97]):
            if isinstance(item, Line):
                assert len(item.data) <= limit
                assert b"\n" not in item.data
                if ends is LineEnd.CR_OR_LF:
                    assert b"\r" not in item.data
        assert framer.pending <= limit + 1


@pytest.mark.realtime
def test_the_framer_loads_nothing_but_itself() -> None:
    """Every line protocol imports it, so it must bring no loop, port, Qt or other part."""
    probe = ("import sys, moas_gui.line_framer\n"
             "print(sorted(m for m in sys.modules if m.split('.')[0] in "
             "('asyncio', 'serial', 'PySide6', 'socket') or "
             "(m.startswith('moas_gui.') and m != 'moas_gui.line_framer')))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]", done.stdout
