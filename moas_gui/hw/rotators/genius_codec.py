"""4O3A Rotator Genius TCP protocol, rev. 4, sans-IO, both ends.

Raw TCP, no terminators: every message is recognised by its two-byte header
and its fixed length (shared/specs/rotator-genius-tcp-rev4.md and section 8
of rotator-protocols.md).

=========  ===========================  ====================================
command    bytes sent                   reply
=========  ===========================  ====================================
heading    ``|h``                       ``|h`` active panic + 2 x 34-byte block
move       ``|A`` rotor ddd             ``|AK``/``|AF`` (or ``|A`` ddd K/F)
stop all   ``|S``                       ``|SK``/``|SF``
turn CW    ``|P`` rotor                 ``|PK``/``|PF``
turn CCW   ``|M`` rotor                 ``|MK``/``|MF``
configure  ``|c`` rotor cw ccw A/E oo   ``|cK``/``|cF``
           name[10]
=========  ===========================  ====================================

A rotor block (offsets): 0-2 azimuth (``999`` = no sensor), 3-5 CW limit,
6-8 CCW limit, 9 ``A``/``E``, 10 moving (``0`` still, ``1`` CW, ``2`` CCW),
11-14 offset, 15-17 target (``999`` = none), 18-20 start (``999`` = none),
21 out-of-limits flag (``0``/``1``; a real unit sent 0x00), 22-33 name.
Numbers are right-aligned with spaces.
"""

from __future__ import annotations

from dataclasses import dataclass

from .ascii import is_digits

NO_VALUE = 999
BLOCK = 34
STATUS_LENGTH = 4 + 2 * BLOCK
STATUS_OK = (ord("K"), ord("F"))


@dataclass(frozen=True, slots=True)
class RotorBlock:
    azimuth: int | None
    """Current azimuth; ``None`` when the controller sends 999 (no sensor)."""
    limit_cw: int = 360
    limit_ccw: int = 0
    configuration: str = "A"
    moving: int = 0
    """0 still, 1 clockwise, 2 counterclockwise."""
    offset: int = 0
    target: int | None = None
    start: int | None = None
    out_of_limits: bool = False
    name: str = ""


@dataclass(frozen=True, slots=True)
class GeniusStatus:
    rotors: tuple[RotorBlock, RotorBlock]
    active: str = "0"
    panic: int = 0


@dataclass(frozen=True, slots=True)
class GeniusReply:
    """The K/F answer to ``command`` (``"A"``, ``"S"``, ``"P"``, ``"M"``, ``"c"``)."""

    command: str
    ok: bool
    target: int | None = None


@dataclass(frozen=True, slots=True)
class GeniusGarbage:
    data: bytes
    reason: str


Event = GeniusStatus | GeniusReply | GeniusGarbage


# ---- client side: commands out -------------------------------------------------------

def encode_read() -> bytes:
    return b"|h"


def encode_move(rotor: int, azimuth: int) -> bytes:
    _check_rotor(rotor)
    if not 0 <= azimuth <= 360:
        raise ValueError(f"Rotator Genius azimuth must be 0-360, not {azimuth}")
    return f"|A{rotor}{azimuth:03d}".encode("ascii")


def encode_stop() -> bytes:
    return b"|S"


def encode_turn(rotor: int, clockwise: bool) -> bytes:
    _check_rotor(rotor)
    return f"|{'P' if clockwise else 'M'}{rotor}".encode("ascii")


def _check_rotor(rotor: int) -> None:
    if rotor not in (1, 2):
        raise ValueError(f"a Rotator Genius has rotators 1 and 2, not {rotor}")


# ---- client side: replies in ---------------------------------------------------------

