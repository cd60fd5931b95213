"""Reading one request line: sans-IO, every rule in one table.

:data:`COMMANDS` lists each command of the client protocol with its
arguments; :func:`parse_line` turns one line into exactly one of

* :class:`Request` -- a well-formed request, its arguments checked and typed;
* :class:`InvalidRequest` -- a JSON object that asks for something malformed
  (missing or wrongly typed argument: ``bad_request``; no such command:
  ``unknown_cmd``); it is answered with its own ``id`` and the connection is
  in good standing;
* :class:`BadLine` -- a line that is not a JSON object at all; answered with
  ``"id": null``, and three in a row close the connection;
* ``None`` -- a blank line, which is not a request and is ignored.

Arguments absent and arguments given as ``null`` are the same thing.  Names a
command does not know are ignored, so that clients written for a later
version of the protocol still work.  ``docs/client-protocol.md`` documents
the same table, and a test checks that every command and argument in it is
documented there.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from enum import Enum
from typing import Any

from .backend import ErrorCode

MAX_ID = 2_147_483_647
"""The largest configuration number (manual 5.1)."""
MAX_GRID = 1000
MAX_KHZ = 1_000_000_000.0
MAX_CLIENT_NAME = 200
MAX_DEPTH = 64
"""The deepest nesting of lists and objects a request line may hold; deeper
lines are refused before they are parsed (a request needs two levels)."""


class Kind(Enum):
    """What an argument may hold; the value is how the docs and errors say it."""

    NUMBER_ID = f"a whole number from 0 to {MAX_ID}"
    KHZ = "a frequency in kHz: a number from 0 to 1000000000"
    HEADING = "a heading in degrees: a number from -360 to 720"
    BOOL = "true or false"
    TEXT = f"a string of at most {MAX_CLIENT_NAME} characters"
    TARGET = 'one of "both", "tx" and "rx"'
    STEP = "1 (next) or -1 (previous)"
    INDEX = f"a position in the list: a whole number from 0 to {MAX_ID}"
    COUNT = f"a whole number from 1 to {MAX_GRID}"


@dataclass(frozen=True, slots=True)
class Arg:
    """One argument of a client command: its name, kind, whether it is needed, its
    default and its description."""

    name: str
    kind: Kind
    required: bool = True
    default: Any = None
    doc: str = ""


@dataclass(frozen=True, slots=True)
class Command:
    """A client command: its arguments, what it answers, and its description."""

    name: str
    args: tuple[Arg, ...]
    result: str
    doc: str
    check: Callable[[Mapping[str, Any]], str | None] | None = None
    """A rule across arguments; returns the complaint, or ``None`` when fine."""


def _one_of_step_index(args: Mapping[str, Any]) -> str | None:
    if (args["step"] is None) == (args["index"] is None):
        return 'relative needs exactly one of "step" (1 or -1) and "index" (0, 1, 2, ...)'
    return None


_STATION = Arg("station", Kind.NUMBER_ID, doc="the station number")
_RADIO = Arg("radio", Kind.NUMBER_ID, doc="the radio number of that station")
_FORCE = Arg("force", Kind.BOOL, False, False,
                     doc="do it even while a radio transmits (its relays open under the "
                         "key); without it a keyed radio refuses the command")
_TX_RX = '{"tx": ID or null, "rx": ID or null} after the change'

COMMANDS: dict[str, Command] = {
    c.name: c
    for c in (
        Command(
            "hello",
            (
                Arg("client", Kind.TEXT, doc="the client's name, shown in the server's log"),
                Arg("station", Kind.NUMBER_ID, False, doc="the station this client serves"),
                Arg("radio", Kind.NUMBER_ID, False, doc="the radio this client serves"),
                Arg("log", Kind.BOOL, False, False, doc="also send log events"),
                Arg("token", Kind.TEXT, False, doc="an operator's token, where one is needed "
                    "or to act as that operator (docs/security.md)"),
            ),
            '{"server": "moas-gui", "version": "X.Y.Z", "protocol": 1}',
            "introduces the client; a state event follows, then change events",
        ),
        Command("state", (), "the snapshot", "the whole state now"),
        Command(
            "frequency",
            (
                _STATION,
                _RADIO,
                Arg("khz", Kind.KHZ, doc="the receive (and transmit) frequency"),
                Arg("tx_khz", Kind.KHZ, False, doc="the transmit frequency when split"),
            ),
            "{}",
            "a radio's frequency, as a logger reports it; antenna selection follows",
        ),
        Command(
            "active",
            (_STATION, _RADIO),
            "{}",
            "the station's transmit focus is on this radio (SO2R), as its logger says",
        ),
        Command(
            "focus",
            (_STATION, _RADIO),
            "{}",
            "the station's receive focus (the operator's keyboard) is on this radio",
        ),
        Command(
            "select",
            (
                _STATION,
                _RADIO,
                Arg("antenna", Kind.NUMBER_ID, doc="the antenna ID"),
                Arg("target", Kind.TARGET, False, "both", doc="which antenna to set"),
                Arg("exclusive", Kind.BOOL, False, False, doc="select this one alone"),
            ),
            _TX_RX,
            "a button press",
        ),
        Command(
            "function",
            (_STATION, _RADIO, Arg("function", Kind.NUMBER_ID, doc="the function ID")),
            "{}",
            "runs one of the configuration's functions for the radio",
        ),
        Command(
            "release",
            (_STATION, _RADIO),
            "{}",
            "releases the hold on a radio's antennas, whoever set it: they follow its "
            "frequency again",
        ),
        Command(
            "relative",
            (
                _STATION,
                _RADIO,
                Arg("step", Kind.STEP, False, doc="next or previous relative antenna"),
                Arg("index", Kind.INDEX, False, doc="position in the relative list, from 0"),
            ),
            _TX_RX,
            "selects from the radio's relative antenna list",
            _one_of_step_index,
        ),
        Command(
            "layout",
            (
                _STATION,
                _RADIO,
                Arg("rows", Kind.COUNT, doc="rows of buttons the client shows"),
                Arg("columns", Kind.COUNT, doc="columns of buttons the client shows"),
            ),
            "the layout",
            "the closest configured layout; layout events follow when it changes",
        ),
        Command(
            "rotate",
            (
                Arg("rotator", Kind.NUMBER_ID, doc="the rotator ID"),
                Arg("heading", Kind.HEADING, doc="where to point"),
            ),
            "{}",
            "starts turning a rotator",
        ),
        Command(
            "stop",
            (Arg("rotator", Kind.NUMBER_ID, doc="the rotator ID"),),
            "{}",
            "stops a rotator",
        ),
        Command("stop_switches", (_FORCE,), "{}",
                "stops every switch: all relays off (admin only)"),
        Command("start_switches", (), "{}",
                "starts the switches again after stop_switches (admin only)"),
        Command("reset_switches", (_FORCE,), "{}",
                "resets every switch and sets the antennas in use again (admin only)"),
    )
}


@dataclass(frozen=True, slots=True)
class Request:
    """A well-formed request; ``args`` holds every argument of its command
    (defaults filled in, ``None`` for optional ones not given)."""

    id: Any
    cmd: str
    args: Mapping[str, Any]


@dataclass(frozen=True, slots=True)
class InvalidRequest:
    """A JSON object that cannot be served as asked."""

    id: Any
    code: ErrorCode
    message: str


@dataclass(frozen=True, slots=True)
class BadLine:
    """A line that is not a JSON object."""

    message: str


def describe(value: Any) -> str:
    """A value as an error message quotes it: short, and saying its JSON type."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        text = repr(value)
        return text if len(text) <= 24 else f"a {len(text)}-digit number"
    if isinstance(value, str):
        shown = value if len(value) <= 24 else value[:24] + "..."
        return "the string " + json.dumps(shown)
    if isinstance(value, list):
        return "a list"
    return "an object"


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    try:
        number = float(value)
    except OverflowError:
        return None
    return number if math.isfinite(number) else None


