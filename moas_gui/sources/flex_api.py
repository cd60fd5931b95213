"""The FlexRadio SmartSDR TCP/IP API, sans IO: lines in, typed values out (docs/sources.md).

A Flex 6000/8000 radio serves its API on TCP port 4992, one ASCII line per
message, ended by a line feed (a carriage return before it is tolerated):

================================  ===============================================
line                              meaning
================================  ===============================================
``V1.4.0.0``                      the API version, first line after connecting
``H5A1B2C3D``                     this connection's client handle (hex), second
``C<seq>|<command>``              a command the client sends (``seq``: decimal)
``R<seq>|<hex code>|<message>``   the answer to command ``seq``; code 0 is success
``S<handle>|<object> key=value``  a status the radio pushes (after ``sub ...``)
``M<hex code>|<text>``            a message from the radio
================================  ===============================================

This module reads those lines (:class:`LineSplitter`, :func:`parse_line`), keeps
what the statuses of interest say (:class:`FlexRadioState`: the slices and the
transmit interlock), maps slices to this server's radios (:class:`SliceMap`),
and reads the radio's discovery datagrams (:func:`parse_discovery`: VITA-49 on
UDP 4992, stream id 0x800, class 0x534CFFFF, payload ``key=value`` words).

Only reading commands leave this server (:data:`OPENING`): it announces a
program name and subscribes; it never changes the radio's state.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Final, TypeAlias

from moas_gui.config.rigs import parse_slice_map
from moas_gui.errors import ProtocolError
from moas_gui.line_framer import LineEnd, LineFramer, LongLine

API_PORT: Final = 4992
"""The radio's TCP API port, and the UDP port its discovery datagrams go to."""
MAX_LINE: Final = 8192
"""The longest line read; a longer one is refused (a status line is a few hundred bytes)."""
MAX_FIELDS: Final = 256
"""The most ``key=value`` words kept from one status line."""
MAX_SLICES: Final = 16
"""Slice numbers 0-15 (an 8000-series radio has up to 8 slices)."""
PING_INTERVAL: Final = 5.0
"""Seconds between two pings; the radio drops a keepalive client silent for 10 s or so."""

PROGRAM: Final = "moas-gui"
OPENING: Final = (
    f"client program {PROGRAM}",
    "sub slice all",
    "sub tx all",
    "keepalive enable",
)
"""What is sent after the handle, in order: a name, then subscriptions; nothing that
changes the radio (no ``client gui``, no ``slice set``)."""
PING: Final = "ping"

TRANSMITTING_STATES: Final = frozenset({"PTT_REQUESTED", "TRANSMITTING", "UNKEY_REQUESTED"})
"""Interlock states in which the radio is keyed or keying."""
RECEIVING_STATES: Final = frozenset({"RECEIVE", "READY", "NOT_READY", "TX_FAULT", "TIMEOUT"})
"""Interlock states in which the radio does not transmit (the API's interlock state list;
any other state leaves the transmit state unknown)."""


class FlexLineError(ProtocolError, ValueError):
    """A line or datagram that is not the API's; ``reason`` is a short key for counting."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


# -- lines ------------------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class Version:
    text: str


@dataclass(frozen=True, slots=True)
class Handle:
    handle: int


@dataclass(frozen=True, slots=True)
class FlexReply:
    seq: int
    code: int
    message: str

    @property
    def ok(self) -> bool:
        return self.code == 0


@dataclass(frozen=True, slots=True)
class FlexStatus:
    """``S<handle>|<words>``: ``words`` split on spaces, ``fields`` the ``key=value`` ones."""

    handle: int
    words: tuple[str, ...]
    fields: Mapping[str, str]


@dataclass(frozen=True, slots=True)
class Message:
    code: int
    text: str


Line: TypeAlias = Version | Handle | FlexReply | FlexStatus | Message


class LineSplitter:
    """Bytes from the socket to whole lines of text, each at most :data:`MAX_LINE` bytes,
    through the project's one line framer (LF or CR LF ends a line)."""

    def __init__(self, limit: int = MAX_LINE) -> None:
        self._framer = LineFramer(limit, LineEnd.LF)

    def feed(self, data: bytes) -> tuple[list[str], int]:
        """The whole lines ``data`` completes, and how many over-long lines were dropped."""
        lines: list[str] = []
        dropped = 0
        for item in self._framer.feed(data):
            if isinstance(item, LongLine):
                dropped += 1
            elif item.data:  # a blank line says nothing in the API
                lines.append(item.data.decode("ascii", "replace"))
        return lines, dropped


