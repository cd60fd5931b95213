"""Yaesu GS-232A and GS-232B computer interfaces (and the many boxes that copy them).

Bytes (9600 baud by default, 8N1; every command ends with CR)::

    C<CR>        ask the azimuth   GS-232A "+0aaa<CR><LF>"   GS-232B "AZ=aaa<CR><LF>"
    Maaa<CR>     turn to azimuth aaa (three digits, 000-450, from the counter-clockwise stop)
    S<CR>        stop everything
    ?>           the answer to a command the unit did not understand

The two models differ only in the answers, so one codec reads both shapes
(and ``C2``'s ``+0aaa+0eee`` / ``AZ=aaa  EL=eee``, with any spacing, as
copies of the GS-232B vary).  MOAS model 4 ("Yaesu") is a GS-232B or a
compatible box; the name "GS-232A" selects the older reply shape for the
emulator and documents the choice (both are driven the same way).  A GS-232A
acknowledges commands with a lone CR, which is skipped quietly.
"""

from __future__ import annotations

import re

from .base import (
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

INFO_B = ModelInfo(
    number=4,
    name="Yaesu",
    description="Yaesu GS-232B or a compatible interface",
    serial=SerialSettings(9600),
    minimum=0.0,
    maximum=450.0,
    write_gap=0.05,
    reply_timeout=0.5,
)

INFO_A = ModelInfo(
    number=None,
    name="GS-232A",
    description="Yaesu GS-232A",
    serial=SerialSettings(9600),
    minimum=0.0,
    maximum=450.0,
    write_gap=0.05,
    reply_timeout=0.5,
)

_A_FORM = re.compile(rb"\+?(\d{1,4})(?:\+(\d{1,4}))?")
_B_FORM = re.compile(rb"AZ\s*=\s*(\d{1,3}(?:\.\d+)?)(?:\s*EL\s*=\s*(\d{1,3}(?:\.\d+)?))?",
                     re.IGNORECASE)


def parse_line(line: bytes) -> Heading | Notice | Garbage:
    """One line from a GS-232A/B (without its CR/LF)."""
    text = line.strip()
    if text.startswith(b"?>"):
        return Notice("controller refused a command (it answered '?>')")
    found = _A_FORM.fullmatch(text) or _B_FORM.fullmatch(text)
    if found is None:
        return Garbage(line, "not a GS-232 azimuth reply ('+0aaa' or 'AZ=aaa')")
    return Heading(float(found.group(1)))


def _match(buffer: bytes) -> tuple[int, Heading | Notice | Garbage | None]:
    used, line = split_line(buffer)
    if line is None:
        return used, None
    return used, parse_line(line) if line.strip() else None


class YaesuCodec(ScannedCodec):
    """The driver's side of a GS-232A or GS-232B; see the module docstring."""

    def __init__(self, info: ModelInfo = INFO_B) -> None:
        self.info = info
        self._scanner: FrameScanner[Heading | Notice | Garbage] = FrameScanner(
            _match, "GS-232 reply line (ends with CR)")

    def poll(self, now: float) -> list[Output]:
        return [Send(b"C\r", expects_reply=True)]

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        return [Send(b"M%03d\r" % whole(degrees))]

    def stop(self, now: float) -> list[Output]:
        return [Send(b"S\r")]



__all__ = ["INFO_A", "INFO_B", "YaesuCodec", "parse_line"]
