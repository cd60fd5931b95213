"""OTRSP (the Open Two Radio Switching Protocol), the logger's side, without I/O.

An SO2R logger (N1MM Logger+, WriteLog, Win-Test, DXLog.net, Logger32,
so2sdr) writes OTRSP to a serial port, 9600 baud 8N1, each command ASCII and
ended by a carriage return (K1XM's protocol page, k1xm.org/OTRSP, and the
reference device's firmware; shared/specs/logger-network.md section 4):

==============  ===================================================
``TX1``/``TX2``  transmit focus to radio 1/2
``RX1``/``RX2``  receive focus: that radio in both ears
``RX1S``...      stereo with focus on 1/2; ``R`` reverse stereo
``AUX1n``        auxiliary output of radio 1 (band decoder / antenna row ``n``)
``AUX2n``        the same for radio 2
``?...``         queries (``?NAME``, ``?TX``...): answered by a device
==============  ===================================================

:class:`CommandParser` takes bytes as they come and returns the commands.
A line feed is taken as an end too (some programs send CR LF).  A line that
is not OTRSP (unknown, too long, a number out of range) raises
:class:`OtrspError` for the caller to count; the parser is then ready for
the next line, since every command stands alone.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Final, Literal, TypeAlias

from moas_gui.errors import ProtocolError
from moas_gui.line_framer import LineEnd, LineFramer, LongLine

MAX_LINE: Final = 32
"""Longer than any OTRSP command; a longer line is dropped."""
MAX_AUX: Final = 255


class OtrspError(ProtocolError, ValueError):
    """A line that is not an OTRSP command; ``reason`` is a short key for counting."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class TxFocus:
    radio: int


@dataclass(frozen=True, slots=True)
class RxFocus:
    radio: int
    audio: Literal["mono", "stereo", "reverse"]


@dataclass(frozen=True, slots=True)
class Aux:
    radio: int
    value: int


@dataclass(frozen=True, slots=True)
class Query:
    text: str
    """The query without its ``?`` (``NAME``, ``TX``, ``AUX1``)."""


OtrspCommand: TypeAlias = TxFocus | RxFocus | Aux | Query

_TX = re.compile(r"TX([12])")
_RX = re.compile(r"RX([12])([SR]?)")
_AUX = re.compile(r"AUX([12])(\d{1,3})")
_AUDIO: Final[dict[str, Literal["mono", "stereo", "reverse"]]] = {
    "": "mono", "S": "stereo", "R": "reverse"}


def parse_command(line: str) -> OtrspCommand:
    """One command line (without its CR) to a command, or :class:`OtrspError`."""
    text = line.strip().upper()
    if text.startswith("?"):
        return Query(text[1:])
    if match := _TX.fullmatch(text):
        return TxFocus(int(match[1]))
    if match := _RX.fullmatch(text):
        return RxFocus(int(match[1]), _AUDIO[match[2]])
    if match := _AUX.fullmatch(text):
        value = int(match[2])
        if value > MAX_AUX:
            raise OtrspError("out_of_range", f"{text!r}: AUX value {value} is above {MAX_AUX}")
        return Aux(int(match[1]), value)
    shown = text[:MAX_LINE].encode("ascii", "backslashreplace").decode("ascii")
    raise OtrspError("unknown", f"{shown!r} is not an OTRSP command")


class CommandParser:
    """Bytes from the logger in, commands out (see :func:`parse_command`); lines are cut
    by :class:`~moas_gui.line_framer.LineFramer` (CR, LF or CR LF; over
    :data:`MAX_LINE` bytes refused once, the rest of that line skipped)."""

    __slots__ = ("_lines",)

    def __init__(self) -> None:
        self._lines = LineFramer(MAX_LINE, LineEnd.CR_OR_LF)

    @property
    def pending(self) -> int:
        """Bytes held for a command not yet ended (never more than :data:`MAX_LINE`)."""
        return self._lines.pending

    def feed(self, data: bytes) -> list[OtrspCommand | OtrspError]:
        """Every complete line's command, or the error that refused it, in order."""
        out: list[OtrspCommand | OtrspError] = []
        for line in self._lines.feed(data):
            if isinstance(line, LongLine):
                out.append(OtrspError("too_long", f"a line longer than {MAX_LINE} bytes"))
                continue
            if not line.data.strip():
                continue
            try:
                out.append(parse_command(line.data.decode("ascii")))
            except UnicodeDecodeError:
                out.append(OtrspError("not_ascii", "a line that is not ASCII"))
            except OtrspError as exc:
                out.append(exc)
        return out


__all__ = ["MAX_LINE", "Aux", "CommandParser", "OtrspCommand", "OtrspError", "Query", "RxFocus",
           "TxFocus", "parse_command"]