def command(seq: int, text: str) -> bytes:
    """The bytes of command ``text`` numbered ``seq``."""
    return f"C{seq}|{text}\n".encode("ascii")


def _hex(text: str, what: str, line: str) -> int:
    text = text.strip()
    digits = text[2:] if text[:2].lower() == "0x" else text
    if not digits or len(digits) > 16 or not all(c in "0123456789abcdefABCDEF" for c in digits):
        raise FlexLineError("bad_number", f"{what} {text!r} is not hexadecimal in {_show(line)}")
    return int(digits, 16)


def _show(line: str) -> str:
    return repr(line if len(line) <= 80 else line[:77] + "...")


def parse_line(line: str) -> Line:
    """One line (without its end) to what it says; :class:`FlexLineError` if it is not the
    API's."""
    if not line:
        raise FlexLineError("empty", "an empty line")
    kind, body = line[0], line[1:]
    if kind == "V" and body and body[0].isdigit():
        return Version(body.strip())
    if kind == "H":
        return Handle(_hex(body, "the handle", line))
    if kind == "R":
        seq, bar, rest = body.partition("|")
        code, _, message = rest.partition("|")
        if not bar or not seq.isdigit():
            raise FlexLineError("bad_reply", f"not a reply: {_show(line)}")
        return FlexReply(int(seq), _hex(code, "the answer code", line), message)
    if kind == "S":
        handle, bar, rest = body.partition("|")
        if not bar:
            raise FlexLineError("bad_status", f"not a status: {_show(line)}")
        return _status(_hex(handle, "the handle", line), rest)
    if kind == "M":
        code, _, text = body.partition("|")
        return Message(_hex(code, "the message code", line), text)
    raise FlexLineError("not_flex", f"not a line of the FlexRadio API: {_show(line)}")


def _status(handle: int, rest: str) -> FlexStatus:
    words = tuple(w for w in rest.split(" ") if w)[:MAX_FIELDS]
    fields: dict[str, str] = {}
    for word in words:
        key, eq, value = word.partition("=")
        if eq:
            fields[key] = value
    return FlexStatus(handle, words, fields)


# -- what the statuses say -----------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class Slice:
    """One slice receiver as the radio last described it."""

    index: int
    in_use: bool = False
    khz: float | None = None
    """``RF_frequency`` (MHz in the API) in kHz; None until told."""
    mode: str = ""
    tx: bool = False
    """The slice the radio transmits on (exactly one has ``tx=1``)."""
    active: bool = False
    letter: str = ""
    """``index_letter``: A, B, C... as SmartSDR shows it."""
    rxant: str = ""
    txant: str = ""
    client: int = 0
    """``client_handle``: the GUI client that owns the slice."""

    @property
    def name(self) -> str:
        return f"slice {self.letter or self.index}"


def _flag(fields: Mapping[str, str], key: str, before: bool) -> bool:
    return fields[key].strip() == "1" if key in fields else before


