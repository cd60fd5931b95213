"""The MOAS Rotator protocol codec (appendix B), both ends: the one the server's link,
the MOAS Rotator program and the test stand-in all use."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.rotators.moas_rotator_codec import (
    MAX_COMMAND_LINE,
    BadRotatorLine,
    CommandDecoder,
    Configure,
    HeadingReport,
    HeadingScale,
    ReportDecoder,
    Rotate,
    RotatorLineReader,
    Stop,
    VersionReport,
    VersionRequest,
    encode_configure,
    encode_heading,
    encode_rotate,
    encode_stop,
    encode_version,
    encode_version_reply,
    model_field,
    parse_command,
)


def test_commands_end_with_cr_and_put_the_model_before_the_port() -> None:
    assert encode_version() == b"VERSION\r"
    assert encode_configure(0, "2", "COM14", 2000) == b"CONFIGURE 0 2 COM14 2000\r"
    assert encode_rotate(3, 123.6) == b"ROTATE 3 124\r"
    assert encode_stop(3) == b"STOP 3\r"


@pytest.mark.parametrize(("name", "field", "scale"), [
    ("DCU1", "1", HeadingScale.COMPASS), ("RotorEZ", "2", HeadingScale.COMPASS),
    ("Yaesu", "4", HeadingScale.FROM_CCW_STOP), ("Alfaspid", "5", HeadingScale.FROM_CCW_STOP),
    ("RC2800P-A", "8", HeadingScale.FROM_CCW_STOP), ("RC2800P-X", "9", HeadingScale.FROM_CCW_STOP),
    ("Prosistel D", "10", HeadingScale.FROM_CCW_STOP), ("prosistel-d", "10", HeadingScale.FROM_CCW_STOP),
    ("rotor ez", "2", HeadingScale.COMPASS), ("4", "4", HeadingScale.FROM_CCW_STOP),
    ("GS-232A", "GS-232A", HeadingScale.FROM_CCW_STOP),
])
def test_model_names_become_the_numbers_of_appendix_b(name: str, field: str, scale: HeadingScale) -> None:
    assert model_field(name) == (field, scale)


@pytest.mark.parametrize("name", ["", "Ham IV deluxe"])
def test_a_model_that_cannot_be_sent_is_refused_with_a_sentence(name: str) -> None:
    with pytest.raises(ValueError, match="Model"):
        model_field(name)


def test_a_port_with_a_space_cannot_be_configured() -> None:
    with pytest.raises(ValueError, match="one word"):
        encode_configure(1, "4", "COM 3", 1000)


def test_reports_are_split_on_cr_lf_or_both() -> None:
    decoder = ReportDecoder()
    events = decoder.feed(b"VERSION 1.2\r0 45\n1 270\r\n\r\n2 1")
    assert events == [VersionReport("1.2"), HeadingReport(0, 45.0), HeadingReport(1, 270.0)]
    assert decoder.feed(b"80\r") == [HeadingReport(2, 180.0)]


def test_malformed_reports_say_what_and_name_the_rotator_when_they_can() -> None:
    events = ReportDecoder().feed(b"3 north\r3 1 2\rhello world\r")
    assert events == [
        BadRotatorLine("3 north", "heading 'north' is not a number", 3),
        BadRotatorLine("3 1 2", "a heading report has exactly two fields", 3),
        BadRotatorLine("hello world", "neither a VERSION line nor '<rotator> <degrees>'"),
    ]


def test_an_endless_line_is_dropped_once_and_the_stream_recovers() -> None:
    splitter = RotatorLineReader(max_line=16)
    out = splitter.feed(b"x" * 40 + b"\r1 5\r")
    assert isinstance(out[0], BadRotatorLine) and "longer than 16" in out[0].reason
    assert out[1:] == ["1 5"]


@given(st.binary(max_size=300))
def test_the_decoder_survives_any_bytes(data: bytes) -> None:
    decoder = ReportDecoder()
    decoder.feed(data)
    assert decoder.feed(b"\r7 12\r")[-1] == HeadingReport(7, 12.0)


@pytest.mark.parametrize(("line", "command"), [
    ("VERSION", VersionRequest()),
    ("CONFIGURE 0 2 COM14 2000", Configure(0, "2", "COM14", 2000)),
    ("CONFIGURE 0 COM14 2 2000", Configure(0, "2", "COM14", 2000)),
    ("CONFIGURE 1 GS-232A /dev/ttyUSB0 500", Configure(1, "GS-232A", "/dev/ttyUSB0", 500)),
    ("ROTATE 0 270", Rotate(0, 270.0)),
    ("STOP 0", Stop(0)),
])
def test_the_program_side_reads_every_command(line: str, command: object) -> None:
    assert parse_command(line) == command


def test_the_program_side_reports_headings_as_whole_degrees() -> None:
    assert encode_heading(4, 89.6) == b"4 90\r"


@pytest.mark.parametrize("line", ["ROTATE x 5", "ROTATE 1", "STOP", "CONFIGURE 1 2 COM1"])
def test_the_program_side_refuses_malformed_commands(line: str) -> None:
    assert isinstance(parse_command(line), BadRotatorLine)


# ---- the program side, as the MOAS Rotator program reads it ----------------------------

@pytest.mark.parametrize(
    ("line", "command"),
    [
        ("VERSION", VersionRequest()),
        ("version", VersionRequest()),
        ("CONFIGURE 0 2 COM14 2000", Configure(0, "2", "COM14", 2000)),  # the worked example
        ("CONFIGURE 0 COM14 2 2000", Configure(0, "2", "COM14", 2000)),  # the format line
        ("CONFIGURE 1 Yaesu /dev/ttyUSB0 1000", Configure(1, "Yaesu", "/dev/ttyUSB0", 1000)),
        ("CONFIGURE 1 /dev/ttyUSB0 GS-232A 1000", Configure(1, "GS-232A", "/dev/ttyUSB0", 1000)),
        ("CONFIGURE 2 Prosistel D COM3 500", Configure(2, "Prosistel D", "COM3", 500)),
        ("CONFIGURE 2 COM3 Prosistel D 500", Configure(2, "Prosistel D", "COM3", 500)),
        ("CONFIGURE 9 10 COM3@4800 500", Configure(9, "10", "COM3@4800", 500)),
        ("CONFIGURE  3   4  COM1  1000", Configure(3, "4", "COM1", 1000)),
        ("ROTATE 0 270", Rotate(0, 270.0)),
        ("ROTATE 0 12.5", Rotate(0, 12.5)),
        ("STOP 7", Stop(7)),
    ],
)
def test_commands_are_read_in_every_accepted_form(line: str, command: object) -> None:
    assert parse_command(line) == command


@pytest.mark.parametrize(
    ("line", "reason", "rotator"),
    [
        ("HELLO", "unknown command 'HELLO'", None),
        ("VERSION 2", "VERSION takes no fields", None),
        ("CONFIGURE 0 2 COM14", "CONFIGURE needs <rotator> <model> <port> <poll>", 0),
        ("CONFIGURE x 2 COM14 1000", "rotator number 'x' is not a whole number", None),
        ("CONFIGURE 0 2 COM14 fast", "poll time 'fast' is not a whole number", 0),
        ("CONFIGURE 0 2 3 1000", "no port: both '2' and '3' are numbers", 0),
        ("CONFIGURE 0 COM1 COM2 1000", "neither 'COM1' nor 'COM2' names a model", 0),
        ("ROTATE 3", "ROTATE needs <rotator> <degrees>", 3),
        ("ROTATE 3 north", "heading 'north' is not a number of degrees", 3),
        ("ROTATE 3 inf", "heading 'inf' is not a number of degrees", 3),
        ("ROTATE -1 10", "rotator number '-1' is not a whole number", None),
        ("STOP", "STOP needs <rotator>", None),
        ("STOP 1 2", "STOP needs <rotator>", 1),
    ],
)
def test_bad_commands_say_why_and_which_rotator(line: str, reason: str,
                                                rotator: int | None) -> None:
    bad = parse_command(line)
    assert isinstance(bad, BadRotatorLine)
    assert bad.line == line and reason in bad.reason and bad.rotator == rotator


def test_lines_end_with_cr_lf_or_crlf_and_may_arrive_in_pieces() -> None:
    reader = CommandDecoder()
    assert reader.feed(b"VERSION\r\nSTOP 1\rROT") == [VersionRequest(), Stop(1)]
    assert reader.feed(b"ATE 1 5") == []
    assert reader.feed(b"\n\r\n\r") == [Rotate(1, 5.0)]


def test_a_line_too_long_is_refused_once_and_the_next_line_is_read() -> None:
    reader = CommandDecoder()
    out = reader.feed(b"X" * (MAX_COMMAND_LINE + 1))
    assert len(out) == 1 and isinstance(out[0], BadRotatorLine)
    assert "longer than 512 bytes" in out[0].reason
    assert reader.feed(b"X" * 1000) == []
    assert reader.feed(b"XX\rSTOP 2\r") == [Stop(2)]


def test_eight_bit_bytes_do_not_break_the_reader() -> None:
    out = CommandDecoder().feed(b"ROT\xe9TE 1 5\r\x00\xff\rSTOP 1\r")
    assert isinstance(out[0], BadRotatorLine) and isinstance(out[1], BadRotatorLine)
    assert out[2] == Stop(1)


def test_messages_end_with_cr() -> None:
    assert encode_version_reply("0.1.0") == b"VERSION 0.1\r"
    assert encode_version_reply("2.13") == b"VERSION 2.13\r"
    assert encode_heading(3, 270) == b"3 270\r"


@pytest.mark.parametrize("line", ["ROTATE \u00b2 5", "STOP \u0663", "CONFIGURE \u00b9 4 COM1 100",
                                  "CONFIGURE 1 4 COM1 \u00b2"])
def test_digits_other_than_ascii_are_refused_not_a_crash(line: str) -> None:
    bad = parse_command(line)
    assert isinstance(bad, BadRotatorLine) and "whole number" in bad.reason


@given(st.text(max_size=60))
def test_the_program_side_reads_any_text_without_raising(line: str) -> None:
    assert isinstance(parse_command(line), BadRotatorLine | VersionRequest | Configure | Rotate | Stop)
