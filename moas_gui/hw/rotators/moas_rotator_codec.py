"""The MOAS Rotator protocol (appendix B, TCP 13020), sans-IO, both ends.

The one codec of this protocol: the server's link (``moas_rotator_link``), the
MOAS Rotator program (``moas_gui.rotator_program``) and the test stand-in
(``moas_gui.testing.fake_moas_rotator``) all read and write through it.

Text lines of 8-bit ASCII, fields separated by spaces, ended by CR (LF and
CR LF are accepted on input).  Server to program::

    VERSION                                    -> "VERSION <major>.<minor>"
    CONFIGURE <rotator> <model> <port> <poll>  (the manual's worked example; ERRATA)
    CONFIGURE <rotator> <port> <model> <poll>  (the manual's format line; read too)
    ROTATE <rotator> <degrees>
    STOP <rotator>

Program to server::

    VERSION <major>.<minor>
    <rotator> <degrees>                        (a heading report)

The two CONFIGURE orders are told apart by the port being the field that is
not a number; a model may also be given by name ("Yaesu", "Prosistel D"),
and then the field that names a known model is the model.  Every line that
cannot be understood becomes a :class:`BadRotatorLine` saying why, with the rotator
number when one could be read; no parser here raises.

Model numbers (appendix B and ERRATA): DCU1=1, RotorEZ=2, Yaesu=4,
Alfaspid=5, RC2800P-A=8, RC2800P-X=9, Prosistel D=10.  What ``<degrees>``
means depends on the controller: for most it counts clockwise from the
counterclockwise stop; the controllers that know north themselves (DCU-1,
Rotor-EZ) take and give compass bearings 0-359.  ``SCALES`` records which is
which; see ``docs/rotators.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

from moas_gui.line_framer import LineEnd, LineFramer, LongLine

from .ascii import is_digits
from .controllers.models import is_model_name

PORT = 13020
"""The TCP port of the MOAS Rotator program (fixed by the original)."""

MAX_REPORT_LINE = 256
"""A report longer than this (bytes, without terminator) is thrown away by the server."""

MAX_COMMAND_LINE = 512
"""A command longer than this is refused by the program without waiting for its end."""


class HeadingScale(Enum):
    """What the degrees of ROTATE and of a heading report mean for a model."""

    FROM_CCW_STOP = "degrees clockwise from the counterclockwise stop"
    COMPASS = "compass bearing 0-359"


MODEL_NUMBERS: dict[str, int] = {
    "DCU1": 1, "RotorEZ": 2, "Yaesu": 4, "Alfaspid": 5,
    "RC2800P-A": 8, "RC2800P-X": 9, "Prosistel D": 10,
}
COMPASS_MODELS = frozenset({1, 2})
SCALES: dict[int, HeadingScale] = {
    number: HeadingScale.COMPASS if number in COMPASS_MODELS else HeadingScale.FROM_CCW_STOP
    for number in MODEL_NUMBERS.values()
}


def model_field(model: str) -> tuple[str, HeadingScale]:
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
        return str(number), SCALES.get(number, HeadingScale.FROM_CCW_STOP)
    wanted = _squash(text)
    for name, number in MODEL_NUMBERS.items():
        if _squash(name) == wanted:
            return str(number), SCALES[number]
    if any(c.isspace() for c in text):
        raise ValueError(
            f"Model {model!r} is not one of {', '.join(MODEL_NUMBERS)} and, "
            "having a space, cannot be sent in CONFIGURE"
        )
    return text, HeadingScale.FROM_CCW_STOP


def _squash(name: str) -> str:
    return "".join(c for c in name.lower() if c.isalnum())


def check_field(what: str, value: str) -> str:
    """A text field of a command: one word of printable ASCII."""
    if not value or any(c.isspace() or not 32 < ord(c) < 127 for c in value):
        raise ValueError(f"{what} {value!r} must be one word of plain ASCII to go in CONFIGURE")
    return value


# ---- the messages --------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class VersionRequest:
    """``VERSION``."""


@dataclass(frozen=True, slots=True)
class Configure:
    """``CONFIGURE``: drive a rotator of ``model`` on ``port``, asking every ``poll_ms``."""

    rotator: int
    model: str
    """As sent: a MOAS number ("2") or a name ("RotorEZ")."""
    port: str
    poll_ms: int


@dataclass(frozen=True, slots=True)
class Rotate:
    """``ROTATE``: turn ``rotator`` to ``degrees``."""

    rotator: int
    degrees: float


@dataclass(frozen=True, slots=True)
class Stop:
    """``STOP``: stop ``rotator``."""

    rotator: int


@dataclass(frozen=True, slots=True)
class VersionReport:
    """``VERSION <major>.<minor>`` from the program."""

    version: str


@dataclass(frozen=True, slots=True)
class HeadingReport:
    """``<rotator> <degrees>`` from the program."""

    rotator: int
    degrees: float


@dataclass(frozen=True, slots=True)
class BadRotatorLine:
    """A line, either way, that means nothing; ``reason`` says why, ``rotator`` when
    one is named."""

    line: str
    reason: str
    rotator: int | None = None


@dataclass(frozen=True, slots=True)
class PortReport:
    """``OFFLINE <rotator> <why...>`` / ``ONLINE <rotator>`` from this project's program:
    whether the rotator's controller can be reached (``reason`` None: it can).  An
    addition to the protocol, sent only to a server: the original program never sends
    it, and the original server would log it as a line it does not know."""

    rotator: int
    reason: str | None


RotatorCommand = VersionRequest | Configure | Rotate | Stop
Report = VersionReport | HeadingReport | PortReport


# ---- server side: commands out, reports in -------------------------------------------

def encode_version() -> bytes:
    return b"VERSION\r"


def encode_configure(rotator: int, model: str, port: str, poll_ms: int) -> bytes:
    check_field("model", model)
    check_field("CommPort", port)
    return f"CONFIGURE {rotator} {model} {port} {int(poll_ms)}\r".encode("latin-1")


def encode_rotate(rotator: int, degrees: float) -> bytes:
    return f"ROTATE {rotator} {round(degrees)}\r".encode("ascii")


def encode_stop(rotator: int) -> bytes:
    return f"STOP {rotator}\r".encode("ascii")


class RotatorLineReader:
    """Bytes in, complete lines out as text (CR, LF or CR LF end a line; empty lines
    dropped); a line longer than ``max_line`` becomes one :class:`BadRotatorLine` as
    soon as that is certain, and the rest of it is skipped to its end.  The cutting is
    :class:`~moas_gui.line_framer.LineFramer`'s."""

    __slots__ = ("_framer", "max_line")

    def __init__(self, max_line: int = MAX_REPORT_LINE) -> None:
        self.max_line = max_line
        self._framer = LineFramer(max_line, LineEnd.CR_OR_LF)

    def feed(self, data: bytes) -> list[str | BadRotatorLine]:
        out: list[str | BadRotatorLine] = []
        for item in self._framer.feed(data):
            if isinstance(item, LongLine):
                out.append(BadRotatorLine(item.head.decode("latin-1") + "...",
                                          f"line longer than {self.max_line} bytes; ignored"))
            elif item.data:
                out.append(item.data.decode("latin-1"))
        return out


