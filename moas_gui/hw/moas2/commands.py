"""Commands to the MOAS II: one table, both directions (values to bytes for
the switch link, bytes to values for the emulator).

The rules, in plain words:

* A command is one command character, a body, and ``;``.  The table
  :data:`COMMANDS` below holds, for each command character, the manual's
  name, the message type, how to read a body and how to write one.  Nothing
  else in the package knows a command's syntax.
* Stations are the digits ``1``-``6`` (``0`` only as the station of an
  antenna command that sets the global relays).  Antennas and relays are
  one sixbit character each.  Times are plain decimal digits.
* No command this module writes is longer than :data:`MAX_COMMAND` (40)
  bytes, so the box's 128-byte input buffer cannot overflow.  Table loads
  with many pairs are split into several commands by :func:`split`; a relay
  list cannot be split (a second antenna command for the same station and
  kind *replaces* the relays), so an antenna command holds at most
  :data:`MAX_RELAYS` (35) relays and more is an error (:class:`RelayListTooLong`).
* Reading is as strict as the box: a body that does not fit its command is
  ``?A`` (:class:`CommandRejected` with code ``"A"``), a station asked to
  inhibit or switch itself is ``?T``, an unknown command character ``?U``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any, TypeVar

from .errors import CommandRejected, CommandTooLong, EncodeError, RelayListTooLong
from .messages import (
    Antenna,
    AntennaKind,
    Command,
    ConflictOp,
    ConflictTable,
    FastOp,
    FastTable,
    Inhibit,
    InhibitOthers,
    InhibitPolarity,
    InhibitTime,
    InterruptDelay,
    Mode,
    Ping,
    PolarityOp,
    ReceiveDelay,
    RelayStatusRequest,
    SetState,
    StateOp,
    StationMode,
    StatusKind,
    StatusRequest,
    SystemTable,
    Uninhibit,
    UnitId,
    UseAlternate,
    VendorExtension,
)
from .sixbit import SixbitError, decode_numbers, encode_numbers, to_char

MAX_COMMAND = 40
"""Longest command, in bytes, this program ever writes."""

MAX_RELAYS = MAX_COMMAND - len("!1B0;")
"""Most relays one antenna command can carry within :data:`MAX_COMMAND` (35)."""

MAX_PAIRS = (MAX_COMMAND - len("%C;")) // 2
"""Most table pairs one table command can carry within :data:`MAX_COMMAND` (18)."""

# --------------------------------------------------------------------------- writing helpers


def _station(number: int, *, zero: bool = False) -> str:
    low = 0 if zero else 1
    if not low <= number <= 6:
        raise EncodeError(f"station {number} is not a MOAS II station ({low}-6)")
    return str(number)


def _stations(numbers: Iterable[int]) -> str:
    return "".join(_station(n) for n in sorted(set(numbers)))


def _sixbit(number: int, what: str) -> str:
    try:
        return to_char(number)
    except SixbitError:
        raise EncodeError(f"{what} {number} is outside 0-63") from None


def _pairs(pairs: Iterable[tuple[int, int]], what: str) -> str:
    return "".join(_sixbit(a, what) + _sixbit(b, what) for a, b in pairs)


def _ms(value: int, low: int, high: int, what: str) -> str:
    if not low <= value <= high:
        raise EncodeError(f"{what} of {value} ms is outside {low}-{high} ms")
    return str(value)


# --------------------------------------------------------------------------- reading helpers


def _reject(reason: str) -> CommandRejected:
    return CommandRejected("A", reason)


def _read_station(char: str, *, zero: bool = False) -> int:
    low = "0" if zero else "1"
    if len(char) != 1 or not low <= char <= "6":
        raise _reject(f"{char!r} is not a station")
    return int(char)


def _read_stations(text: str) -> frozenset[int]:
    return frozenset(_read_station(c) for c in text)


def _read_sixbits(text: str, what: str) -> tuple[int, ...]:
    try:
        return decode_numbers(text)
    except SixbitError as exc:
        raise _reject(f"bad {what}: {exc}") from None


def _read_pairs(text: str, what: str) -> tuple[tuple[int, int], ...]:
    if len(text) % 2:
        raise _reject(f"{what} come in pairs; {len(text)} characters is odd")
    numbers = _read_sixbits(text, what)
    return tuple(zip(numbers[::2], numbers[1::2], strict=True))


def _read_ms(text: str, digits: int, low: int, high: int, what: str) -> int:
    if not 1 <= len(text) <= digits or not text.isdigit() or not text.isascii():
        raise _reject(f"{what} must be 1-{digits} digits, not {text!r}")
    value = int(text)
    if not low <= value <= high:
        raise _reject(f"{what} of {value} ms is outside {low}-{high} ms")
    return value


_E = TypeVar("_E", ConflictOp, FastOp, PolarityOp, StationMode, StateOp, StatusKind, AntennaKind)


def _read_option(enum: type[_E], char: str, what: str) -> _E:
    try:
        return enum(char)
    except ValueError:
        raise _reject(f"{char!r} is not a {what}") from None


def _require_empty(body: str, what: str) -> None:
    if body:
        raise _reject(f"{what} takes no argument, got {body!r}")


# --------------------------------------------------------------------------- each command


def _write_antenna(c: Antenna) -> str:
    if c.station == 0 and c.kind is not AntennaKind.EXTRA:
        raise EncodeError("station 0 takes only extra relays (kind X)")
    if len(c.relays) > MAX_RELAYS:
        raise RelayListTooLong(
            f"station {c.station} {c.kind.name} antenna {c.antenna} needs {len(c.relays)} relays;"
            f" one antenna command holds at most {MAX_RELAYS}"
        )
    return (
        _station(c.station, zero=True)
        + c.kind.value
        + _sixbit(c.antenna, "antenna")
        + _relay_chars(c.relays)
    )


def _relay_chars(relays: Iterable[int]) -> str:
    try:
        return encode_numbers(relays)
    except SixbitError as exc:
        raise EncodeError(f"relay out of range: {exc}") from None


def _read_antenna(body: str) -> Antenna:
    if len(body) < 3:
        raise _reject(f"an antenna command needs station, kind and antenna, got {body!r}")
    station = _read_station(body[0], zero=True)
    kind = _read_option(AntennaKind, body[1], "antenna kind (T, R, B, A or X)")
    if station == 0 and kind is not AntennaKind.EXTRA:
        raise _reject("station 0 takes only extra relays (kind X)")
    antenna = _read_sixbits(body[2], "antenna")[0]
    relays = _read_sixbits(body[3:], "relay")
    return Antenna(station, kind, antenna, relays)


def _write_conflict(c: ConflictTable) -> str:
    if c.op in (ConflictOp.NONE, ConflictOp.ALL):
        if c.pairs:
            raise EncodeError(f"conflict sub-command {c.op.value} takes no pairs")
        return str(c.op.value)
    return str(c.op.value) + _pairs(c.pairs, "antenna")


def _read_conflict(body: str) -> ConflictTable:
    if not body:
        raise _reject("the conflict table command needs a sub-command")
    op = _read_option(ConflictOp, body[0], "conflict sub-command (0, 1, C or c)")
    if op in (ConflictOp.NONE, ConflictOp.ALL):
        return ConflictTable(op)
    return ConflictTable(op, _read_pairs(body[1:], "antenna pairs"))


def _write_fast(c: FastTable) -> str:
    if c.op in (FastOp.ALL_SLOW, FastOp.ALL_FAST):
        if c.pairs:
            raise EncodeError(f"fast sub-command {c.op.value} takes no pairs")
        return str(c.op.value)
    return str(c.op.value) + _pairs(c.pairs, "antenna")


def _read_fast(body: str) -> FastTable:
    if not body:
        raise _reject("the fast table command needs a sub-command")
    op = _read_option(FastOp, body[0], "fast sub-command (0, 1, F or f)")
    if op in (FastOp.ALL_SLOW, FastOp.ALL_FAST):
        return FastTable(op)
    return FastTable(op, _read_pairs(body[1:], "antenna pairs"))


def _write_inhibit(c: Inhibit | Uninhibit) -> str:
    return _stations(c.stations)


def _read_inhibit(body: str) -> Inhibit:
    return Inhibit(_read_stations(body))


def _read_uninhibit(body: str) -> Uninhibit:
    return Uninhibit(_read_stations(body))


def _write_station_list(c: InhibitOthers | UseAlternate) -> str:
    return _station(c.station) + _stations(c.stations)


def _read_station_list(body: str, what: str) -> tuple[int, frozenset[int]]:
    if not body:
        raise _reject(f"{what} needs a station")
    station = _read_station(body[0])
    stations = _read_stations(body[1:])
    if station in stations:
        raise CommandRejected("T", f"station {station} cannot {what} itself")
    return station, stations


def _write_others(c: InhibitOthers) -> str:
    if c.station in c.stations:
        raise EncodeError(f"station {c.station} cannot inhibit itself")
    return _write_station_list(c)


def _read_others(body: str) -> InhibitOthers:
    return InhibitOthers(*_read_station_list(body, "inhibit"))


def _write_alternate(c: UseAlternate) -> str:
    if c.station in c.stations:
        raise EncodeError(f"station {c.station} cannot move itself to its alternate antenna")
    return _write_station_list(c)


def _read_alternate(body: str) -> UseAlternate:
    return UseAlternate(*_read_station_list(body, "switch to the alternate antenna"))


def _write_polarity(c: InhibitPolarity) -> str:
    if c.op in (PolarityOp.ALL_INHIBIT_LOW, PolarityOp.ALL_ENABLE_LOW):
        return str(c.op.value)
    if not c.stations:
        raise EncodeError(f"polarity sub-command {c.op.value} needs at least one station")
    return str(c.op.value) + _stations(c.stations)


def _read_polarity(body: str) -> InhibitPolarity:
    if not body:
        raise _reject("the inhibit polarity command needs a sub-command")
    op = _read_option(PolarityOp, body[0], "polarity sub-command (0, 1, E or I)")
    if op in (PolarityOp.ALL_INHIBIT_LOW, PolarityOp.ALL_ENABLE_LOW):
        return InhibitPolarity(op)
    stations = _read_stations(body[1:])
    if not stations:
        raise _reject(f"polarity sub-command {op.value} needs at least one station")
    return InhibitPolarity(op, stations)


def _write_inhibit_time(c: InhibitTime) -> str:
    return _ms(c.ms, 1, 9999, "an inhibit time")


def _read_inhibit_time(body: str) -> InhibitTime:
    return InhibitTime(_read_ms(body, 4, 1, 9999, "the inhibit time"))


def _write_interrupt_delay(c: InterruptDelay) -> str:
    return _ms(c.ms, 0, 99, "an interrupt delay")


def _read_interrupt_delay(body: str) -> InterruptDelay:
    return InterruptDelay(_read_ms(body, 2, 0, 99, "the interrupt delay"))


def _write_mode(c: Mode) -> str:
    return c.mode.value + _stations(c.stations)


def _read_mode(body: str) -> Mode:
    if not body:
        raise _reject("the mode command needs W or I")
    return Mode(_read_option(StationMode, body[0], "mode (W or I)"), _read_stations(body[1:]))


def _write_nothing(c: Ping | RelayStatusRequest) -> str:
    return ""


def _read_ping(body: str) -> Ping:
    _require_empty(body, "ping")
    return Ping()


def _read_relay_status(body: str) -> RelayStatusRequest:
    _require_empty(body, "relay status")
    return RelayStatusRequest()


def _write_receive_delay(c: ReceiveDelay) -> str:
    return _station(c.station) + _ms(c.ms, 0, 9999, "a receive delay")


def _read_receive_delay(body: str) -> ReceiveDelay:
    if not body:
        raise _reject("the receive delay command needs a station and a time")
    return ReceiveDelay(_read_station(body[0]), _read_ms(body[1:], 4, 0, 9999, "the receive delay"))


def _write_state(c: SetState) -> str:
    if not c.ops:
        raise EncodeError("a set state command needs at least one sub-command")
    return "".join(op.value for op in c.ops)


def _read_state(body: str) -> SetState:
    if not body:
        raise _reject("the set state command needs at least one sub-command")
    return SetState(tuple(_read_option(StateOp, ch, "set state sub-command") for ch in body))


def _write_status(c: StatusRequest) -> str:
    return c.kind.value


def _read_status(body: str) -> StatusRequest:
    if len(body) != 1:
        raise _reject(f"the status command takes B or I, got {body!r}")
    return StatusRequest(_read_option(StatusKind, body, "status sub-command (B or I)"))


def _write_system(c: SystemTable) -> str:
    if c.clear:
        if c.pairs:
            raise EncodeError("system sub-command 0 takes no pairs")
        return "0"
    return "S" + _pairs(c.pairs, "antenna or system")


def _read_system(body: str) -> SystemTable:
    # The manual's format is "_S{pairs};" but its own example writes
    # "_112131;" with no sub-command: both are read (docs/switch.md).
    if not body:
        raise _reject("the system command needs a sub-command")
    if body[0] == "0":
        return SystemTable(clear=True)
    if body[0] == "S" and len(body) % 2 == 1:
        return SystemTable(False, _read_pairs(body[1:], "antenna and system pairs"))
    return SystemTable(False, _read_pairs(body, "antenna and system pairs"))


def _write_unit_id(c: UnitId) -> str:
    if c.unit is None:
        return ""
    if not 0 <= c.unit <= 99:
        raise EncodeError(f"unit identifier {c.unit} is outside 0-99")
    return str(c.unit)


def _read_unit_id(body: str) -> UnitId:
    if not body:
        return UnitId()
    if len(body) > 2 or not body.isdigit() or not body.isascii():
        raise _reject(f"a unit identifier is one or two digits, not {body!r}")
    return UnitId(int(body))


def _write_vendor(c: VendorExtension) -> str:
    return c.text


def _read_vendor(body: str) -> VendorExtension:
    return VendorExtension(body)


# --------------------------------------------------------------------------- the table


@dataclass(frozen=True, slots=True)
class CommandRule:
    """One row of the command table."""

    char: str
    name: str
    type: type
    read: Callable[[str], Command]
    write: Callable[[Any], str]


COMMANDS: dict[str, CommandRule] = {
    rule.char: rule
    for rule in (
        CommandRule("!", "Antenna", Antenna, _read_antenna, _write_antenna),
        CommandRule("%", "Conflict table", ConflictTable, _read_conflict, _write_conflict),
        CommandRule("&", "Fast table", FastTable, _read_fast, _write_fast),
        CommandRule("(", "Inhibit", Inhibit, _read_inhibit, _write_inhibit),
        CommandRule("~", "Inhibit other station", InhibitOthers, _read_others, _write_others),
        CommandRule("^", "Inhibit polarity", InhibitPolarity, _read_polarity, _write_polarity),
        CommandRule("[", "Inhibit time", InhibitTime, _read_inhibit_time, _write_inhibit_time),
        CommandRule(
            "]", "Interrupt mode delay", InterruptDelay, _read_interrupt_delay,
            _write_interrupt_delay,
        ),
        CommandRule("/", "Mode", Mode, _read_mode, _write_mode),
        CommandRule("'", "Ping", Ping, _read_ping, _write_nothing),
        CommandRule("\\", "Receive delay", ReceiveDelay, _read_receive_delay, _write_receive_delay),
        CommandRule("|", "Relay status", RelayStatusRequest, _read_relay_status, _write_nothing),
        CommandRule("*", "Set state", SetState, _read_state, _write_state),
        CommandRule('"', "Status", StatusRequest, _read_status, _write_status),
        CommandRule("_", "System", SystemTable, _read_system, _write_system),
        CommandRule(")", "Uninhibit", Uninhibit, _read_uninhibit, _write_inhibit),
        CommandRule(":", "Unit ID", UnitId, _read_unit_id, _write_unit_id),
        CommandRule("@", "Use alternate antenna", UseAlternate, _read_alternate, _write_alternate),
        CommandRule("#", "Vendor extension", VendorExtension, _read_vendor, _write_vendor),
    )
}
"""Command character -> its rule."""

_BY_TYPE: dict[type, CommandRule] = {rule.type: rule for rule in COMMANDS.values()}


def command_name(command: Command) -> str:
    """The manual's name of a command ("Antenna", "Conflict table", ...)."""
    return _BY_TYPE[type(command)].name


