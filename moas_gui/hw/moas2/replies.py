"""Messages from the MOAS II (replies, events, errors): one table, both
directions (bytes to values for the switch link, values to bytes for the
emulator).

The rules, in plain words:

* A message is one leading character, a body, and ``;``, like a command.
  :data:`REPLIES` maps each leading character to how its body is read;
  :func:`encode_reply` writes any message value.
* ``!`` means three things, told apart by the body: nothing (a ping answer
  from an active box), ``{station}X`` (extra relays changed) or
  ``{station}{status}{antenna}`` (an antenna event).  ``.`` is the ping
  answer of an inactive box.
* ``(`` and ``)`` carry the stations inhibited by command; ``"B`` and ``"I``
  the box and polarity status; ``|`` eleven sixbit characters of relays;
  ``:`` a three-character version and the unit id; ``?`` one error letter.
* A body that does not fit raises :class:`ValueError`; the streaming decoder
  turns that into a :class:`~.messages.Malformed` value and carries on.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .messages import (
    AntennaEvent,
    AntennaStatus,
    BoxMessage,
    BoxStatus,
    ErrorReply,
    ExtraRelaysEvent,
    InhibitReply,
    PolarityStatus,
    Pong,
    ReceiveEvent,
    RelayStatus,
    TransmitEvent,
    TRState,
    UninhibitReply,
    UnitIdReply,
    VendorReply,
)
from .sixbit import (
    decode_numbers,
    decode_relay_bitmap,
    encode_numbers,
    encode_relay_bitmap,
    to_char,
)

_STATIONS = frozenset("123456")


def _stations(body: str) -> frozenset[int]:
    if not set(body) <= _STATIONS:
        raise ValueError(f"{body!r} is not a list of stations 1-6")
    return frozenset(int(c) for c in body)


def _station_text(stations: frozenset[int]) -> str:
    return "".join(str(s) for s in sorted(stations))


def _station(char: str, low: str = "1") -> int:
    if not low <= char <= "6" or len(char) != 1:
        raise ValueError(f"{char!r} is not a station")
    return int(char)


def _read_bang(body: str) -> BoxMessage:
    if not body:
        return Pong(True)
    if len(body) == 2 and body[1] == "X":
        return ExtraRelaysEvent(_station(body[0], "0"))
    if len(body) == 3:
        return AntennaEvent(_station(body[0]), AntennaStatus(body[1]), decode_numbers(body[2])[0])
    raise ValueError(f"!{body} is neither a ping answer nor an antenna event")


def _read_dot(body: str) -> Pong:
    if body:
        raise ValueError(f"an inactive ping answer has no body, got {body!r}")
    return Pong(False)


def _read_tr(body: str) -> tuple[int, int]:
    if len(body) != 2:
        raise ValueError(f"a transmit/receive event is station and antenna, got {body!r}")
    return _station(body[0]), decode_numbers(body[1])[0]


def _read_transmit(body: str) -> TransmitEvent:
    return TransmitEvent(*_read_tr(body))


def _read_receive(body: str) -> ReceiveEvent:
    return ReceiveEvent(*_read_tr(body))


def _read_inhibit(body: str) -> InhibitReply:
    return InhibitReply(_stations(body))


def _read_uninhibit(body: str) -> UninhibitReply:
    return UninhibitReply(_stations(body))


def _read_status(body: str) -> BoxStatus | PolarityStatus:
    if body[:1] == "I":
        return PolarityStatus(_stations(body[1:]))
    if body[:1] == "B" and len(body) >= 25:
        # Six T/R letters and 18 antennas; the manual's own example carries
        # three antennas too many, so characters after the 18th are ignored.
        tr = tuple(TRState(c) for c in body[1:7])
        numbers = decode_numbers(body[7:])
        return BoxStatus(tr, numbers[0:6], numbers[6:12], numbers[12:18])
    raise ValueError(f'"{body} is neither a box status ("B + 24) nor a polarity status ("I)')


def _read_relays(body: str) -> RelayStatus:
    return RelayStatus(decode_relay_bitmap(body))


def _read_unit(body: str) -> UnitIdReply:
    if not 4 <= len(body) <= 5 or not body[3:].isdigit() or not body.isascii():
        raise ValueError(f"a unit id answer is a 3-character version and 1-2 digits, got {body!r}")
    return UnitIdReply(body[:3], int(body[3:]))


def _read_error(body: str) -> ErrorReply:
    if len(body) != 1:
        raise ValueError(f"an error is one letter, got {body!r}")
    return ErrorReply(body)


def _read_vendor(body: str) -> VendorReply:
    return VendorReply(body)


REPLIES: dict[str, Callable[[str], BoxMessage]] = {
    "!": _read_bang,
    ".": _read_dot,
    "<": _read_transmit,
    ">": _read_receive,
    "(": _read_inhibit,
    ")": _read_uninhibit,
    '"': _read_status,
    "|": _read_relays,
    ":": _read_unit,
    "?": _read_error,
    "#": _read_vendor,
}
"""Leading character -> how its body is read."""


def parse_reply(text: str) -> BoxMessage:
    """The message in ``text`` (leading character and body, no ``;``).

    Raises :class:`ValueError` (with the reason) for anything else.
    """
    reader = REPLIES.get(text[:1])
    if reader is None:
        raise ValueError(f"{text[:1]!r} does not start a message from the switch")
    return reader(text[1:])


def _write_box_status(m: BoxStatus) -> str:
    return (
        '"B'
        + "".join(t.value for t in m.tr)
        + encode_numbers(m.tx)
        + encode_numbers(m.rx)
        + encode_numbers(m.alt)
    )


_WRITERS: dict[type, Callable[[Any], str]] = {
    Pong: lambda m: "!" if m.active else ".",
    AntennaEvent: lambda m: f"!{m.station}{m.status.value}{to_char(m.antenna)}",
    ExtraRelaysEvent: lambda m: f"!{m.station}X",
    TransmitEvent: lambda m: f"<{m.station}{to_char(m.antenna)}",
    ReceiveEvent: lambda m: f">{m.station}{to_char(m.antenna)}",
    InhibitReply: lambda m: "(" + _station_text(m.stations),
    UninhibitReply: lambda m: ")" + _station_text(m.stations),
    BoxStatus: _write_box_status,
    PolarityStatus: lambda m: '"I' + _station_text(m.enable_low),
    RelayStatus: lambda m: "|" + encode_relay_bitmap(m.relays),
    UnitIdReply: lambda m: f":{m.version}{m.unit}",
    ErrorReply: lambda m: f"?{m.code}",
    VendorReply: lambda m: f"#{m.text}",
}


def encode_reply(message: BoxMessage) -> bytes:
    """The bytes the box sends for ``message``."""
    return (_WRITERS[type(message)](message) + ";").encode("ascii")


__all__ = ["REPLIES", "encode_reply", "parse_reply"]