def parse_report(line: str) -> Report | BadRotatorLine:
    """One line from the program."""
    fields = line.split()
    if len(fields) == 2 and fields[0] == "VERSION":
        return VersionReport(fields[1])
    if len(fields) >= 2 and fields[0] in ("OFFLINE", "ONLINE") and _is_int(fields[1]):
        why = " ".join(fields[2:]) or "its controller cannot be reached"
        return PortReport(int(fields[1]), why if fields[0] == "OFFLINE" else None)
    if len(fields) == 2 and _is_int(fields[0]):
        rotator = int(fields[0])
        degrees = _finite(fields[1])
        if degrees is None:
            return BadRotatorLine(line, f"heading {fields[1]!r} is not a number", rotator)
        return HeadingReport(rotator, degrees)
    if fields and _is_int(fields[0]):
        return BadRotatorLine(line, "a heading report has exactly two fields", int(fields[0]))
    return BadRotatorLine(line, "neither a VERSION line nor '<rotator> <degrees>'")


class ReportDecoder:
    """Bytes from the program in, reports (or :class:`BadRotatorLine`) out."""

    def __init__(self) -> None:
        self._lines = RotatorLineReader(MAX_REPORT_LINE)

    def feed(self, data: bytes) -> list[Report | BadRotatorLine]:
        return [
            item if isinstance(item, BadRotatorLine) else parse_report(item)
            for item in self._lines.feed(data)
        ]


