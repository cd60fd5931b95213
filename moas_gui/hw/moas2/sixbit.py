"""Sixbit: the MOAS II's one-character numbers.

The switch writes every antenna number (0-63) and every relay number (0-63)
as one printable character, and packs the state of all 64 relays into eleven
such characters.  ``0``-``9`` are 0-9, ``A``-``Z`` are 10-35, ``a``-``z`` are
36-61, ``{`` is 62 and ``}`` is 63.

None of these characters is a command character, which is what lets a
decoder find the start of the next message after garbage.
"""

from __future__ import annotations

from collections.abc import Iterable

from moas_gui.errors import ProtocolError

ALPHABET = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz{}"
"""Character ``n`` of this string is the sixbit code for ``n``."""

_VALUE = {c: n for n, c in enumerate(ALPHABET)}

RELAY_CHARS = 11
"""Characters in a relay-status bitmap (66 bits for 64 relays)."""


class SixbitError(ProtocolError, ValueError):
    """A character or number that sixbit cannot represent."""


def to_char(number: int) -> str:
    """The sixbit character for ``number`` (0-63)."""
    if not 0 <= number <= 63:
        raise SixbitError(f"sixbit numbers are 0-63, not {number}")
    return ALPHABET[number]


def from_char(char: str) -> int:
    """The number that sixbit character ``char`` stands for."""
    try:
        return _VALUE[char]
    except KeyError:
        raise SixbitError(f"{char!r} is not a sixbit character") from None


def is_sixbit(char: str) -> bool:
    """True when ``char`` is one of the 64 sixbit characters."""
    return char in _VALUE


def encode_numbers(numbers: Iterable[int]) -> str:
    """Several numbers (antennas or relays), one character each, in order."""
    return "".join(to_char(n) for n in numbers)


def decode_numbers(text: str) -> tuple[int, ...]:
    """The numbers of a run of sixbit characters, in order."""
    return tuple(from_char(c) for c in text)


def encode_relay_bitmap(relays: Iterable[int]) -> str:
    """The eleven-character relay map of a ``|`` reply: the rightmost
    character holds relays 0-5 (relay 0 in its lowest bit)."""
    bits = 0
    for relay in relays:
        if not 0 <= relay <= 63:
            raise SixbitError(f"relays are 0-63, not {relay}")
        bits |= 1 << relay
    return "".join(ALPHABET[(bits >> (6 * i)) & 0x3F] for i in reversed(range(RELAY_CHARS)))


def decode_relay_bitmap(text: str) -> frozenset[int]:
    """The closed relays named by an eleven-character relay map."""
    if len(text) != RELAY_CHARS:
        raise SixbitError(f"a relay map has {RELAY_CHARS} characters, not {len(text)}")
    relays: set[int] = set()
    for index, char in enumerate(reversed(text)):
        value = from_char(char)
        for bit in range(6):
            if value >> bit & 1:
                relay = index * 6 + bit
                if relay > 63:
                    raise SixbitError(f"relay map {text!r} sets bit {relay}, beyond relay 63")
                relays.add(relay)
    return frozenset(relays)


__all__ = [
    "ALPHABET",
    "RELAY_CHARS",
    "SixbitError",
    "decode_numbers",
    "decode_relay_bitmap",
    "encode_numbers",
    "encode_relay_bitmap",
    "from_char",
    "is_sixbit",
    "to_char",
]
