"""Win-Test network frames: one UDP broadcast in, a typed frame out (sans-IO).

Win-Test stations talk to each other with UDP broadcasts, port 9871 by
default.  A frame, as published in Win-Test's summary broadcasting notes
(download.win-test.com/utils/SummaryBroadcastingSpecs.txt) and read alike by
independent parsers (see docs/sources.md), is::

    FRAMETYPE: "from" "to" data... <checksum>[NUL]

- fields are separated by spaces; strings are double-quoted, with ``\\"`` for a
  quote, ``\\\\`` for a backslash and ``\\`` + three octal digits for a byte
  above 127; numbers are bare;
- the checksum byte is the sum of every byte before it, modulo 256, with the
  top bit set;
- most frames end with a NUL byte.

Only ``STATUS`` says where a radio is: its field 6 (counting from 0 after the
frame type) is the frequency in **100 Hz units** (``140751`` is 14,075.1 kHz).
Field 0 is the sending station's name.  Field 10 holds a second frequency
whose meaning is not published, and no field has been identified as the
transmit state or a radio number, so this parser reads neither.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Final

from moas_gui.errors import ProtocolError
from moas_gui.sources.base import MAX_KHZ

DEFAULT_PORT: Final = 9871
MAX_FRAME_BYTES: Final = 4096
"""A STATUS frame is under 100 bytes; anything over 4 KiB is refused unread."""
MAX_FIELDS: Final = 64

REASONS: Final = ("too_large", "not_a_frame", "checksum", "not_status", "bad_value")

_TYPE: Final = re.compile(rb"[A-Z][A-Z0-9_]{0,31}")
_NUMBER: Final = re.compile(r"-?[0-9]{1,12}")


class WinTestFrameError(ProtocolError):
    """A datagram that is not a usable Win-Test frame; :attr:`reason` is one of :data:`REASONS`."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class WinTestFrame:
    kind: str
    """The frame type: ``STATUS``, ``ADDQSO``, ``GAB``..."""
    fields: tuple[str | int, ...]
    """Quoted fields as text, bare ones as integers (other bare words as text)."""


@dataclass(frozen=True, slots=True)
class WinTestStatus:
    """What a STATUS frame says: the sending station and its radio's frequency."""

    station_name: str
    khz: float | None
    """``None`` when the frame carries 0 (no frequency)."""
    operator: str = ""


def checksum(data: bytes) -> int:
    """The checksum byte of the frame text ``data``."""
    return (sum(data) & 0xFF) | 0x80


def _unquote(body: bytes, start: int) -> tuple[str, int]:
    """The string starting after the quote at ``start - 1``; returns it and the index past it."""
    out = bytearray()
    i = start
    while i < len(body):
        byte = body[i]
        if byte == 0x22:  # closing quote
            return out.decode("latin-1"), i + 1
        if byte == 0x5C:  # backslash
            octal = body[i + 1:i + 4]
            if len(octal) == 3 and all(0x30 <= b <= 0x37 for b in octal):
                out.append(int(octal, 8) & 0xFF)
                i += 4
                continue
            if i + 1 < len(body):
                out.append(body[i + 1])
                i += 2
                continue
        out.append(byte)
        i += 1
    raise WinTestFrameError("not_a_frame", "a quoted field is not closed")


def parse_frame(data: bytes) -> WinTestFrame:
    """Read one datagram; raise :class:`WinTestFrameError` when it is not a valid frame."""
    if len(data) > MAX_FRAME_BYTES:
        raise WinTestFrameError(
            "too_large", f"frame of {len(data)} bytes is over the {MAX_FRAME_BYTES}-byte limit")
    if data.endswith(b"\x00"):
        data = data[:-1]
    head, colon, _ = data.partition(b": ")
    if not colon or _TYPE.fullmatch(head) is None or len(data) < len(head) + 3:
        raise WinTestFrameError("not_a_frame", f"does not start with a frame type: {data[:20]!r}")
    body, check = data[:-1], data[-1]
    if checksum(body) != check:
        raise WinTestFrameError(
            "checksum", f"checksum byte is {check:#04x}, the frame adds up to {checksum(body):#04x}")
    fields: list[str | int] = []
    i = len(head) + 2
    while i < len(body):
        byte = body[i]
        if byte == 0x20:
            i += 1
            continue
        if len(fields) >= MAX_FIELDS:
            raise WinTestFrameError("not_a_frame", f"more than {MAX_FIELDS} fields")
        if byte == 0x22:
            text, i = _unquote(body, i + 1)
            fields.append(text)
            continue
        end = body.find(b" ", i)
        end = len(body) if end < 0 else end
        word = body[i:end].decode("latin-1")
        fields.append(int(word) if _NUMBER.fullmatch(word) else word)
        i = end
    return WinTestFrame(head.decode("ascii"), tuple(fields))


def parse_status(data: bytes) -> WinTestStatus:
    """Read a STATUS frame; other frame types raise with reason ``not_status``."""
    frame = parse_frame(data)
    if frame.kind != "STATUS":
        raise WinTestFrameError("not_status", f"{frame.kind} frame is not STATUS")
    if len(frame.fields) < 7:
        raise WinTestFrameError("bad_value", f"STATUS with {len(frame.fields)} fields, needs 7")
    name, units = frame.fields[0], frame.fields[6]
    if not isinstance(name, str) or not isinstance(units, int) or units < 0:
        raise WinTestFrameError(
            "bad_value", f"STATUS station {name!r} / frequency {units!r} are not a name and "
                         "a whole number")
    khz = units / 10.0 if units else None
    if khz is not None and khz >= MAX_KHZ:
        raise WinTestFrameError("bad_value", f"STATUS frequency {units} is {khz:,.1f} kHz, "
                                             "not a radio frequency")
    operator = frame.fields[11] if len(frame.fields) > 11 else ""
    return WinTestStatus(name, khz, operator if isinstance(operator, str) else "")


def _quote(text: str) -> bytes:
    out = bytearray(b'"')
    for byte in text.encode("latin-1", errors="replace"):
        if byte in (0x22, 0x5C):
            out += b"\\" + bytes([byte])
        elif byte > 127:
            out += b"\\" + f"{byte:03o}".encode()
        else:
            out.append(byte)
    return bytes(out + b'"')


def make_frame(kind: str, *fields: str | int, nul: bool = True) -> bytes:
    """A frame as Win-Test writes it (the fake Win-Test of the tests and benchmarks)."""
    parts = [_quote(f) if isinstance(f, str) else str(f).encode() for f in fields]
    body = kind.encode("ascii") + b": " + b" ".join(parts)
    return body + bytes([checksum(body)]) + (b"\x00" if nul else b"")


def status_frame(station_name: str, khz: float, *, operator: str = "", mode: int = 0) -> bytes:
    """A STATUS frame laid out like the published sample (fields 2-5 and 7-10 as seen there)."""
    return make_frame("STATUS", station_name, "", 0, 5, mode, 0, round(khz * 10), "0", 0, "1",
                      0, operator)


__all__ = [
    "DEFAULT_PORT", "MAX_FRAME_BYTES", "REASONS", "WinTestFrame", "WinTestFrameError",
    "WinTestStatus", "checksum", "make_frame", "parse_frame", "parse_status", "status_frame",
]