def _whole(value: Any, low: int, high: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and low <= value <= high


def _convert(kind: Kind, value: Any) -> tuple[bool, Any]:
    """``(True, typed value)`` when ``value`` is of ``kind``, else ``(False, None)``."""
    match kind:
        case Kind.NUMBER_ID | Kind.INDEX | Kind.COUNT | Kind.STEP:
            return (True, value) if _whole_of(kind, value) else (False, None)
        case Kind.BOOL:
            return (True, value) if isinstance(value, bool) else (False, None)
        case Kind.TEXT:
            ok = isinstance(value, str) and len(value) <= MAX_CLIENT_NAME
            return (True, value) if ok else (False, None)
        case Kind.TARGET:
            return (True, value) if value in ("both", "tx", "rx") else (False, None)
        case Kind.KHZ | Kind.HEADING:
            number = _number_of(kind, value)
            return (True, number) if number is not None else (False, None)
    return False, None  # pragma: no cover - every kind is matched above


def _whole_of(kind: Kind, value: Any) -> bool:
    """Whether ``value`` is a whole number a whole-number kind allows: an ID or index
    from 0, a count from 1 to the largest grid, a step of -1 or +1."""
    if kind is Kind.COUNT:
        return _whole(value, 1, MAX_GRID)
    if kind is Kind.STEP:
        return _whole(value, -1, 1) and value != 0
    return _whole(value, 0, MAX_ID)


def _number_of(kind: Kind, value: Any) -> float | None:
    """``value`` as a number a numeric kind allows (None when it is not): a frequency
    from 0 to the highest kHz, a heading from -360 to 720 degrees."""
    number = _number(value)
    if number is None:
        return None
    low, high = (0.0, MAX_KHZ) if kind is Kind.KHZ else (-360.0, 720.0)
    return number if low <= number <= high else None


def _needs(command: Command) -> str:
    names = [f'"{a.name}"' for a in command.args if a.required]
    if len(names) > 1:
        return ", ".join(names[:-1]) + " and " + names[-1]
    return names[0] if names else "nothing"


def check_request(request_id: Any, cmd: Any, obj: Mapping[str, Any]) -> Request | InvalidRequest:
    """Checks the command name and the arguments of a decoded request object."""
    if cmd is None:
        return InvalidRequest(
            request_id, ErrorCode.BAD_REQUEST,
            '"cmd" is missing: every request names its command, as in {"cmd": "state"}',
        )
    if not isinstance(cmd, str):
        return InvalidRequest(
            request_id, ErrorCode.BAD_REQUEST, f'"cmd" must be a string, not {describe(cmd)}'
        )
    command = COMMANDS.get(cmd)
    if command is None:
        return InvalidRequest(
            request_id, ErrorCode.UNKNOWN_CMD,
            f"there is no command {json.dumps(cmd if len(cmd) <= 40 else cmd[:40] + '...')}; "
            "the commands are " + ", ".join(COMMANDS),
        )
    args: dict[str, Any] = {}
    for arg in command.args:
        value = obj.get(arg.name)
        if value is None:
            if arg.required:
                return InvalidRequest(
                    request_id, ErrorCode.BAD_REQUEST,
                    f'"{arg.name}" is missing: {cmd} needs {_needs(command)}',
                )
            args[arg.name] = arg.default
            continue
        ok, typed = _convert(arg.kind, value)
        if not ok:
            return InvalidRequest(
                request_id, ErrorCode.BAD_REQUEST,
                f'"{arg.name}" must be {arg.kind.value}, not {describe(value)}',
            )
        args[arg.name] = typed
    if command.check is not None:
        complaint = command.check(args)
        if complaint is not None:
            return InvalidRequest(request_id, ErrorCode.BAD_REQUEST, complaint)
    return Request(request_id, cmd, args)


def _no_constants(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON value")


def _finite(text: str) -> float:
    number = float(text)
    if not math.isfinite(number):
        raise ValueError(f"{text[:24]} is too large for a number")
    return number


_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
_BRACKET = re.compile(r"[\[\]{}]")


def too_deep(text: str, limit: int = MAX_DEPTH) -> bool:
    """Whether ``text`` nests lists and objects more than ``limit`` deep
    (brackets inside strings do not count).  Linear in the length of ``text``."""
    if text.count("[") + text.count("{") <= limit:
        return False
    depth = 0
    for match in _BRACKET.finditer(_STRING.sub("", text)):
        if match.group() in "[{":
            depth += 1
            if depth > limit:
                return True
        else:
            depth -= 1
    return False


def parse_line(line: bytes) -> Request | InvalidRequest | BadLine | None:
    """One line (without its ending) to what it asks; see the module's docstring."""
    try:
        text = line.decode("utf-8")
    except UnicodeDecodeError as e:
        return BadLine(f"the line is not UTF-8 text (byte {e.start + 1} is 0x{line[e.start]:02x})")
    if not text.strip():
        return None
    if too_deep(text):
        return BadLine(f"the line is nested too deeply for this server (over {MAX_DEPTH} levels)")
    try:
        obj = json.loads(text, parse_constant=_no_constants, parse_float=_finite)
    except json.JSONDecodeError as e:
        return BadLine(f"the line is not JSON: {e.msg} at column {e.colno}")
    except RecursionError:  # pragma: no cover - too_deep refuses these first
        return BadLine("the line is nested too deeply for this server")
    except ValueError as e:  # NaN/Infinity, or an integer with thousands of digits
        return BadLine(f"the line is not JSON this server accepts: {e}")
    if not isinstance(obj, dict):
        return BadLine(
            f"the line is JSON but {describe(obj)}, not an object; "
            'each request is one object such as {"id": 1, "cmd": "state"}'
        )
    return check_request(obj.get("id"), obj.get("cmd"), obj)


__all__ = [
    "COMMANDS",
    "MAX_DEPTH",
    "Arg",
    "BadLine",
    "Command",
    "InvalidRequest",
    "Kind",
    "Request",
    "check_request",
    "describe",
    "parse_line",
    "too_deep",
]
