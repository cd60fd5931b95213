"""The server side of Hamlib's rotctld protocol, sans-IO (rotator-protocols.md 7).

Input is a byte stream, not lines: a command is one character or a backslash
and a long name, and its arguments are the following whitespace-separated
words, wherever the line breaks fall (``P 10 20 p`` is two commands;
``P\\n10\\n20`` is one).  A ``+`` (or another punctuation character) before a
command asks for the extended answer: a header record, one ``Label: value``
record per value, then ``RPRT <code>``, records separated by LF (``+``) or
by that character.  ``#`` starts a comment line; ``q``/``Q`` ends the session.

Default answers: values one per line with no ``RPRT``; a command without
values answers ``RPRT 0``; any failure answers ``RPRT -<code>``.

The azimuth scale offered to clients (``dump_state``'s ``min_az``/``max_az``)
is the rotator's own, unwrapped: it starts at the CCW stop written between
-180 and 180 (a stop at south is -180, so west reads -90), and is widened to
cover 0..360 so that a client sending plain compass bearings is never refused
by its own limit check.  Unbounded rotators get -180..540 and read 0..360.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from moas_gui.hw.rotators.headings import FULL_TURN, Travel, normalize, window_base

PROTOCOL_VERSION = 1
MODEL = 2
MAX_BUFFER = 4096
WHITESPACE = " \t\r\n"
NOT_PREFIXES = "\\_#"

COMMANDS: dict[str, tuple[str, int]] = {
    "P": ("set_pos", 2), "p": ("get_pos", 0), "K": ("park", 0), "S": ("stop", 0),
    "R": ("reset", 1), "M": ("move", 2), "V": ("set_level", 2), "v": ("get_level", 1),
    "U": ("set_func", 2), "u": ("get_func", 1), "X": ("set_parm", 2), "x": ("get_parm", 1),
    "C": ("set_conf", 2), "_": ("get_info", 0), "s": ("get_status", 0), "1": ("dump_caps", 0),
    "3": ("dump_conf", 0), "q": ("quit", 0), "Q": ("quit", 0),
}
LONG_NAMES: dict[str, int] = {name: count for name, count in COMMANDS.values()}
LONG_NAMES.update({"dump_state": 0, "pause": 1, "send_cmd": -1})
"""Argument count per long name; -1 means the rest of the line."""

EINVAL, ENIMPL, ETIMEOUT, EIO, ERJCTED, ENAVAIL = 1, 4, 5, 6, 9, 11
"""Hamlib's error numbers (``RPRT -n``): invalid parameter, not implemented,
communication timed out, I/O error, rejected by the device, feature not
available."""

CLOCKWISE, COUNTERCLOCKWISE = 16, 8
"""``move`` directions (rotator.h ``ROT_MOVE_CW``/``ROT_MOVE_CCW``)."""
DIRECTIONS = {
    "LEFT": COUNTERCLOCKWISE, "CCW": COUNTERCLOCKWISE, "RIGHT": CLOCKWISE, "CW": CLOCKWISE,
    "UP": 2, "DOWN": 4, "UP_LEFT": 32, "UP_CCW": 32, "UP_RIGHT": 64, "UP_CW": 64,
    "DOWN_LEFT": 128, "DOWN_CCW": 128, "DOWN_RIGHT": 256, "DOWN_CW": 256,
}
"""Direction names rotctld takes, and their numbers; every direction but
plain CW and CCW moves the elevation."""
MOVE_STEP = 179.0
"""How far one ``move`` turns at most: under half a turn, so the heading rules
cannot take the other way round."""


@dataclass(frozen=True, slots=True)
class RotctldRequest:
    name: str
    """The long name (``get_pos``), or the text typed when it is not a command."""
    args: tuple[str, ...] = ()
    separator: str | None = None
    """``None``: default answers; otherwise the extended record separator."""
    known: bool = True


class RequestParser:
    """Bytes in, :class:`RotctldRequest` values out."""

    def __init__(self) -> None:
        self._buffer = ""
        self.overflowed = False

    def feed(self, data: bytes) -> list[RotctldRequest]:
        self._buffer += data.decode("latin-1")
        out: list[RotctldRequest] = []
        while True:
            found = self._next()
            if found is None:
                break
            used, request = found
            self._buffer = self._buffer[used:]
            if request is not None:
                out.append(request)
        if len(self._buffer) > MAX_BUFFER:
            self._buffer = ""
            self.overflowed = True
        return out

    def _next(self) -> tuple[int, RotctldRequest | None] | None:
        """(characters used, request or None for a comment), or None: need more."""
        text = self._buffer
        i = _skip_space(text, 0)
        if i >= len(text):
            return (i, None) if i else None
        if text[i] == "#":
            end = text.find("\n", i)
            return None if end < 0 else (end + 1, None)
        separator: str | None = None
        if _is_prefix(text[i]):
            separator = "\n" if text[i] == "+" else text[i]
            i += 1
            if i >= len(text):
                return None
        if text[i] == "\\":
            name_end = _word_end(text, i + 1)
            if name_end is None:
                return None
            name, i = text[i + 1:name_end], name_end
            count = LONG_NAMES.get(name)
        else:
            letter = text[i]
            known = COMMANDS.get(letter)
            name, count = known if known else (letter, None)
            i += 1
        if count is None:
            return i, RotctldRequest(name, (), separator, known=False)
        if count < 0:
            end = text.find("\n", i)
            if end < 0:
                return None
            return end + 1, RotctldRequest(name, (text[i:end].strip(),), separator)
        args: list[str] = []
        for _ in range(count):
            start = _skip_space(text, i)
            word_end = _word_end(text, start)
            if start >= len(text) or word_end is None:
                return None
            args.append(text[start:word_end])
            i = word_end
        return i, RotctldRequest(name, tuple(args), separator)


def _is_prefix(char: str) -> bool:
    return not char.isalnum() and not char.isspace() and char not in NOT_PREFIXES \
        and char.isprintable()


def _skip_space(text: str, i: int) -> int:
    while i < len(text) and text[i] in WHITESPACE:
        i += 1
    return i


def _word_end(text: str, i: int) -> int | None:
    """Index of the whitespace ending the word at ``i``; None if it has not come yet."""
    while i < len(text):
        if text[i] in WHITESPACE:
            return i
        i += 1
    return None


# ---- answers -------------------------------------------------------------------------

def answer(request: RotctldRequest, values: tuple[tuple[str, str], ...] = (),
           code: int = 0) -> bytes:
    """The answer to ``request``: ``values`` as (label, text) when it succeeded,
    else ``code`` (positive Hamlib error number)."""
    if request.separator is None:
        if code:
            return f"RPRT {-code}\n".encode("latin-1")
        if values:
            return "".join(f"{text}\n" for _, text in values).encode("latin-1")
        return b"RPRT 0\n"
    sep = request.separator
    header = request.name + ":" + "".join(" " + arg for arg in request.args)
    records = [header] + ([] if code else [f"{label}: {text}" for label, text in values])
    return (sep.join(records) + sep + f"RPRT {-code}\n").encode("latin-1")


@dataclass(frozen=True, slots=True)
class AzimuthScale:
    """The azimuth scale offered to clients."""

    min_az: float
    max_az: float
    base: float
    """Unwrapped azimuth of the CCW stop (position 0)."""
    bounded: bool = True


def scale_for(travel: Travel) -> AzimuthScale:
    if not travel.bounded:
        return AzimuthScale(-180.0, 540.0, 0.0, bounded=False)
    stop = normalize(travel.ccw_limit)
    low = min(stop - FULL_TURN if stop >= 180.0 else stop, 0.0)
    base = window_base(travel, low)
    return AzimuthScale(low, max(base + travel.rotation, FULL_TURN), base)


def azimuth_for(scale: AzimuthScale, heading: float) -> float:
    """A compass heading written on the offered scale (0..360 for unbounded)."""
    if not scale.bounded:
        return normalize(heading)
    return scale.base + normalize(heading - scale.base)


def parse_number(text: str) -> float | None:
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def parse_direction(text: str) -> int | None:
    """A ``move`` direction: a number or one of rotctld's names; None if neither."""
    if text.upper() in DIRECTIONS:
        return DIRECTIONS[text.upper()]
    value = int(text) if text.isascii() and text.isdigit() else None
    return value if value in DIRECTIONS.values() else None


