"""Prosistel rotators with the "D" control box.

Bytes (9600 baud, 8N1).  Commands are STX, the unit letter (``A`` azimuth),
the command, a value, CR; answers are STX, the unit letter and
comma-separated fields, CR::

    \\x02A?\\r          -> \\x02A,?,290,R\\r     position of unit A (whole degrees)
    \\x02AG200\\r       -> \\x02A,G,R\\r         go to 200
    \\x02AG997\\r       -> \\x02A,G,R\\r         soft stop (999 would be an immediate stop)
    \\x02AS\\r          -> \\x02A,S,R\\r         stop the continuous position reports (CPM)
                       \\x02A,?,E,00003\\r     an error: E and a code

The driver sends ``\\x02AS\\r`` once after opening the port, as Hamlib does,
so a box that reports continuously goes quiet; position answers that come
anyway are taken like any other.
"""

from __future__ import annotations

from .base import (
    NEED_MORE,
    NO_FRAME,
    Ack,
    FrameScanner,
    Garbage,
    Heading,
    ModelInfo,
    Notice,
    Output,
    ScannedCodec,
    Send,
    SerialSettings,
    check_range,
    whole,
)

INFO = ModelInfo(
    number=10,
    name="Prosistel D",
    description="Prosistel rotator with the D control box",
    serial=SerialSettings(9600),
    minimum=0.0,
    maximum=360.0,
    write_gap=0.05,
    reply_timeout=1.0,
)

STX = 0x02
SOFT_STOP = 997
FAST_STOP = 999


def parse_answer(body: bytes) -> Heading | Notice | Ack | Garbage:
    """One answer without STX and CR, e.g. ``A,?,290,R``."""
    fields = body.split(b",")
    if len(fields) < 2 or len(fields[0]) != 1:
        return Garbage(body, "not a Prosistel answer ('A,?,ddd,R')")
    unit, command = fields[0], fields[1]
    if len(fields) >= 3 and fields[2][:1] == b"E" and command == b"?":
        return Notice(f"controller unit {unit.decode('ascii', 'replace')} reports error "
                      f"{b','.join(fields[2:]).decode('ascii', 'replace')}")
    if command == b"?":
        if unit != b"A":
            return Ack()  # another unit's position (an elevation box on the same line)
        if len(fields) >= 3 and fields[2].strip().lstrip(b"-").isdigit():
            return Heading(float(int(fields[2])))
        return Garbage(body, "a Prosistel position answer without a number")
    if command in (b"G", b"S"):
        return Ack()
    return Garbage(body, f"a Prosistel answer to an unknown command {command!r}")


def _match(buffer: bytes) -> tuple[int, Heading | Notice | Ack | Garbage | None]:
    first = buffer[0]
    if first in (0x0D, 0x0A):
        return 1, None
    if first != STX:
        return NO_FRAME, None
    end = buffer.find(b"\r")
    if end < 0:
        return (NEED_MORE, None) if len(buffer) < 40 else (NO_FRAME, None)
    if STX in buffer[1:end]:
        return NO_FRAME, None  # a broken answer followed by a new one
    return end + 1, parse_answer(buffer[1:end])


class ProsistelCodec(ScannedCodec):
    """The driver's side of a Prosistel D box; see the module docstring."""

    info = INFO

    def __init__(self) -> None:
        self._scanner: FrameScanner[Heading | Notice | Ack | Garbage] = FrameScanner(
            _match, "Prosistel answer (STX ... CR)")

    def opening(self) -> list[Send]:
        return [Send(b"\x02AS\r", expects_reply=True)]

    def poll(self, now: float) -> list[Output]:
        return [Send(b"\x02A?\r", expects_reply=True)]

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        return [Send(b"\x02AG%d\r" % whole(degrees), expects_reply=True)]

    def stop(self, now: float) -> list[Output]:
        return [Send(b"\x02AG%d\r" % SOFT_STOP, expects_reply=True)]



__all__ = ["FAST_STOP", "INFO", "SOFT_STOP", "ProsistelCodec", "parse_answer"]