def encode(command: Command) -> bytes:
    """The bytes of one command; :class:`CommandTooLong` if over 40 bytes."""
    rule = _BY_TYPE[type(command)]
    text = rule.char + rule.write(command) + ";"
    if len(text) > MAX_COMMAND:
        raise CommandTooLong(
            f"{rule.name} command {text[:20]!r}... is {len(text)} bytes; at most {MAX_COMMAND}"
        )
    try:
        return text.encode("ascii")
    except UnicodeEncodeError:
        raise EncodeError(f"{rule.name} command {text!r} is not plain ASCII") from None


def split(command: Command) -> tuple[Command, ...]:
    """``command`` as commands of at most 40 bytes each: table loads with many
    pairs become several loads of at most 18 pairs; others stay as they are."""
    if isinstance(command, ConflictTable | FastTable | SystemTable) and command.pairs:
        pairs = command.pairs
        if len(pairs) > MAX_PAIRS:
            return tuple(
                replace(command, pairs=pairs[i : i + MAX_PAIRS])
                for i in range(0, len(pairs), MAX_PAIRS)
            )
    return (command,)


def encode_all(commands: Iterable[Command]) -> bytes:
    """Several commands, each split as needed, as one run of bytes."""
    return b"".join(encode(part) for command in commands for part in split(command))


def parse_command(text: str) -> Command:
    """The command in ``text`` (command character and body, without ``;``).

    Raises :class:`CommandRejected` with the letter the box would answer.
    """
    if not text:
        raise CommandRejected("U", "an empty command")
    rule = COMMANDS.get(text[0])
    if rule is None:
        raise CommandRejected("U", f"{text[0]!r} is not a command")
    return rule.read(text[1:])


__all__ = [
    "COMMANDS",
    "MAX_COMMAND",
    "MAX_PAIRS",
    "MAX_RELAYS",
    "CommandRule",
    "command_name",
    "encode",
    "encode_all",
    "parse_command",
    "split",
]