@dataclass(slots=True)
class FlexRadioState:
    """The slices and the interlock, as the status lines said; :meth:`apply` each status."""

    slices: dict[int, Slice] = field(default_factory=dict)
    interlock: str = ""
    """The interlock's ``state`` (``RECEIVE``, ``TRANSMITTING``...); empty until told."""

    def apply(self, status: FlexStatus) -> bool:
        """Takes in one status; True when a slice or the interlock changed.
        :class:`FlexLineError` for a slice or interlock status that makes no sense."""
        words = status.words
        if len(words) >= 2 and words[0] == "slice":
            return self._slice(words[1], status)
        if words and words[0] == "interlock" and "state" in status.fields:
            state = status.fields["state"].upper()
            changed, self.interlock = state != self.interlock, state
            return changed
        return False

    def _slice(self, number: str, status: FlexStatus) -> bool:
        if not number.isdigit() or int(number) >= MAX_SLICES:
            raise FlexLineError("bad_slice", f"slice number {number[:20]!r} is not 0-"
                                f"{MAX_SLICES - 1}")
        index = int(number)
        f = status.fields
        before = self.slices.get(index, Slice(index))
        after = before
        if "removed" in status.words[2:]:
            after = Slice(index)
        after = replace(
            after,
            in_use=_flag(f, "in_use", after.in_use), tx=_flag(f, "tx", after.tx),
            active=_flag(f, "active", after.active),
            mode=f.get("mode", after.mode)[:32], letter=f.get("index_letter", after.letter)[:32],
            rxant=f.get("rxant", after.rxant)[:32], txant=f.get("txant", after.txant)[:32])
        if "RF_frequency" in f:
            after = replace(after, khz=_mhz_to_khz(f["RF_frequency"]))
        if "client_handle" in f:
            after = replace(after, client=_hex(f["client_handle"], "client_handle",
                                                " ".join(status.words)))
        if before.in_use and not after.in_use:
            after = Slice(index, letter=after.letter)  # a slice that went tells nothing more
        self.slices[index] = after
        return after != before

    @property
    def transmitting(self) -> bool | None:
        """Whether the radio is keyed, from the interlock; None while unknown."""
        if self.interlock in TRANSMITTING_STATES:
            return True
        if self.interlock in RECEIVING_STATES:
            return False
        return None

    def in_use(self) -> list[Slice]:
        return [s for _, s in sorted(self.slices.items()) if s.in_use]


def _mhz_to_khz(text: str) -> float:
    text = text.strip()
    if not text or not text.isascii() or not all(c.isdigit() or c == "." for c in text) \
            or text.count(".") > 1:
        raise FlexLineError("bad_frequency", f"RF_frequency {text[:20]!r} is not a number of MHz")
    khz = float(text) * 1000.0
    if not 0.0 < khz < 300_000_000.0:
        raise FlexLineError("bad_frequency", f"RF_frequency {text[:20]} MHz is not a radio "
                            "frequency")
    return khz


# -- slices to radios ------------------------------------------------------------------------

RadioRef: TypeAlias = tuple[int, int]
"""``(station, radio)`` of this server (:func:`parse_slice_map` reads a map of them)."""


@dataclass(frozen=True, slots=True)
class SliceMap:
    """Which radio each slice feeds.

    With ``by_letter`` empty (the default) the transmitting slice (``tx=1``) is
    ``first``'s and the lowest-numbered other slice in use ``second``'s (SO2R on
    one radio); with ``by_letter`` (``A=1/1,B=1/2``) each named slice feeds its
    radio, whether it transmits or not.
    """

    first: RadioRef | None = (1, 1)
    second: RadioRef | None = (1, 2)
    by_letter: Mapping[str, RadioRef] = field(default_factory=dict)

    def radios(self) -> list[RadioRef]:
        """Every radio this map may feed, in order."""
        if self.by_letter:
            return list(dict.fromkeys(self.by_letter.values()))
        return [r for r in (self.first, self.second) if r is not None]

    def assign(self, slices: Iterable[Slice]) -> dict[RadioRef, Slice]:
        """Each radio's slice now (a radio with no slice in use is left out)."""
        used = [s for s in slices if s.in_use]
        if self.by_letter:
            out: dict[RadioRef, Slice] = {}
            for s in used:
                ref = self.by_letter.get(s.letter.upper())
                if ref is not None and ref not in out:
                    out[ref] = s
            return out
        tx = next((s for s in used if s.tx), None)
        rest = [s for s in used if s is not tx]
        pairs = [(self.first, tx), (self.second, rest[0] if rest else None)]
        return {ref: s for ref, s in pairs if ref is not None and s is not None}

    def text(self) -> str:
        if self.by_letter:
            return ",".join(f"{k}={s}/{r}" for k, (s, r) in self.by_letter.items())
        roles = (("TX", self.first), ("other", self.second))
        return ",".join(f"{role}={ref[0]}/{ref[1]}" for role, ref in roles if ref is not None)


