"""How each MOAS II command is written and read: one ``write_x`` and one
``read_x`` per command, and the limits that keep every command within 40
bytes.  The table that ties them to command characters is
:data:`moas_gui.hw.moas2.commands.COMMANDS`; the rules are stated there."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

from .errors import CommandRejected, EncodeError, RelayListTooLong
from .messages import (
    AntennaKind,
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
    SetAntenna,
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


def read_station(char: str, *, zero: bool = False) -> int:
    low = "0" if zero else "1"
    if len(char) != 1 or not low <= char <= "6":
        raise _reject(f"{char!r} is not a station")
    return int(char)


def read_stations(text: str) -> frozenset[int]:
    return frozenset(read_station(c) for c in text)


def read_sixbits(text: str, what: str) -> tuple[int, ...]:
    try:
        return decode_numbers(text)
    except SixbitError as exc:
        raise _reject(f"bad {what}: {exc}") from None


def read_pairs(text: str, what: str) -> tuple[tuple[int, int], ...]:
    if len(text) % 2:
        raise _reject(f"{what} come in pairs; {len(text)} characters is odd")
    numbers = read_sixbits(text, what)
    return tuple(zip(numbers[::2], numbers[1::2], strict=True))


def read_ms(text: str, digits: int, low: int, high: int, what: str) -> int:
    if not 1 <= len(text) <= digits or not text.isdigit() or not text.isascii():
        raise _reject(f"{what} must be 1-{digits} digits, not {text!r}")
    value = int(text)
    if not low <= value <= high:
        raise _reject(f"{what} of {value} ms is outside {low}-{high} ms")
    return value


_E = TypeVar("_E", ConflictOp, FastOp, PolarityOp, StationMode, StateOp, StatusKind, AntennaKind)


def read_option(enum: type[_E], char: str, what: str) -> _E:
    try:
        return enum(char)
    except ValueError:
        raise _reject(f"{char!r} is not a {what}") from None


def _require_empty(body: str, what: str) -> None:
    if body:
        raise _reject(f"{what} takes no argument, got {body!r}")


# --------------------------------------------------------------------------- each command


def write_antenna(c: SetAntenna) -> str:
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


def read_antenna(body: str) -> SetAntenna:
    if len(body) < 3:
        raise _reject(f"an antenna command needs station, kind and antenna, got {body!r}")
    station = read_station(body[0], zero=True)
    kind = read_option(AntennaKind, body[1], "antenna kind (T, R, B, A or X)")
    if station == 0 and kind is not AntennaKind.EXTRA:
        raise _reject("station 0 takes only extra relays (kind X)")
    antenna = read_sixbits(body[2], "antenna")[0]
    relays = read_sixbits(body[3:], "relay")
    return SetAntenna(station, kind, antenna, relays)


def write_conflict(c: ConflictTable) -> str:
    if c.op in (ConflictOp.NONE, ConflictOp.ALL):
        if c.pairs:
            raise EncodeError(f"conflict sub-command {c.op.value} takes no pairs")
        return str(c.op.value)
    return str(c.op.value) + _pairs(c.pairs, "antenna")


def read_conflict(body: str) -> ConflictTable:
    if not body:
        raise _reject("the conflict table command needs a sub-command")
    op = read_option(ConflictOp, body[0], "conflict sub-command (0, 1, C or c)")
    if op in (ConflictOp.NONE, ConflictOp.ALL):
        return ConflictTable(op)
    return ConflictTable(op, read_pairs(body[1:], "antenna pairs"))


def write_fast(c: FastTable) -> str:
    if c.op in (FastOp.ALL_SLOW, FastOp.ALL_FAST):
        if c.pairs:
            raise EncodeError(f"fast sub-command {c.op.value} takes no pairs")
        return str(c.op.value)
    return str(c.op.value) + _pairs(c.pairs, "antenna")


def read_fast(body: str) -> FastTable:
    if not body:
        raise _reject("the fast table command needs a sub-command")
    op = read_option(FastOp, body[0], "fast sub-command (0, 1, F or f)")
    if op in (FastOp.ALL_SLOW, FastOp.ALL_FAST):
        return FastTable(op)
    return FastTable(op, read_pairs(body[1:], "antenna pairs"))


def write_inhibit(c: Inhibit | Uninhibit) -> str:
    return _stations(c.stations)


def read_inhibit(body: str) -> Inhibit:
    return Inhibit(read_stations(body))


def read_uninhibit(body: str) -> Uninhibit:
    return Uninhibit(read_stations(body))


def write_station_list(c: InhibitOthers | UseAlternate) -> str:
    return _station(c.station) + _stations(c.stations)


def read_station_list(body: str, what: str) -> tuple[int, frozenset[int]]:
    if not body:
        raise _reject(f"{what} needs a station")
    station = read_station(body[0])
    stations = read_stations(body[1:])
    if station in stations:
        raise CommandRejected("T", f"station {station} cannot {what} itself")
    return station, stations


def write_others(c: InhibitOthers) -> str:
    if c.station in c.stations:
        raise EncodeError(f"station {c.station} cannot inhibit itself")
    return write_station_list(c)


def read_others(body: str) -> InhibitOthers:
    return InhibitOthers(*read_station_list(body, "inhibit"))


def write_alternate(c: UseAlternate) -> str:
    if c.station in c.stations:
        raise EncodeError(f"station {c.station} cannot move itself to its alternate antenna")
    return write_station_list(c)


def read_alternate(body: str) -> UseAlternate:
    return UseAlternate(*read_station_list(body, "switch to the alternate antenna"))


def write_polarity(c: InhibitPolarity) -> str:
    if c.op in (PolarityOp.ALL_INHIBIT_LOW, PolarityOp.ALL_ENABLE_LOW):
        return str(c.op.value)
    if not c.stations:
        raise EncodeError(f"polarity sub-command {c.op.value} needs at least one station")
    return str(c.op.value) + _stations(c.stations)


def read_polarity(body: str) -> InhibitPolarity:
    if not body:
        raise _reject("the inhibit polarity command needs a sub-command")
    op = read_option(PolarityOp, body[0], "polarity sub-command (0, 1, E or I)")
    if op in (PolarityOp.ALL_INHIBIT_LOW, PolarityOp.ALL_ENABLE_LOW):
        return InhibitPolarity(op)
    stations = read_stations(body[1:])
    if not stations:
        raise _reject(f"polarity sub-command {op.value} needs at least one station")
    return InhibitPolarity(op, stations)


def write_inhibit_time(c: InhibitTime) -> str:
    return _ms(c.ms, 1, 9999, "an inhibit time")


def read_inhibit_time(body: str) -> InhibitTime:
    return InhibitTime(read_ms(body, 4, 1, 9999, "the inhibit time"))


def write_interrupt_delay(c: InterruptDelay) -> str:
    return _ms(c.ms, 0, 99, "an interrupt delay")


def read_interrupt_delay(body: str) -> InterruptDelay:
    return InterruptDelay(read_ms(body, 2, 0, 99, "the interrupt delay"))


def write_mode(c: Mode) -> str:
    return c.mode.value + _stations(c.stations)


def read_mode(body: str) -> Mode:
    if not body:
        raise _reject("the mode command needs W or I")
    return Mode(read_option(StationMode, body[0], "mode (W or I)"), read_stations(body[1:]))


def write_nothing(c: Ping | RelayStatusRequest) -> str:
    return ""


def read_ping(body: str) -> Ping:
    _require_empty(body, "ping")
    return Ping()


def read_relay_status(body: str) -> RelayStatusRequest:
    _require_empty(body, "relay status")
    return RelayStatusRequest()


def write_receive_delay(c: ReceiveDelay) -> str:
    return _station(c.station) + _ms(c.ms, 0, 9999, "a receive delay")


def read_receive_delay(body: str) -> ReceiveDelay:
    if not body:
        raise _reject("the receive delay command needs a station and a time")
    return ReceiveDelay(read_station(body[0]), read_ms(body[1:], 4, 0, 9999, "the receive delay"))


def write_state(c: SetState) -> str:
    if not c.ops:
        raise EncodeError("a set state command needs at least one sub-command")
    return "".join(op.value for op in c.ops)


def read_state(body: str) -> SetState:
    if not body:
        raise _reject("the set state command needs at least one sub-command")
    return SetState(tuple(read_option(StateOp, ch, "set state sub-command") for ch in body))


def write_status(c: StatusRequest) -> str:
    return c.kind.value


def read_status(body: str) -> StatusRequest:
    if len(body) != 1:
        raise _reject(f"the status command takes B or I, got {body!r}")
    return StatusRequest(read_option(StatusKind, body, "status sub-command (B or I)"))


def write_system(c: SystemTable) -> str:
    if c.clear:
        if c.pairs:
            raise EncodeError("system sub-command 0 takes no pairs")
        return "0"
    return "S" + _pairs(c.pairs, "antenna or system")


def read_system(body: str) -> SystemTable:
    # The manual's format is "_S{pairs};" but its own example writes
    # "_112131;" with no sub-command: both are read (docs/switch.md).
    if not body:
        raise _reject("the system command needs a sub-command")
    if body[0] == "0":
        return SystemTable(clear=True)
    if body[0] == "S" and len(body) % 2 == 1:
        return SystemTable(False, read_pairs(body[1:], "antenna and system pairs"))
    return SystemTable(False, read_pairs(body, "antenna and system pairs"))


def write_unit_id(c: UnitId) -> str:
    if c.unit is None:
        return ""
    if not 0 <= c.unit <= 99:
        raise EncodeError(f"unit identifier {c.unit} is outside 0-99")
    return str(c.unit)


def read_unit_id(body: str) -> UnitId:
    if not body:
        return UnitId()
    if len(body) > 2 or not body.isdigit() or not body.isascii():
        raise _reject(f"a unit identifier is one or two digits, not {body!r}")
    return UnitId(int(body))


def write_vendor(c: VendorExtension) -> str:
    return c.text


def read_vendor(body: str) -> VendorExtension:
    return VendorExtension(body)


__all__ = [
    "MAX_COMMAND",
    "MAX_PAIRS",
    "MAX_RELAYS",
    "read_alternate",
    "read_antenna",
    "read_conflict",
    "read_fast",
    "read_inhibit",
    "read_inhibit_time",
    "read_interrupt_delay",
    "read_mode",
    "read_ms",
    "read_option",
    "read_others",
    "read_pairs",
    "read_ping",
    "read_polarity",
    "read_receive_delay",
    "read_relay_status",
    "read_sixbits",
    "read_state",
    "read_station",
    "read_station_list",
    "read_stations",
    "read_status",
    "read_system",
    "read_uninhibit",
    "read_unit_id",
    "read_vendor",
    "write_alternate",
    "write_antenna",
    "write_conflict",
    "write_fast",
    "write_inhibit",
    "write_inhibit_time",
    "write_interrupt_delay",
    "write_mode",
    "write_nothing",
    "write_others",
    "write_polarity",
    "write_receive_delay",
    "write_state",
    "write_station_list",
    "write_status",
    "write_system",
    "write_unit_id",
    "write_vendor",
]
