"""Any bytes into the rigctld, flrig and OTRSP parsers give values or their typed errors."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from moas_gui.sources.base import MAX_KHZ
from moas_gui.sources.flrig_rpc import FlrigReplyError, ResponseParser, hz
from moas_gui.sources.otrsp_command import MAX_LINE, Aux, CommandParser, OtrspError
from moas_gui.sources.rigctld_reply import ReplyParser, RigctldReplyError, RigReading

chunks = st.lists(st.binary(max_size=300), max_size=20)
rigctld_like = st.lists(st.sampled_from([
    b"get_freq:\n", b"Frequency: 14025000\n", b"RPRT 0\n", b"RPRT -11\n", b"get_split_vfo:\n",
    b"Split: 1\n", b"TX VFO: VFOB\n", b"get_split_freq:\n", b"TX Frequency: 9\n", b"get_ptt:\n",
    b"PTT: 1\n", b"\n", b"x", b"Frequency: 1e999\n"]), max_size=40)


@given(chunks)
def test_rigctld_parser_any_bytes(data: list[bytes]) -> None:
    parser = ReplyParser()
    for chunk in data:
        try:
            readings = parser.feed(chunk)
        except RigctldReplyError as exc:
            assert exc.reason
            parser.reset()
            continue
        for r in readings:
            assert isinstance(r, RigReading)


@given(rigctld_like)
def test_rigctld_parser_near_misses(parts: list[bytes]) -> None:
    parser = ReplyParser()
    try:
        readings = parser.feed(b"".join(parts))
    except RigctldReplyError:
        return
    for r in readings:
        for value in (r.rx_hz, r.tx_hz):
            assert value is None or 0 <= value <= MAX_KHZ * 1000


@given(chunks)
def test_flrig_parser_any_bytes(data: list[bytes]) -> None:
    parser = ResponseParser()
    for chunk in data:
        try:
            parser.feed(chunk)
        except FlrigReplyError as exc:
            assert exc.reason
            parser = ResponseParser()


@given(st.one_of(st.text(max_size=30), st.integers(), st.floats(allow_nan=True)))
def test_flrig_frequencies_are_numbers_in_range_or_refused(value: object) -> None:
    try:
        result = hz(value, "rig.get_vfo")
    except FlrigReplyError:
        return
    assert 0 < result <= MAX_KHZ * 1000


@given(chunks)
def test_otrsp_parser_any_bytes(data: list[bytes]) -> None:
    parser = CommandParser()
    for chunk in data:
        for item in parser.feed(chunk):
            if isinstance(item, OtrspError):
                assert item.reason
            elif isinstance(item, Aux):
                assert item.radio in (1, 2) and 0 <= item.value <= 255
    assert parser.pending <= MAX_LINE + 300