def move_target(travel: Travel, heading: float, position: float | None,
                clockwise: bool) -> float:
    """The compass heading one ``move`` turns to: up to :data:`MOVE_STEP`
    that way, never past the end of travel.

    ``position`` (on the travel) decides where the rotator is when a heading
    has two positions (the overlap); when it is not known the heading alone
    decides, and in the overlap the move aims at the end of travel's heading,
    which every reading of the heading reaches turning the asked way.
    """
    sign = 1.0 if clockwise else -1.0
    if not travel.bounded:
        return normalize(heading + sign * MOVE_STEP)
    if position is None:
        positions = travel.positions_of(heading)
        if len(positions) != 1:
            return travel.heading_at(travel.rotation if clockwise else 0.0)
        position = positions[0]
    return travel.heading_at(travel.clamp(position + sign * MOVE_STEP))


def dump_caps(request: RotctldRequest, info: str, scale: AzimuthScale, can_park: bool) -> bytes:
    """``dump_caps``: what this listener does, in rotctld's layout (every line
    well under 64 bytes); ends with ``RPRT 0`` in both forms, as rotctld's."""
    yes = {True: "Y", False: "N"}
    lines = [
        f"Caps dump for model:\t{MODEL}",
        f"Model name:\t\t{info[:40]}",
        "Mfg name:\t\tmoas-gui",
        "Backend status:\t\tStable",
        "Rot type:\t\tAz-El",
        "Port type:\t\tNetwork link",
        f"Min Azimuth:\t\t{scale.min_az:.2f}",
        f"Max Azimuth:\t\t{scale.max_az:.2f}",
        "Min Elevation:\t\t0.00",
        "Max Elevation:\t\t90.00",
        "Can set Position:\tY",
        "Can get Position:\tY",
        "Can Stop:\t\tY",
        f"Can Park:\t\t{yes[can_park]}",
        "Can Reset:\t\tY",
        "Can Move:\t\tY",
        "Can get Info:\t\tY",
        "Can get Status:\t\tN",
    ]
    if request.separator is not None:
        lines.insert(0, "dump_caps:")
    sep = request.separator or "\n"
    return (sep.join(lines) + sep + "RPRT 0\n").encode("latin-1")


