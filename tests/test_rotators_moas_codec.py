"""The MOAS Rotator protocol codec (appendix B), both ends."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.rotators.moas_rotator_codec import (
    BadLine,
    Configure,
    HeadingReport,
    LineSplitter,
    ReportDecoder,
    Rotate,
    Scale,
    Stop,
    VersionQuery,
    VersionReport,
    encode_configure,
    encode_heading,
    encode_rotate,
    encode_stop,
    encode_version,
    model_field,
    parse_command,
)


def test_commands_end_with_cr_and_put_the_model_before_the_port() -> None:
    assert encode_version() == b"VERSION\r"
    assert encode_configure(0, "2", "COM14", 2000) == b"CONFIGURE 0 2 COM14 2000\r"
    assert encode_rotate(3, 123.6) == b"ROTATE 3 124\r"
    assert encode_stop(3) == b"STOP 3\r"


@pytest.mark.parametrize(("name", "field", "scale"), [
    ("DCU1", "1", Scale.COMPASS), ("RotorEZ", "2", Scale.COMPASS),
    ("Yaesu", "4", Scale.FROM_CCW_STOP), ("Alfaspid", "5", Scale.FROM_CCW_STOP),
    ("RC2800P-A", "8", Scale.FROM_CCW_STOP), ("RC2800P-X", "9", Scale.FROM_CCW_STOP),
    ("Prosistel D", "10", Scale.FROM_CCW_STOP), ("prosistel-d", "10", Scale.FROM_CCW_STOP),
    ("rotor ez", "2", Scale.COMPASS), ("4", "4", Scale.FROM_CCW_STOP),
    ("GS-232A", "GS-232A", Scale.FROM_CCW_STOP),
])
def test_model_names_become_the_numbers_of_appendix_b(name: str, field: str, scale: Scale) -> None:
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
        BadLine("3 north", "heading 'north' is not a number", 3),
        BadLine("3 1 2", "a heading report has exactly two fields", 3),
        BadLine("hello world", "neither a VERSION line nor '<rotator> <degrees>'"),
    ]


def test_an_endless_line_is_dropped_once_and_the_stream_recovers() -> None:
    splitter = LineSplitter(max_line=16)
    out = splitter.feed(b"x" * 40 + b"\r1 5\r")
    assert isinstance(out[0], BadLine) and "longer than 16" in out[0].reason
    assert out[1:] == ["1 5"]


@given(st.binary(max_size=300))
def test_the_decoder_survives_any_bytes(data: bytes) -> None:
    decoder = ReportDecoder()
    decoder.feed(data)
    assert decoder.feed(b"\r7 12\r")[-1] == HeadingReport(7, 12.0)


@pytest.mark.parametrize(("line", "command"), [
    ("VERSION", VersionQuery()),
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
    assert isinstance(parse_command(line), BadLine)