class ReplyDecoder:
    """Bytes from a controller in, events out; resynchronises on the next ``|``."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[Event]:
        self._buffer += data
        events: list[Event] = []
        while self._buffer:
            start = self._buffer.find(b"|")
            if start < 0:
                events.append(GeniusGarbage(bytes(self._buffer), "bytes outside any reply"))
                self._buffer.clear()
                break
            if start > 0:
                events.append(GeniusGarbage(bytes(self._buffer[:start]), "bytes outside any reply"))
                del self._buffer[:start]
            if len(self._buffer) < 3:
                break
            found = self._one()
            if found is None:
                break
            used, event = found
            events.append(event)
            del self._buffer[:used]
        return events

    def _one(self) -> tuple[int, Event] | None:
        """(bytes used, event), or ``None`` when more bytes are needed."""
        buf = self._buffer
        kind = chr(buf[1])
        if kind == "h":
            if len(buf) < STATUS_LENGTH:
                return None
            try:
                return STATUS_LENGTH, decode_status(bytes(buf[:STATUS_LENGTH]))
            except ValueError as exc:
                return self._skip(str(exc))
        if kind == "A" and buf[2] not in STATUS_OK:
            if len(buf) < 6:
                return None
            digits, status = bytes(buf[2:5]).decode("latin-1"), buf[5]
            if status in STATUS_OK and is_digits(digits.strip()):
                return 6, GeniusReply("A", status == ord("K"), int(digits))
            return self._skip("a |A reply must end in K or F")
        if kind in "ASPMc":
            if buf[2] in STATUS_OK:
                return 3, GeniusReply(kind, buf[2] == ord("K"))
            return self._skip(f"a |{kind} reply must end in K or F")
        return self._skip(f"unknown reply header |{kind}")

    def _skip(self, reason: str) -> tuple[int, Event]:
        """Throw away everything up to the next ``|``."""
        following = self._buffer.find(b"|", 1)
        used = len(self._buffer) if following < 0 else following
        return used, GeniusGarbage(bytes(self._buffer[:used]), reason)


def decode_status(data: bytes) -> GeniusStatus:
    """A whole 72-byte ``|h`` reply; ``ValueError`` says what is wrong."""
    if len(data) != STATUS_LENGTH or data[:2] != b"|h":
        raise ValueError(f"a |h reply has {STATUS_LENGTH} bytes starting with |h")
    first = decode_block(data[4:4 + BLOCK], 1)
    second = decode_block(data[4 + BLOCK:], 2)
    return GeniusStatus((first, second), chr(data[2]), data[3])


def decode_block(block: bytes, rotor: int) -> RotorBlock:
    text = block.decode("latin-1")
    where = f"rotator {rotor} block"
    if text[9] not in "AE":
        raise ValueError(f"{where}: configuration byte is {text[9]!r}, not A or E")
    if text[10] not in "012":
        raise ValueError(f"{where}: moving byte is {text[10]!r}, not 0, 1 or 2")

    def number(first: int, last: int, what: str) -> int:
        field = text[first:last + 1].strip()
        body = field[1:] if field[:1] == "-" else field
        if not is_digits(body):
            raise ValueError(f"{where}: {what} {text[first:last + 1]!r} is not a number")
        return int(field)

    azimuth = number(0, 2, "azimuth")
    target = number(15, 17, "target")
    start = number(18, 20, "start azimuth")
    return RotorBlock(
        azimuth=None if azimuth == NO_VALUE else azimuth,
        limit_cw=number(3, 5, "CW limit"),
        limit_ccw=number(6, 8, "CCW limit"),
        configuration=text[9],
        moving=int(text[10]),
        offset=number(11, 14, "offset"),
        target=None if target == NO_VALUE else target,
        start=None if start == NO_VALUE else start,
        out_of_limits=text[21] == "1",
        name=text[22:34].strip(" \x00"),
    )


# ---- controller side (the emulator) --------------------------------------------------

@dataclass(frozen=True, slots=True)
class GeniusCommand:
    """A command as the controller sees it: ``kind`` is h, A, S, P, M or c."""

    kind: str
    rotor: int | None = None
    azimuth: int | None = None
    raw: bytes = b""


COMMAND_LENGTHS = {"h": 2, "S": 2, "A": 6, "P": 3, "M": 3, "c": 22}


class GeniusCommandDecoder:
    """Bytes from a client in, :class:`Command` or :class:`Garbage` out."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[GeniusCommand | GeniusGarbage]:
        self._buffer += data
        out: list[GeniusCommand | GeniusGarbage] = []
        while self._buffer:
            start = self._buffer.find(b"|")
            if start != 0:
                cut = len(self._buffer) if start < 0 else start
                out.append(GeniusGarbage(bytes(self._buffer[:cut]), "bytes outside any command"))
                del self._buffer[:cut]
                continue
            if len(self._buffer) < 2:
                break
            kind = chr(self._buffer[1])
            length = COMMAND_LENGTHS.get(kind)
            if length is None:
                out.append(GeniusGarbage(bytes(self._buffer[:2]), f"unknown command |{kind}"))
                del self._buffer[:2]
                continue
            if len(self._buffer) < length:
                break
            raw = bytes(self._buffer[:length])
            del self._buffer[:length]
            out.append(_command(kind, raw))
        return out


def _command(kind: str, raw: bytes) -> GeniusCommand | GeniusGarbage:
    if kind in "hS":
        return GeniusCommand(kind, raw=raw)
    rotor = raw[2] - ord("0")
    if rotor not in (1, 2):
        return GeniusGarbage(raw, f"|{kind} names rotator {chr(raw[2])!r}, not 1 or 2")
    if kind == "A":
        digits = raw[3:6].decode("latin-1").strip()
        if not is_digits(digits):
            return GeniusGarbage(raw, "|A needs a 3-digit azimuth")
        return GeniusCommand(kind, rotor, int(digits), raw)
    return GeniusCommand(kind, rotor, raw=raw)


def encode_block(rotor: RotorBlock) -> bytes:
    def field(value: int | None, width: int) -> str:
        return f"{NO_VALUE if value is None else value:>{width}}"[:width]

    text = (
        field(rotor.azimuth, 3) + field(rotor.limit_cw, 3) + field(rotor.limit_ccw, 3)
        + rotor.configuration[:1] + str(rotor.moving) + field(rotor.offset, 4)
        + field(rotor.target, 3) + field(rotor.start, 3)
        + ("1" if rotor.out_of_limits else "0") + f"{rotor.name[:12]:<12}"
    )
    return text.encode("latin-1")


def encode_status(status: GeniusStatus) -> bytes:
    return (b"|h" + status.active.encode("latin-1")[:1] + bytes([status.panic])
            + encode_block(status.rotors[0]) + encode_block(status.rotors[1]))


def encode_reply(command: str, ok: bool) -> bytes:
    return f"|{command}{'K' if ok else 'F'}".encode("ascii")


__all__ = [
    "BLOCK",
    "COMMAND_LENGTHS",
    "NO_VALUE",
    "STATUS_LENGTH",
    "Event",
    "GeniusCommand",
    "GeniusCommandDecoder",
    "GeniusGarbage",
    "GeniusReply",
    "GeniusStatus",
    "ReplyDecoder",
    "RotorBlock",
    "decode_block",
    "decode_status",
    "encode_block",
    "encode_move",
    "encode_read",
    "encode_reply",
    "encode_status",
    "encode_stop",
    "encode_turn",
]