def dump_state(request: RotctldRequest, scale: AzimuthScale) -> bytes:
    """``\\dump_state``, protocol 1 (the layout Hamlib 4.5.1 and later read)."""
    numbers = [
        ("rotctld Protocol Ver", "", str(PROTOCOL_VERSION)),
        ("Rotor Model", "", str(MODEL)),
        ("Minimum Azimuth", "min_az=", f"{scale.min_az:.6f}"),
        ("Maximum Azimuth", "max_az=", f"{scale.max_az:.6f}"),
        ("Minimum Elevation", "min_el=", f"{0.0:.6f}"),
        ("Maximum Elevation", "max_el=", f"{90.0:.6f}"),
        ("South Zero", "south_zero=", "0"),
    ]
    if request.separator is None:
        lines = [key + value for _, key, value in numbers] + ["rot_type=AzEl", "done"]
        return "".join(line + "\n" for line in lines).encode("latin-1")
    sep = request.separator
    records = ["dump_state:"] + [f"{label}: {value}" for label, _, value in numbers]
    records += ["rot_type=AzEl", "done"]
    return (sep.join(records) + sep + "RPRT 0\n").encode("latin-1")


__all__ = [
    "CLOCKWISE",
    "COMMANDS",
    "COUNTERCLOCKWISE",
    "DIRECTIONS",
    "EINVAL",
    "EIO",
    "ENAVAIL",
    "ENIMPL",
    "ERJCTED",
    "ETIMEOUT",
    "LONG_NAMES",
    "MOVE_STEP",
    "AzimuthScale",
    "RequestParser",
    "RotctldRequest",
    "answer",
    "azimuth_for",
    "dump_caps",
    "dump_state",
    "move_target",
    "parse_direction",
    "parse_number",
    "scale_for",
]
