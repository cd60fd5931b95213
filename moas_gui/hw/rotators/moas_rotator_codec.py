"""The MOAS Rotator protocol (appendix B, TCP 13020), sans-IO, both ends.

Text lines of 8-bit ASCII, fields separated by one space, ended by CR (LF and
CR LF are accepted on input).  Server to program::

    VERSION
    CONFIGURE <rotator> <model> <port> <poll>     (ERRATA: model before port)
    ROTATE <rotator> <degrees>
    STOP <rotator>

Program to server::

    VERSION <major>.<minor>
    <rotator> <degrees>                            (a heading report)

Model numbers (appendix B and ERRATA): DCU1=1, RotorEZ=2, Yaesu=4,
Alfaspid=5, RC2800P-A=8, RC2800P-X=9, Prosistel D=10.

What ``<degrees>`` means depends on the controller.  Appendix B says "for
most rotators" it counts clockwise from the counterclockwise stop; the
controllers that know north themselves (DCU-1, Rotor-EZ: they take and give
compass bearings 0-359 and guard their own stop, like the Rotor-EZ with a
south stop in the manual's example 6.9.1) are the exception.  ``SCALES``
records which is which; see ``docs/rotators.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

from .ascii import is_digits

MAX_LINE = 256
"""A line longer than this (bytes, without terminator) is thrown away."""


class Scale(Enum):
    """What the degrees of ROTATE and of a heading report mean for a model."""

    FROM_CCW_STOP = "degrees clockwise from the counterclockwise stop"
    COMPASS = "compass bearing 0-359"


MODEL_NUMBERS: dict[str, int] = {
    "DCU1": 1, "RotorEZ": 2, "Yaesu": 4, "Alfaspid": 5,
    "RC2800P-A": 8, "RC2800P-X": 9, "Prosistel D": 10,
}
COMPASS_MODELS = frozenset({1, 2})
SCALES: dict[int, Scale] = {
    number: Scale.COMPASS if number in COMPASS_MODELS else Scale.FROM_CCW_STOP
    for number in MODEL_NUMBERS.values()
}


def model_field(model: str) -> tuple[str, Scale]:
    """The CONFIGURE model field for a configuration ``Model``, and its scale.

    Known names (any case, spaces and dashes optional) become their number; a
    number is sent as it is; another single word is sent as a name for the
    program to judge.  Raises ``ValueError`` with a sentence otherwise.
    """
    text = model.strip()
    if not text:
        raise ValueError(f"Model is missing (one of {', '.join(MODEL_NUMBERS)})")
    if is_digits(text):
        number = int(text)
        return str(number), SCALES.get(number, Scale.FROM_CCW_STOP)
    wanted = _squash(text)
    for name, number in MODEL_NUMBERS.items():
        if _squash(name) == wanted:
            return str(number), SCALES[number]
    if any(c.isspace() for c in text):
        raise ValueError(
            f"Model {model!r} is not one of {', '.join(MODEL_NUMBERS)} and, "
            "having a space, cannot be sent in CONFIGURE"
        )
    return text, Scale.FROM_CCW_STOP


def _squash(name: str) -> str:
    return "".join(c for c in name.lower() if c.isalnum())


def check_field(what: str, value: str) -> str:
    """A text field of a command: one word of printable ASCII."""
    if not value or any(c.isspace() or not 32 < ord(c) < 127 for c in value):
        raise ValueError(f"{what} {value!r} must be one word of plain ASCII to go in CONFIGURE")
    return value


# ---- server side: commands out, reports in -------------------------------------------

def encode_version() -> bytes:
    return b"VERSION\r"


def encode_configure(rotator: int, model: str, port: str, poll: int) -> bytes:
    check_field("model", model)
    check_field("CommPort", port)
    return f"CONFIGURE {rotator} {model} {port} {int(poll)}\r".encode("latin-1")


def encode_rotate(rotator: int, degrees: float) -> bytes:
    return f"ROTATE {rotator} {round(degrees)}\r".encode("ascii")


def encode_stop(rotator: int) -> bytes:
    return f"STOP {rotator}\r".encode("ascii")


@dataclass(frozen=True, slots=True)
class VersionReport:
    version: str


@dataclass(frozen=True, slots=True)
class HeadingReport:
    rotator: int
    degrees: float


@dataclass(frozen=True, slots=True)
class BadLine:
    """A line that means nothing; ``reason`` says why, ``rotator`` when one is named."""

    line: str
    reason: str
    rotator: int | None = None


Report = VersionReport | HeadingReport | BadLine


class LineSplitter:
    """Bytes in, complete lines out (CR, LF or CR LF; empty lines dropped)."""

    def __init__(self, max_line: int = MAX_LINE) -> None:
        self.max_line = max_line
        self._buffer = bytearray()
        self._discarding = False

    def feed(self, data: bytes) -> list[str | BadLine]:
        out: list[str | BadLine] = []
        for byte in data:
            if byte in (0x0D, 0x0A):
                if self._discarding:
                    self._discarding = False
                elif self._buffer:
                    out.append(self._buffer.decode("latin-1"))
                self._buffer.clear()
            elif self._discarding:
                continue
            elif len(self._buffer) >= self.max_line:
                head = self._buffer[:40].decode("latin-1")
                out.append(BadLine(head + "...", f"line longer than {self.max_line} bytes"))
                self._buffer.clear()
                self._discarding = True
            else:
                self._buffer.append(byte)
        return out


def parse_report(line: str) -> Report:
    """One line from the program."""
    fields = line.split()
    if len(fields) == 2 and fields[0] == "VERSION":
        return VersionReport(fields[1])
    if len(fields) == 2 and _is_int(fields[0]):
        rotator = int(fields[0])
        degrees = _number(fields[1])
        if degrees is None:
            return BadLine(line, f"heading {fields[1]!r} is not a number", rotator)
        return HeadingReport(rotator, degrees)
    if fields and _is_int(fields[0]):
        return BadLine(line, "a heading report has exactly two fields", int(fields[0]))
    return BadLine(line, "neither a VERSION line nor '<rotator> <degrees>'")


class ReportDecoder:
    """Bytes from the program in, :data:`Report` events out."""

    def __init__(self) -> None:
        self._lines = LineSplitter()

    def feed(self, data: bytes) -> list[Report]:
        return [
            item if isinstance(item, BadLine) else parse_report(item)
            for item in self._lines.feed(data)
        ]


# ---- program side (used by the fake program) ------------------------------------------

@dataclass(frozen=True, slots=True)
class VersionQuery:
    pass


@dataclass(frozen=True, slots=True)
class Configure:
    rotator: int
    model: str
    port: str
    poll: int


@dataclass(frozen=True, slots=True)
class Rotate:
    rotator: int
    degrees: float


@dataclass(frozen=True, slots=True)
class Stop:
    rotator: int


Command = VersionQuery | Configure | Rotate | Stop | BadLine


def parse_command(line: str) -> Command:
    """One line from the server.  CONFIGURE takes either field order: the port
    is the field that is not a number."""
    fields = line.split()
    if not fields:
        return BadLine(line, "empty command")
    word, args = fields[0].upper(), fields[1:]
    if word == "VERSION" and not args:
        return VersionQuery()
    if not args or not _is_int(args[0]):
        return BadLine(line, f"{word} needs a rotator number first")
    rotator = int(args[0])
    if word == "CONFIGURE" and len(args) == 4 and _is_int(args[3]):
        first, second = args[1], args[2]
        model, port = (first, second) if _is_int(first) or not _is_int(second) else (second, first)
        return Configure(rotator, model, port, int(args[3]))
    if word == "ROTATE" and len(args) == 2:
        degrees = _number(args[1])
        if degrees is not None:
            return Rotate(rotator, degrees)
    if word == "STOP" and len(args) == 1:
        return Stop(rotator)
    return BadLine(line, f"not a well-formed {word} command", rotator)


def encode_version_reply(version: str) -> bytes:
    return f"VERSION {version}\r".encode("ascii")


def encode_heading(rotator: int, degrees: float) -> bytes:
    return f"{rotator} {round(degrees)}\r".encode("ascii")


def _is_int(text: str) -> bool:
    body = text[1:] if text[:1] == "-" else text
    return is_digits(body)


def _number(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


__all__ = [
    "COMPASS_MODELS",
    "MAX_LINE",
    "MODEL_NUMBERS",
    "SCALES",
    "BadLine",
    "Command",
    "Configure",
    "HeadingReport",
    "LineSplitter",
    "Report",
    "ReportDecoder",
    "Rotate",
    "Scale",
    "Stop",
    "VersionQuery",
    "VersionReport",
    "encode_configure",
    "encode_heading",
    "encode_rotate",
    "encode_stop",
    "encode_version",
    "encode_version_reply",
    "model_field",
    "parse_command",
    "parse_report",
]
