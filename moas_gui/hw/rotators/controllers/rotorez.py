"""Idiom Press Rotor-EZ / RotorCard and other "enhanced DCU-1" controllers.

Bytes (4800 baud, 8N1; commands are case-sensitive)::

    AI1;       ask the bearing        answer ";ddd" (Rotor-EZ) or "ddd;" (Green Heron and others)
    AP1ddd;    load bearing ddd, then
    AM1;       start turning
    ;          stop

Answers have no terminator: ``;ddd`` is four bytes.  The decoder takes both
shapes, finds its place again after noise (a Rotor-EZ may put one stray
byte out at power-on), reports a 360 as 0 (as Hamlib does), and recognises
the text a Rotor-EZ sends when it did not understand a command
(``C2000 IDIOM V1.4S ``, for example after a stop while standing still).
"""

from __future__ import annotations

from .base import (
    NEED_MORE,
    NO_FRAME,
    FrameScanner,
    Heading,
    ModelInfo,
    Notice,
    Output,
    ScannedCodec,
    Send,
    SerialSettings,
    check_range,
)
from .dcu1 import LOAD_PAUSE, bearing_command

INFO = ModelInfo(
    number=2,
    name="RotorEZ",
    description="Idiom Press Rotor-EZ / RotorCard, Green Heron and other enhanced DCU-1 boxes",
    serial=SerialSettings(4800),
    minimum=0.0,
    maximum=360.0,
    write_gap=0.5,
    reply_timeout=1.0,
)

BANNER_START = b"C2000 IDIOM V"
"""How a Rotor-EZ's answer to a command it does not know begins."""

_DIGITS = frozenset(b"0123456789")


def match_reply(buffer: bytes) -> tuple[int, Heading | Notice | None]:
    """Matcher for :class:`FrameScanner`: ``;ddd``, ``ddd;`` or the Idiom Press text."""
    first = buffer[0]
    if first == ord(";"):
        return _digits_then(buffer, 1, 4, b"")
    if first in _DIGITS:
        return _digits_then(buffer, 0, 4, b";")
    if first == BANNER_START[0]:
        head = buffer[: len(BANNER_START)]
        if not BANNER_START.startswith(head):
            return NO_FRAME, None
        if len(head) < len(BANNER_START):
            return NEED_MORE, None
        end = buffer.find(b" ", len(BANNER_START))
        if end < 0:
            return (NEED_MORE, None) if len(buffer) < 32 else (NO_FRAME, None)
        text = buffer[: end + 1].decode("ascii", "replace").strip()
        return end + 1, Notice(f"controller did not understand a command (it says {text!r})")
    return NO_FRAME, None


def _digits_then(buffer: bytes, at: int, length: int,
                 last: bytes) -> tuple[int, Heading | Notice | None]:
    """Three digits starting at ``at``, then ``last`` (b"" when the frame ends with them)."""
    for i in range(at, at + 3):
        if i >= len(buffer):
            return NEED_MORE, None
        if buffer[i] not in _DIGITS:
            return NO_FRAME, None
    if last:
        if len(buffer) < length:
            return NEED_MORE, None
        if buffer[3:4] != last:
            return NO_FRAME, None
    value = int(buffer[at : at + 3])
    if value > 360:
        return NO_FRAME, None
    return length, Heading(float(value % 360))


class RotorEZCodec(ScannedCodec):
    """The driver's side of a Rotor-EZ; see the module docstring."""

    info = INFO

    def __init__(self) -> None:
        self._scanner: FrameScanner[Heading | Notice] = FrameScanner(
            match_reply, "Rotor-EZ bearing (';ddd' or 'ddd;')")

    def poll(self, now: float) -> list[Output]:
        return [Send(b"AI1;", expects_reply=True)]

    def rotate(self, degrees: float, now: float) -> list[Output]:
        check_range(self.info, degrees)
        return [Send(bearing_command(degrees), pause=LOAD_PAUSE), Send(b"AM1;")]

    def stop(self, now: float) -> list[Output]:
        return [Send(b";")]



__all__ = ["BANNER_START", "INFO", "RotorEZCodec", "match_reply"]
