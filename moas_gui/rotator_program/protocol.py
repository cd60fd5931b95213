"""The MOAS Rotator's TCP protocol (port 13020), without any I/O.

The server sends lines of 8-bit text ending in CR (LF and CRLF are taken
too), fields separated by a space::

    VERSION                                    -> "VERSION <major>.<minor>"
    CONFIGURE <rotator> <model> <port> <poll>  (the manual's worked example's order)
    CONFIGURE <rotator> <port> <model> <poll>  (the manual's format line's order)
    ROTATE <rotator> <degrees>
    STOP <rotator>

and this program sends ``<rotator> <degrees>`` whenever a heading changes.
Our messages end with CR, like the server's.

The two CONFIGURE orders are told apart by the port being the field that is
not a number; a model may also be given by name ("Yaesu", "Prosistel D"),
and then the field that names a known model is the model.  Every line that
cannot be understood becomes a :class:`BadCommand` saying why, with the
rotator number when one could be read; nothing here raises.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from moas_gui.hw.rotators.controllers.models import is_model_name

PORT = 13020
"""The TCP port of the MOAS Rotator program (fixed by the original)."""

MAX_LINE = 512
"""Longest command accepted; anything longer is refused without waiting for its end."""


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
class BadCommand:
    """A line that is not a command this program understands, and why."""

    line: str
    reason: str
    rotator: int | None = None


Command = VersionRequest | Configure | Rotate | Stop


def _number(text: str) -> bool:
    return text.lstrip("+-").isdigit()


def _looks_like_port(text: str) -> bool:
    """COM3, /dev/ttyUSB0, socket://host:port, a Windows device path and the like."""
    return text.upper().startswith("COM") or "/" in text or "\\" in text


def _rotator(text: str) -> int | None:
    return int(text) if text.isdigit() else None


def _configure(line: str, fields: list[str]) -> Command | BadCommand:
    usage = "CONFIGURE needs <rotator> <model> <port> <poll>"
    if len(fields) < 5:
        return BadCommand(line, usage, _rotator(fields[1]) if len(fields) > 1 else None)
    rotator = _rotator(fields[1])
    if rotator is None:
        return BadCommand(line, f"rotator number {fields[1]!r} is not a whole number >= 0")
    poll = fields[-1]
    if not poll.isdigit():
        return BadCommand(line, f"poll time {poll!r} is not a whole number of milliseconds",
                          rotator)
    middle = fields[2:-1]
    split = _model_and_port(middle)
    if isinstance(split, str):
        return BadCommand(line, split, rotator)
    model, port = split
    return Configure(rotator, model, port, int(poll))


def _model_and_port(middle: list[str]) -> tuple[str, str] | str:
    """``(model, port)`` from the fields between rotator and poll, or why not."""
    if len(middle) == 2:
        first, second = middle
        if _number(first) != _number(second):
            return (first, second) if _number(first) else (second, first)
        if _number(first):
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
    if _number(middle[0]):
        return middle[0], " ".join(middle[1:])
    if _number(middle[-1]):
        return middle[-1], " ".join(middle[:-1])
    return "unknown rotator model: no field names a model"


def parse_command(line: str) -> Command | BadCommand:
    """One line, without its terminator."""
    fields = line.split()
    if not fields:
        return BadCommand(line, "empty command")
    word = fields[0].upper()
    if word == "VERSION":
        if len(fields) != 1:
            return BadCommand(line, "VERSION takes no fields")
        return VersionRequest()
    if word == "CONFIGURE":
        return _configure(line, fields)
    if word in ("ROTATE", "STOP"):
        wanted = 3 if word == "ROTATE" else 2
        rotator = _rotator(fields[1]) if len(fields) > 1 else None
        usage = "ROTATE needs <rotator> <degrees>" if word == "ROTATE" else "STOP needs <rotator>"
        if len(fields) != wanted:
            return BadCommand(line, usage, rotator)
        if rotator is None:
            return BadCommand(line, f"rotator number {fields[1]!r} is not a whole number >= 0")
        if word == "STOP":
            return Stop(rotator)
        try:
            degrees = float(fields[2])
        except ValueError:
            degrees = math.nan
        if not math.isfinite(degrees):
            return BadCommand(line, f"heading {fields[2]!r} is not a number of degrees", rotator)
        return Rotate(rotator, degrees)
    return BadCommand(line, f"unknown command {fields[0]!r} (known: VERSION, CONFIGURE, "
                            "ROTATE, STOP)")


class CommandReader:
    """Cuts the server's byte stream into commands (feed it bytes as they come)."""

    __slots__ = ("_buffer", "_skipping")

    def __init__(self) -> None:
        self._buffer = b""
        self._skipping = False

    def feed(self, data: bytes) -> list[Command | BadCommand]:
        out: list[Command | BadCommand] = []
        buffer = self._buffer + data
        start = 0
        for i, byte in enumerate(buffer):
            if byte not in (0x0D, 0x0A):
                continue
            chunk = buffer[start:i]
            start = i + 1
            if self._skipping:
                self._skipping = False
                continue
            text = chunk.decode("latin-1").strip()
            if text:
                out.append(parse_command(text))
        rest = buffer[start:]
        if len(rest) > MAX_LINE:
            if not self._skipping:
                shown = rest[:40].decode("latin-1")
                out.append(BadCommand(shown + "...",
                                      f"line longer than {MAX_LINE} bytes without CR; ignored"))
            self._skipping = True
            rest = b""
        self._buffer = rest
        return out


def version_message(version: str) -> bytes:
    """``VERSION <major>.<minor>`` from a version like "0.1.0"."""
    parts = (version.split(".") + ["0"])[:2]
    major, minor = (int(p) if p.isdigit() else 0 for p in parts)
    return f"VERSION {major}.{minor}\r".encode("ascii")


def heading_message(rotator: int, degrees: int) -> bytes:
    """``<rotator> <degrees>``."""
    return f"{rotator} {degrees}\r".encode("ascii")


__all__ = [
    "MAX_LINE",
    "PORT",
    "BadCommand",
    "Command",
    "CommandReader",
    "Configure",
    "Rotate",
    "Stop",
    "VersionRequest",
    "heading_message",
    "parse_command",
    "version_message",
]