# -- discovery -------------------------------------------------------------------------------

DISCOVERY_STREAM: Final = 0x00000800
FLEX_OUI: Final = 0x001C2D
DISCOVERY_CLASS: Final = 0x534CFFFF
"""Information class 0x534C, packet class 0xFFFF."""
_HEADER: Final = struct.Struct(">BBHIIIIQ")
"""Packet type and flags, TSI/TSF and count, size in 32-bit words, stream id, OUI, class,
integer and fractional timestamps: 28 bytes."""
MAX_DATAGRAM: Final = 2048


@dataclass(frozen=True, slots=True)
class FlexAnnouncement:
    """One radio's discovery datagram: what it calls itself and where its API is."""

    fields: Mapping[str, str]

    @property
    def model(self) -> str:
        return self.fields.get("model", "")

    @property
    def serial(self) -> str:
        return self.fields.get("serial", "")

    @property
    def nickname(self) -> str:
        return self.fields.get("nickname", "")

    @property
    def ip(self) -> str:
        return self.fields.get("ip", "")

    @property
    def port(self) -> int:
        text = self.fields.get("port", "")
        return int(text) if text.isdigit() and 1 <= int(text) <= 65535 else API_PORT

    def label(self) -> str:
        """``FLEX-6600 "Shack" (serial 1234-5678, 192.168.1.50:4992)``."""
        nick = f' "{self.nickname}"' if self.nickname else ""
        return (f"{self.model or 'FlexRadio'}{nick} (serial {self.serial or '?'}, "
                f"{self.ip}:{self.port})")

    def matches(self, wanted: str) -> bool:
        """Whether ``wanted`` is this radio's serial, nickname or address."""
        w = wanted.strip().casefold()
        return bool(w) and w in (self.serial.casefold(), self.nickname.casefold(),
                                 self.ip.casefold())


def parse_discovery(data: bytes) -> FlexAnnouncement:
    """A discovery datagram to an :class:`FlexAnnouncement`; :class:`FlexLineError` otherwise."""
    if len(data) < _HEADER.size or len(data) > MAX_DATAGRAM:
        raise FlexLineError("bad_size", f"{len(data)} bytes is no discovery datagram")
    first, _, words, stream, oui, klass, _, _ = _HEADER.unpack_from(data)
    if first >> 4 != 0x3 or not first & 0x08:
        raise FlexLineError("not_vita", "not a VITA-49 extension packet with a class id")
    if stream != DISCOVERY_STREAM or oui & 0xFFFFFF != FLEX_OUI or klass != DISCOVERY_CLASS:
        raise FlexLineError("not_discovery", f"stream 0x{stream:X} class 0x{oui & 0xFFFFFF:06X}"
                            f"/0x{klass:08X} is not FlexRadio discovery")
    end = min(len(data), words * 4) if words else len(data)
    payload = data[_HEADER.size:end].split(b"\x00", 1)[0]
    try:
        text = payload.decode("ascii")
    except UnicodeDecodeError:
        raise FlexLineError("not_ascii", "the discovery payload is not ASCII") from None
    fields: dict[str, str] = {}
    for word in text.split()[:MAX_FIELDS]:
        key, eq, value = word.partition("=")
        if eq:
            fields[key] = value[:64]
    if not fields.get("ip") and not fields.get("serial"):
        raise FlexLineError("no_radio", "the discovery payload names no ip and no serial")
    return FlexAnnouncement(fields)


__all__ = [
    "API_PORT",
    "DISCOVERY_CLASS",
    "DISCOVERY_STREAM",
    "FLEX_OUI",
    "MAX_LINE",
    "OPENING",
    "PING",
    "PING_INTERVAL",
    "PROGRAM",
    "FlexAnnouncement",
    "FlexLineError",
    "FlexRadioState",
    "FlexReply",
    "FlexStatus",
    "Handle",
    "Line",
    "LineSplitter",
    "Message",
    "RadioRef",
    "Slice",
    "SliceMap",
    "Version",
    "command",
    "parse_discovery",
    "parse_line",
    "parse_slice_map",
]