# ---- program side: commands in, reports out ------------------------------------------

def encode_version_reply(version: str) -> bytes:
    """``VERSION <major>.<minor>`` from a version like "0.1.0"."""
    parts = (version.split(".") + ["0"])[:2]
    major, minor = (int(p) if is_digits(p) else 0 for p in parts)
    return f"VERSION {major}.{minor}\r".encode("ascii")


def encode_port_state(rotator: int, reason: str | None) -> bytes:
    """``OFFLINE <rotator> <reason>`` or ``ONLINE <rotator>`` (see :class:`PortReport`)."""
    if reason is None:
        return f"ONLINE {rotator}\r".encode("ascii")
    words = " ".join(reason.split())[:MAX_REPORT_LINE - 20]
    return f"OFFLINE {rotator} {words}\r".encode("ascii", "replace")


def encode_heading(rotator: int, degrees: float) -> bytes:
    """``<rotator> <degrees>``, in whole degrees."""
    return f"{rotator} {round(degrees)}\r".encode("ascii")


def parse_command(line: str) -> RotatorCommand | BadRotatorLine:
    """One line from the server, without its terminator."""
    fields = line.split()
    if not fields:
        return BadRotatorLine(line, "empty command")
    word = fields[0].upper()
    if word == "VERSION":
        if len(fields) != 1:
            return BadRotatorLine(line, "VERSION takes no fields")
        return VersionRequest()
    if word == "CONFIGURE":
        return _configure(line, fields)
    if word in ("ROTATE", "STOP"):
        wanted = 3 if word == "ROTATE" else 2
        rotator = _rotator(fields[1]) if len(fields) > 1 else None
        usage = "ROTATE needs <rotator> <degrees>" if word == "ROTATE" else "STOP needs <rotator>"
        if len(fields) != wanted:
            return BadRotatorLine(line, usage, rotator)
        if rotator is None:
            return BadRotatorLine(line, f"rotator number {fields[1]!r} is not a whole number >= 0")
        if word == "STOP":
            return Stop(rotator)
        degrees = _finite(fields[2])
        if degrees is None:
            return BadRotatorLine(line, f"heading {fields[2]!r} is not a number of degrees",
                                  rotator)
        return Rotate(rotator, degrees)
    return BadRotatorLine(line, f"unknown command {fields[0]!r} (known: VERSION, CONFIGURE, "
                         "ROTATE, STOP)")


def _configure(line: str, fields: list[str]) -> Configure | BadRotatorLine:
    usage = "CONFIGURE needs <rotator> <model> <port> <poll>"
    if len(fields) < 5:
        return BadRotatorLine(line, usage, _rotator(fields[1]) if len(fields) > 1 else None)
    rotator = _rotator(fields[1])
    if rotator is None:
        return BadRotatorLine(line, f"rotator number {fields[1]!r} is not a whole number >= 0")
    poll = fields[-1]
    if not is_digits(poll):
        return BadRotatorLine(line, f"poll time {poll!r} is not a whole number of milliseconds",
                       rotator)
    split = _model_and_port(fields[2:-1])
    if isinstance(split, str):
        return BadRotatorLine(line, split, rotator)
    model, port = split
    return Configure(rotator, model, port, int(poll))


