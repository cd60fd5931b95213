"""M2 RC2800 controllers: RC2800P-A (early protocol, reports by itself) and RC2800P-X.

Bytes (9600 baud, 8N1; commands end with CR)::

    A<CR>            select azimuth; the unit answers with a status line
    A<CR>ddd<CR><CR> RC2800P-A: select azimuth, set ddd, and an empty line for a status line
    Addd<CR>         RC2800P-X: set azimuth ddd; answered with a status line
    A<CR>S<CR>       stop azimuth

    status line      "A P= 123.0 S=9 ST" then LF CR   (P= is 6 characters wide, one decimal;
                     ST standing, MV moving; "A=123.0 S=9 M" on other firmware; "A ERR=05" on error)

The RC2800P-A sends a status line by itself whenever the reading changes, so
its poll time is ignored (the driver only checks now and then that it is
alive).  Which RC2800 speaks which protocol is not documented anywhere this
project could read; this split (P-A early, P-X new) follows Hamlib, whose
early-protocol model was tested on an RC2800P-A.  The decoder reads every
form above, from either model, in any pieces, and skips echoed commands.
"""

from __future__ import annotations

import re

from .base import (
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
    split_line,
    whole,
)

INFO_A = ModelInfo(
    number=8,
    name="RC2800P-A",
    description="M2 RC2800P-A (reports its heading by itself)",
    serial=SerialSettings(9600),
    minimum=0.0,
    maximum=360.0,
    write_gap=0.1,
    reply_timeout=1.0,
    unsolicited=True,
)

INFO_X = ModelInfo(
    number=9,
    name="RC2800P-X",
    description="M2 RC2800P-X",
    serial=SerialSettings(9600),
    minimum=0.0,
    maximum=360.0,
    write_gap=0.1,
    reply_timeout=1.0,
)

_STATUS = re.compile(rb"([AE])\s*(?:P\s*)?=\s*(-?\d+(?:\.\d*)?)(?:\s+S\s*=\s*\d+)?(?:\s+\w+)?")
_ERROR = re.compile(rb"([AE])\s*ERR\s*=\s*(\w+)")
_ECHO = re.compile(rb"[AES]?\s*-?\d*(?:\.\d*)?")


def parse_line(line: bytes) -> Heading | Notice | Ack | Garbage | None:
    """One RC2800 line (without CR/LF); None for echoed commands."""
    text = line.strip()
    found = _STATUS.fullmatch(text)
    if found is not None:
        return Heading(float(found.group(2))) if found.group(1) == b"A" else Ack()
    error = _ERROR.fullmatch(text)
    if error is not None:
        axis = "azimuth" if error.group(1) == b"A" else "elevation"
        return Notice(f"controller reports {axis} error {error.group(2).decode('ascii')}")
    if _ECHO.fullmatch(text):
        return None
    return Garbage(line, "not an RC2800 status line ('A P= ddd.d S=n ST')")


def _match(buffer: bytes) -> tuple[int, Heading | Notice | Ack | Garbage | None]:
    used, line = split_line(buffer)
    if line is None:
        return used, None
    return used, parse_line(line)


class RC2800Codec(ScannedCodec):
    """The driver's side of an RC2800P-A (``early=True``) or RC2800P-X."""

    def __init__(self, early: bool = True) -> None:
        self.info = INFO_A if early else INFO_X
        self._early = early
        self._scanner: FrameScanner[Heading | Notice | Ack | Garbage] = FrameScanner(
            _match, "RC2800 status line (ends with CR or LF)")

    def poll(self, now: float) -> list[Output]:
        return [Send(b"A\r", expects_reply=True)]

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        value = whole(degrees)
        if self._early:
            return [Send(b"A\r%d\r\r" % value, expects_reply=True)]
        return [Send(b"A%d\r" % value, expects_reply=True)]

    def stop(self, now: float) -> list[Output]:
        return [Send(b"A\rS\r", expects_reply=True)]



__all__ = ["INFO_A", "INFO_X", "RC2800Codec", "parse_line"]
