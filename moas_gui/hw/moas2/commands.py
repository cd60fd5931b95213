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
from typing import Any

from .command_syntax import (
    MAX_COMMAND,
    MAX_PAIRS,
    MAX_RELAYS,
    read_alternate,
    read_antenna,
    read_conflict,
    read_fast,
    read_inhibit,
    read_inhibit_time,
    read_interrupt_delay,
    read_mode,
    read_others,
    read_ping,
    read_polarity,
    read_receive_delay,
    read_relay_status,
    read_state,
    read_status,
    read_system,
    read_uninhibit,
    read_unit_id,
    read_vendor,
    write_alternate,
    write_antenna,
    write_conflict,
    write_fast,
    write_inhibit,
    write_inhibit_time,
    write_interrupt_delay,
    write_mode,
    write_nothing,
    write_others,
    write_polarity,
    write_receive_delay,
    write_state,
    write_status,
    write_system,
    write_unit_id,
    write_vendor,
)
from .errors import CommandRejected, CommandTooLong, EncodeError
from .messages import (
    Command,
    ConflictTable,
    FastTable,
    Inhibit,
    InhibitOthers,
    InhibitPolarity,
    InhibitTime,
    InterruptDelay,
    Mode,
    Ping,
    ReceiveDelay,
    RelayStatusRequest,
    SetAntenna,
    SetState,
    StatusRequest,
    SystemTable,
    Uninhibit,
    UnitId,
    UseAlternate,
    VendorExtension,
)

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
        CommandRule("!", "Antenna", SetAntenna, read_antenna, write_antenna),
        CommandRule("%", "Conflict table", ConflictTable, read_conflict, write_conflict),
        CommandRule("&", "Fast table", FastTable, read_fast, write_fast),
        CommandRule("(", "Inhibit", Inhibit, read_inhibit, write_inhibit),
        CommandRule("~", "Inhibit other station", InhibitOthers, read_others, write_others),
        CommandRule("^", "Inhibit polarity", InhibitPolarity, read_polarity, write_polarity),
        CommandRule("[", "Inhibit time", InhibitTime, read_inhibit_time, write_inhibit_time),
        CommandRule(
            "]", "Interrupt mode delay", InterruptDelay, read_interrupt_delay,
            write_interrupt_delay,
        ),
        CommandRule("/", "Mode", Mode, read_mode, write_mode),
        CommandRule("'", "Ping", Ping, read_ping, write_nothing),
        CommandRule("\\", "Receive delay", ReceiveDelay, read_receive_delay, write_receive_delay),
        CommandRule("|", "Relay status", RelayStatusRequest, read_relay_status, write_nothing),
        CommandRule("*", "Set state", SetState, read_state, write_state),
        CommandRule('"', "Status", StatusRequest, read_status, write_status),
        CommandRule("_", "System", SystemTable, read_system, write_system),
        CommandRule(")", "Uninhibit", Uninhibit, read_uninhibit, write_inhibit),
        CommandRule(":", "Unit ID", UnitId, read_unit_id, write_unit_id),
        CommandRule("@", "Use alternate antenna", UseAlternate, read_alternate, write_alternate),
        CommandRule("#", "Vendor extension", VendorExtension, read_vendor, write_vendor),
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