def _model_and_port(middle: list[str]) -> tuple[str, str] | str:
    """``(model, port)`` from the fields between rotator and poll, or why not."""
    if len(middle) == 2:
        first, second = middle
        if _numeric(first) != _numeric(second):
            return (first, second) if _numeric(first) else (second, first)
        if _numeric(first):
            return f"no port: both {first!r} and {second!r} are numbers"
        first_is, second_is = is_model_name(first), is_model_name(second)
        if first_is and not second_is:
            return first, second
        if second_is and not first_is:
            return second, first
        if first_is:
            return f"cannot tell the port from the model: {first!r} and {second!r} are both models"
        first_port, second_port = _looks_like_port(first), _looks_like_port(second)
        if first_port != second_port:  # an unknown model beside a port: the model is refused
            return (second, first) if first_port else (first, second)
        return f"unknown rotator model: neither {first!r} nor {second!r} names a model"
    # A name with a space ("Prosistel D"), or a port name with one: longest model name first.
    for cut in range(len(middle) - 1, 0, -1):
        head = " ".join(middle[:cut])
        if is_model_name(head):
            return head, " ".join(middle[cut:])
    for cut in range(1, len(middle)):
        tail = " ".join(middle[cut:])
        if is_model_name(tail):
            return tail, " ".join(middle[:cut])
    if _numeric(middle[0]):
        return middle[0], " ".join(middle[1:])
    if _numeric(middle[-1]):
        return middle[-1], " ".join(middle[:-1])
    return "unknown rotator model: no field names a model"


def _looks_like_port(text: str) -> bool:
    """COM3, /dev/ttyUSB0, socket://host:port, a Windows device path and the like."""
    return text.upper().startswith("COM") or "/" in text or "\\" in text


class CommandDecoder:
    """Bytes from the server in, commands (or :class:`BadRotatorLine`) out."""

    __slots__ = ("_lines",)

    def __init__(self) -> None:
        self._lines = RotatorLineReader(MAX_COMMAND_LINE)

    def feed(self, data: bytes) -> list[RotatorCommand | BadRotatorLine]:
        out: list[RotatorCommand | BadRotatorLine] = []
        for item in self._lines.feed(data):
            if isinstance(item, BadRotatorLine):
                out.append(item)
            elif text := item.strip():
                out.append(parse_command(text))
        return out


# ---- numbers -------------------------------------------------------------------------

def _is_int(text: str) -> bool:
    """A report's whole number: ASCII digits, perhaps after a minus."""
    return is_digits(text[1:] if text[:1] == "-" else text)


def _numeric(text: str) -> bool:
    """A command field that is a number rather than a name or a port."""
    return is_digits(text.lstrip("+-"))


def _rotator(text: str) -> int | None:
    return int(text) if is_digits(text) else None


def _finite(text: str) -> float | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


__all__ = [
    "COMPASS_MODELS",
    "MAX_COMMAND_LINE",
    "MAX_REPORT_LINE",
    "MODEL_NUMBERS",
    "PORT",
    "SCALES",
    "BadRotatorLine",
    "CommandDecoder",
    "Configure",
    "HeadingReport",
    "HeadingScale",
    "PortReport",
    "Report",
    "ReportDecoder",
    "Rotate",
    "RotatorCommand",
    "RotatorLineReader",
    "Stop",
    "VersionReport",
    "VersionRequest",
    "check_field",
    "encode_configure",
    "encode_heading",
    "encode_port_state",
    "encode_rotate",
    "encode_stop",
    "encode_version",
    "encode_version_reply",
    "model_field",
    "parse_command",
    "parse_report",
]
