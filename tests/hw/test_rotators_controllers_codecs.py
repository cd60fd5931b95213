"""The driver-side codecs: bytes they write, events they read, and how they survive noise."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moas_gui.hw.rotators.controllers import dcu1, prosistel, rc2800, rotorez, spid, yaesu
from moas_gui.hw.rotators.controllers.base import (
    Ack,
    FrameScanner,
    Garbage,
    Heading,
    Notice,
    OutOfRange,
    Send,
)
from moas_gui.hw.rotators.controllers.models import MODELS


def headings(outputs: list[object]) -> list[float]:
    return [o.degrees for o in outputs if isinstance(o, Heading)]


def sent(outputs: list[object]) -> bytes:
    return b"".join(o.data for o in outputs if isinstance(o, Send))


# -- DCU-1 ---------------------------------------------------------------------------------


def test_dcu1_loads_the_bearing_then_starts_after_a_pause() -> None:
    out = dcu1.DCU1Codec().rotate(90, now=0.0)
    assert out == [Send(b"AP1090;", pause=0.5), Send(b"AM1;")]


def test_dcu1_sends_360_as_000_and_rounds_half_up() -> None:
    codec = dcu1.DCU1Codec()
    assert sent(codec.rotate(360, 0.0)).startswith(b"AP1000;")
    assert sent(codec.rotate(89.5, 0.0)).startswith(b"AP1090;")


def test_dcu1_refuses_a_heading_outside_0_to_360_saying_so() -> None:
    with pytest.raises(OutOfRange, match="361 is outside 0..360"):
        dcu1.DCU1Codec().rotate(361, 0.0)


def test_dcu1_reports_the_commanded_heading_once_the_turn_should_be_over() -> None:
    codec = dcu1.DCU1Codec(speed=10.0, settle=1.0)
    codec.rotate(90, now=0.0)
    # Nobody knows where it started: a whole turn is allowed for.
    assert codec.deadline() == pytest.approx(0.5 + 36.0 + 1.0)
    assert codec.tick(30.0) == []
    assert codec.tick(37.5) == [Heading(90.0, estimated=True)]
    assert codec.deadline() is None
    # From a known place, the travel counts; 90 -> 0 is 90 degrees.
    codec.rotate(0, now=100.0)
    assert codec.deadline() == pytest.approx(100.0 + 0.5 + 9.0 + 1.0)


def test_dcu1_goes_the_long_way_round_the_south_stop() -> None:
    codec = dcu1.DCU1Codec(speed=10.0, settle=0.0)
    codec.rotate(170, 0.0)
    codec.tick(100.0)
    codec.rotate(190, now=200.0)  # 170 -> 190 crosses south: 340 degrees through north
    assert codec.deadline() == pytest.approx(200.0 + 0.5 + 34.0)


def test_dcu1_stop_mid_turn_reports_where_the_antenna_should_be() -> None:
    codec = dcu1.DCU1Codec(speed=10.0, settle=0.0)
    codec.rotate(0, 0.0)
    codec.tick(100.0)
    codec.rotate(90, now=100.0)
    out = codec.stop(now=100.5 + 3.0)  # 3 s of turning at 10 deg/s
    assert out == [Send(b"AS1;"), Heading(30.0, estimated=True)]
    assert codec.deadline() is None


def test_dcu1_stop_with_unknown_start_reports_nothing() -> None:
    codec = dcu1.DCU1Codec()
    codec.rotate(90, 0.0)
    assert codec.stop(5.0) == [Send(b"AS1;")]


def test_dcu1_treats_any_byte_it_receives_as_garbage() -> None:
    out = dcu1.DCU1Codec().receive(b"OK\r\n", 0.0)
    assert out == [Garbage(b"OK\r\n", "a DCU-1 never sends anything")]


# -- Rotor-EZ ------------------------------------------------------------------------------


def test_rotorez_polls_with_ai1_and_turns_with_ap1_then_am1() -> None:
    codec = rotorez.RotorEZCodec()
    assert codec.poll(0.0) == [Send(b"AI1;", expects_reply=True)]
    assert codec.rotate(200, 0.0) == [Send(b"AP1200;", pause=0.5), Send(b"AM1;")]
    assert codec.stop(0.0) == [Send(b";")]


def test_rotorez_reads_both_reply_shapes_in_any_pieces() -> None:
    codec = rotorez.RotorEZCodec()
    out: list[object] = []
    for byte in b";123;124":
        out += codec.receive(bytes([byte]), 0.0)
    assert headings(out) == [123.0, 124.0]
    assert headings(rotorez.RotorEZCodec().receive(b"045;046;", 0.0)) == [45.0, 46.0]


def test_rotorez_reports_360_as_0() -> None:
    assert headings(rotorez.RotorEZCodec().receive(b";360", 0.0)) == [0.0]


def test_rotorez_skips_the_power_on_byte_and_says_so() -> None:
    out = rotorez.RotorEZCodec().receive(b"\xe0;123", 0.0)
    assert isinstance(out[0], Garbage) and out[0].data == b"\xe0"
    assert out[1:] == [Heading(123.0)]


def test_rotorez_recognises_the_idiom_text_after_a_bad_command() -> None:
    out = rotorez.RotorEZCodec().receive(b"C2000 IDIOM V1.4S ;090", 0.0)
    assert isinstance(out[0], Notice) and "C2000 IDIOM V1.4S" in out[0].text
    assert out[1:] == [Heading(90.0)]


def test_rotorez_refuses_a_reading_above_360() -> None:
    out = rotorez.RotorEZCodec().receive(b";999;010", 0.0)
    assert headings(out) == [10.0]
    assert any(isinstance(o, Garbage) for o in out)


# -- Yaesu GS-232A/B -----------------------------------------------------------------------


def test_yaesu_polls_with_c_turns_with_m_and_stops_with_s() -> None:
    codec = yaesu.YaesuCodec()
    assert codec.poll(0.0) == [Send(b"C\r", expects_reply=True)]
    assert codec.rotate(5, 0.0) == [Send(b"M005\r")]
    assert codec.rotate(450, 0.0) == [Send(b"M450\r")]
    assert codec.stop(0.0) == [Send(b"S\r")]
    with pytest.raises(OutOfRange):
        codec.rotate(451, 0.0)


@pytest.mark.parametrize(
    ("reply", "degrees"),
    [
        (b"+0123\r\n", 123.0),  # GS-232A, C
        (b"+0123+0045\r\n", 123.0),  # GS-232A, C2
        (b"AZ=123\r\n", 123.0),  # GS-232B, C
        (b"AZ=123  EL=045\r\n", 123.0),  # GS-232B, C2
        (b"AZ=229\r", 229.0),  # a 12PR1A answers C2 with the azimuth only
        (b"AZ=310EL=010\r\n", 310.0),  # K3NG's copy, no spaces
        (b"+0450\r\n", 450.0),  # 450 degree mode
    ],
)
def test_yaesu_reads_every_known_azimuth_reply(reply: bytes, degrees: float) -> None:
    assert headings(yaesu.YaesuCodec().receive(reply, 0.0)) == [degrees]


def test_yaesu_reports_the_error_prompt_and_skips_bare_acknowledgements() -> None:
    out = yaesu.YaesuCodec().receive(b"\r?>\r\n\r+0010\r\n", 0.0)
    assert isinstance(out[0], Notice) and "?>" in out[0].text
    assert out[1:] == [Heading(10.0)]


def test_yaesu_reports_a_line_it_cannot_read_and_carries_on() -> None:
    out = yaesu.YaesuCodec().receive(b"HELLO\r\nAZ=001\r\n", 0.0)
    assert isinstance(out[0], Garbage) and out[0].data == b"HELLO"
    assert out[1:] == [Heading(1.0)]


# -- RC2800 --------------------------------------------------------------------------------


def test_rc2800pa_uses_the_early_protocol() -> None:
    codec = rc2800.RC2800Codec(early=True)
    assert codec.info.number == 8 and codec.info.unsolicited
    assert sent(codec.rotate(200, 0.0)) == b"A\r200\r\r"
    assert sent(codec.poll(0.0)) == b"A\r"
    assert sent(codec.stop(0.0)) == b"A\rS\r"


def test_rc2800px_sets_the_azimuth_in_one_command() -> None:
    codec = rc2800.RC2800Codec(early=False)
    assert codec.info.number == 9 and not codec.info.unsolicited
    assert sent(codec.rotate(200, 0.0)) == b"A200\r"


@pytest.mark.parametrize(
    ("line", "event"),
    [
        (b"A P= 123.0 S=9 ST\n\r", Heading(123.0)),
        (b"A P=  98.1 S=9 MV\n\r", Heading(98.1)),
        (b"A=43.7 S=9 M\r", Heading(43.7)),
        (b"E P=  45.0 S=9 ST\n\r", Ack()),
    ],
)
def test_rc2800_reads_status_lines(line: bytes, event: object) -> None:
    assert rc2800.RC2800Codec().receive(line, 0.0) == [event]


def test_rc2800_reports_an_error_line_and_skips_echoed_commands() -> None:
    out = rc2800.RC2800Codec().receive(b"A200\rA ERR=05\n\r", 0.0)
    assert len(out) == 1 and isinstance(out[0], Notice) and "error 05" in out[0].text


def test_rc2800_finds_a_status_line_after_a_cut_one() -> None:
    out = rc2800.RC2800Codec().receive(b"S=9 MV\n\rA P= 120.5 S=9 MV\n\r", 0.0)
    assert isinstance(out[0], Garbage)
    assert out[1:] == [Heading(120.5)]


# -- SPID ----------------------------------------------------------------------------------


def test_spid_reads_a_rot1prog_answer() -> None:
    assert headings(spid.SpidCodec().receive(bytes([0x57, 3, 7, 2, 0x20]), 0.0)) == [12.0]


def test_spid_reads_a_rot2prog_answer_with_tenths() -> None:
    frame = bytes([0x57, 3, 7, 2, 5, 2, 3, 9, 4, 0, 2, 0x20])
    assert headings(spid.SpidCodec("rot2").receive(frame, 0.0)) == [12.5]


def test_spid_rot1prog_set_frame_matches_the_protocol_example() -> None:
    codec = spid.SpidCodec("rot1")
    assert codec.rotate(123, 0.0) == [Send(bytes.fromhex("57 34 38 33 30 00 00 00 00 00 00 2F 20"))]


def test_spid_rot2prog_waits_for_the_resolution_then_sends_the_set_frame() -> None:
    codec = spid.SpidCodec("rot2")
    assert codec.rotate(123.5, 0.0) == [Send(spid.STATUS, expects_reply=True)]
    answer = bytes([0x57, 4, 8, 3, 0, 2, 4, 3, 7, 0, 2, 0x20])  # az 123.0, el 77.0, PH=PV=2
    out = codec.receive(answer, 0.1)
    assert out == [Heading(123.0),
                   Send(bytes.fromhex("57 30 39 36 37 02 30 38 37 34 02 2F 20"))]
    # Known from now on: the next turn goes out at once.
    assert sent(codec.rotate(0, 1.0)) == b"W0720\x020874\x02\x2f\x20"


def test_alfaspid_learns_the_frame_type_from_the_first_answer() -> None:
    codec = spid.SpidCodec(None)
    assert codec.info.number == 5
    assert codec.rotate(10, 0.0) == [Send(spid.STATUS, expects_reply=True)]
    out = codec.receive(bytes([0x57, 3, 6, 0, 0x20]), 0.1)
    assert out == [Heading(0.0), Send(spid.set_frame_rot1(10))]


def test_spid_stop_expects_the_position_answer() -> None:
    assert spid.SpidCodec().stop(0.0) == [Send(spid.STOP, expects_reply=True)]


def test_spid_skips_a_broken_frame_and_reads_the_next() -> None:
    out = spid.SpidCodec().receive(b"W\x03\x07\xff\x20" + bytes([0x57, 3, 7, 2, 0x20]), 0.0)
    assert isinstance(out[0], Garbage)
    assert headings(out) == [12.0]


# -- Prosistel -----------------------------------------------------------------------------


def test_prosistel_turns_off_continuous_reports_when_the_port_opens() -> None:
    assert prosistel.ProsistelCodec().opening() == [Send(b"\x02AS\r", expects_reply=True)]


def test_prosistel_commands() -> None:
    codec = prosistel.ProsistelCodec()
    assert sent(codec.poll(0.0)) == b"\x02A?\r"
    assert sent(codec.rotate(200, 0.0)) == b"\x02AG200\r"
    assert sent(codec.stop(0.0)) == b"\x02AG997\r"


def test_prosistel_reads_positions_acknowledgements_and_errors() -> None:
    out = prosistel.ProsistelCodec().receive(
        b"\x02A,?,290,R\r\x02A,G,R\r\x02B,?,E,00003\r\x02A,?,1000,R\r", 0.0)
    assert out[0] == Heading(290.0)
    assert out[1] == Ack()
    assert isinstance(out[2], Notice) and "00003" in out[2].text
    assert out[3] == Heading(1000.0)


def test_prosistel_finds_the_next_answer_after_a_broken_one() -> None:
    out = prosistel.ProsistelCodec().receive(b"\x02A,?,29\x02A,?,045,R\r", 0.0)
    assert isinstance(out[0], Garbage)
    assert out[1:] == [Heading(45.0)]


# -- every codec ---------------------------------------------------------------------------


CODECS = [m.codec for m in MODELS]


@pytest.mark.parametrize("make", CODECS, ids=[m.name for m in MODELS])
@settings(max_examples=60, deadline=None)
@given(data=st.binary(max_size=200), cuts=st.lists(st.integers(0, 200), max_size=8))
def test_no_codec_crashes_on_any_bytes_cut_anywhere(make: object, data: bytes,
                                                    cuts: list[int]) -> None:
    whole_codec = make()  # type: ignore[operator]
    pieces_codec = make()  # type: ignore[operator]
    at_once = whole_codec.receive(data, 0.0)
    in_pieces: list[object] = []
    start = 0
    for cut in sorted(set(cuts)) + [len(data)]:
        in_pieces += pieces_codec.receive(data[start:cut], 0.0)
        start = max(start, cut)
    # Cutting the stream differently never changes the headings read from it.
    assert headings(in_pieces) == headings(at_once)
    for item in at_once:
        assert isinstance(item, (Heading, Notice, Ack, Garbage, Send))


def test_frame_scanner_keeps_a_partial_frame_for_later() -> None:
    scanner = FrameScanner(rotorez.match_reply, "test frame")
    assert scanner.feed(b";12") == []
    assert scanner.pending == b";12"
    assert scanner.feed(b"3") == [Heading(123.0)]
