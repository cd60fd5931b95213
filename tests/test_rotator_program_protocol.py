"""The TCP 13020 protocol, without sockets: commands read, messages written."""

from __future__ import annotations

import pytest

from moas_gui.rotator_program.protocol import (
    MAX_LINE,
    BadCommand,
    CommandReader,
    Configure,
    Rotate,
    Stop,
    VersionRequest,
    heading_message,
    parse_command,
    version_message,
)


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
    assert isinstance(bad, BadCommand)
    assert bad.line == line and reason in bad.reason and bad.rotator == rotator


def test_lines_end_with_cr_lf_or_crlf_and_may_arrive_in_pieces() -> None:
    reader = CommandReader()
    assert reader.feed(b"VERSION\r\nSTOP 1\rROT") == [VersionRequest(), Stop(1)]
    assert reader.feed(b"ATE 1 5") == []
    assert reader.feed(b"\n\r\n\r") == [Rotate(1, 5.0)]


def test_a_line_too_long_is_refused_once_and_the_next_line_is_read() -> None:
    reader = CommandReader()
    out = reader.feed(b"X" * (MAX_LINE + 1))
    assert len(out) == 1 and isinstance(out[0], BadCommand)
    assert "longer than 512 bytes" in out[0].reason
    assert reader.feed(b"X" * 1000) == []
    assert reader.feed(b"XX\rSTOP 2\r") == [Stop(2)]


def test_eight_bit_bytes_do_not_break_the_reader() -> None:
    out = CommandReader().feed(b"ROT\xe9TE 1 5\r\x00\xff\rSTOP 1\r")
    assert isinstance(out[0], BadCommand) and isinstance(out[1], BadCommand)
    assert out[2] == Stop(1)


def test_messages_end_with_cr() -> None:
    assert version_message("0.1.0") == b"VERSION 0.1\r"
    assert version_message("2.13") == b"VERSION 2.13\r"
    assert heading_message(3, 270) == b"3 270\r"
