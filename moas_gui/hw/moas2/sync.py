"""What to send a switch to take it from one :class:`SwitchState` to another.

Pure: states in, commands out, through one planner (``_Planner``):
:func:`difference` (what changed), :func:`initialise` (a reset and a full load) and
:func:`absolute` (the whole state as values, no reset) build their commands with the
same methods, so a value the box cannot take is reported the same way by each.
Which of them a session sends is :func:`.plan.choose_plan`'s choice; what a box
found on (re)connection is taken to hold is :mod:`.resync`'s.

The rules, in plain words:

* Only what changed is sent.  The tables are never sent again unless they
  changed, and then as the shorter of "change these pairs" and "clear (or
  fill) the table and load it".
* An antenna command goes out for a station only when that antenna or its
  relays changed; transmit and receive go as one ``B`` command when they are
  the same antenna with the same relays.
* When two or more antenna commands go out while the box is active, they are
  put between "resolver off" (``*r``) and "resolver on" (``*R``), so the box
  carries them out together (two stations swapping antennas, a shared
  system changing for everyone at once).
* Going from active to stopped is a reset (``*0``) and a full load without
  activation (the box has no "deactivate"); going back is ``*1``.
* A value the box cannot take is not sent as it is: the problem is reported
  in the plan and the nearest safe value is sent instead (a relay list over
  35 relays, or with relays outside 0-63, leaves that list with no relays:
  the station is disconnected rather than half connected).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace

from ...engine.switchstate import STATIONS, StationAntennas, SwitchState
from .commands import MAX_RELAYS, encode_all
from .messages import (
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
    PolarityOp,
    ReceiveDelay,
    SetAntenna,
    SetState,
    StateOp,
    StationMode,
    SystemTable,
    Uninhibit,
    UseAlternate,
)

POWER_ON = SwitchState(active=False)
"""What a box holds after power-on or a reset, as a state."""

ALL_PAIRS = 64 * 65 // 2
"""Pairs in a triangular 64x64 table (each antenna with itself included)."""

DEFAULT_EVENTS: tuple[StateOp, ...] = (StateOp.ANTENNA_EVENTS_ON, StateOp.TR_EVENTS_ON)
"""Events the link asks for: antenna changes (to log conflicts) and T/R."""

_PairCommand = Callable[[tuple[tuple[int, int], ...]], Command]

_EVERY_PAIR = frozenset((a, b) for a in range(64) for b in range(a, 64))


@dataclass(frozen=True, slots=True)
class CommandPlan:
    """Commands to send, and what could not be sent as asked."""

    commands: tuple[Command, ...] = ()
    problems: tuple[str, ...] = ()

    def encode(self) -> bytes:
        """The bytes on the wire (table loads split to 40-byte commands)."""
        return encode_all(self.commands)


class _Planner:
    def __init__(self) -> None:
        self.commands: list[Command] = []
        self.problems: list[str] = []

    def plan(self) -> CommandPlan:
        return CommandPlan(tuple(self.commands), tuple(self.problems))

    # ---------------------------------------------------------------- values

    def _relays(self, relays: Iterable[int], what: str) -> tuple[int, ...]:
        chosen = tuple(sorted(set(relays)))
        bad = [r for r in chosen if not 0 <= r <= 63]
        if bad:
            self.problems.append(f"{what}: relays {bad} are outside 0-63; sending no relays")
            return ()
        if len(chosen) > MAX_RELAYS:
            self.problems.append(
                f"{what}: {len(chosen)} relays, but one antenna command holds at most "
                f"{MAX_RELAYS}; sending no relays (the station stays disconnected)"
            )
            return ()
        return chosen

    def _pairs(self, pairs: Iterable[tuple[int, int]], what: str) -> frozenset[tuple[int, int]]:
        good = set()
        for a, b in pairs:
            if 0 <= a <= 63 and 0 <= b <= 63:
                good.add((min(a, b), max(a, b)))
            else:
                self.problems.append(f"{what} pair ({a}, {b}) is outside 0-63; left out")
        return frozenset(good)

    def _ms(self, value: int, low: int, high: int, what: str) -> int:
        if low <= value <= high:
            return value
        fixed = min(max(value, low), high)
        self.problems.append(f"{what} of {value} ms is outside {low}-{high} ms; sending {fixed}")
        return fixed

    def _stations(self, stations: Iterable[int], what: str) -> frozenset[int]:
        chosen = frozenset(stations)
        bad = sorted(s for s in chosen if s not in STATIONS)
        if bad:
            self.problems.append(f"{what}: stations {bad} are not 1-6; left out")
        return chosen - set(bad)

    # ---------------------------------------------------------------- tables

    def tables(self, old: SwitchState, new: SwitchState) -> None:
        if old.conflicts is not new.conflicts and old.conflicts != new.conflicts:
            self._pair_table(
                self._pairs(old.conflicts, "conflict"), self._pairs(new.conflicts, "conflict"),
                lambda pairs: ConflictTable(ConflictOp.SET, pairs),
                lambda pairs: ConflictTable(ConflictOp.CLEAR, pairs),
                ConflictTable(ConflictOp.NONE), ConflictTable(ConflictOp.ALL),
            )
        if old.fast is not new.fast and old.fast != new.fast:
            self._pair_table(
                self._pairs(old.fast, "fast"), self._pairs(new.fast, "fast"),
                lambda pairs: FastTable(FastOp.FAST, pairs),
                lambda pairs: FastTable(FastOp.SLOW, pairs),
                FastTable(FastOp.ALL_SLOW), FastTable(FastOp.ALL_FAST),
            )
        if old.systems != new.systems:
            self._systems(old.systems, new.systems)

    def _pair_table(
        self,
        old: frozenset[tuple[int, int]],
        new: frozenset[tuple[int, int]],
        on: _PairCommand,
        off: _PairCommand,
        empty: Command,
        full: Command,
    ) -> None:
        options = [
            _some(on, new - old) + _some(off, old - new),
            _reload(empty, on, new),
        ]
        if len(new) > ALL_PAIRS // 2:
            options.append([full, *_some(off, _EVERY_PAIR - new)])
        self.commands += min(options, key=lambda cmds: len(encode_all(cmds)))

    def _system_pairs(self, table: Iterable[tuple[int, int]]) -> dict[int, int]:
        """The system table's (antenna, system) pairs the box can take; each other pair
        is reported as a problem and left out."""
        good = {}
        for antenna, system in table:
            if 0 <= antenna <= 63 and 0 <= system <= 63:
                good[antenna] = system
            else:
                self.problems.append(f"system pair ({antenna}, {system}) is outside 0-63")
        return good

    def _systems(self, old_pairs: Iterable[tuple[int, int]],
                 new_pairs: Iterable[tuple[int, int]]) -> None:
        old, new = self._system_pairs(old_pairs), self._system_pairs(new_pairs)
        changed = tuple(
            (a, new.get(a, 0)) for a in sorted(set(old) | set(new)) if old.get(a, 0) != new.get(a, 0)
        )
        incremental: list[Command] = [SystemTable(False, changed)] if changed else []
        self.commands += min(incremental, _system_reload(new),
                             key=lambda cmds: len(encode_all(cmds)))

    def load_tables(self, state: SwitchState) -> None:
        """Every table cleared and loaded with ``state``'s, whatever the box held."""
        self.commands += _reload(ConflictTable(ConflictOp.NONE),
                                 lambda pairs: ConflictTable(ConflictOp.SET, pairs),
                                 self._pairs(state.conflicts, "conflict"))
        self.commands += _reload(FastTable(FastOp.ALL_SLOW),
                                 lambda pairs: FastTable(FastOp.FAST, pairs),
                                 self._pairs(state.fast, "fast"))
        self.commands += _system_reload(self._system_pairs(state.systems))

    # ---------------------------------------------------------------- settings

    def settings(self, old: SwitchState, new: SwitchState) -> None:
        low_old = self._stations(old.enable_low, "polarity")
        low_new = self._stations(new.enable_low, "polarity")
        if low_new - low_old:
            self.commands.append(InhibitPolarity(PolarityOp.ENABLE_LOW, low_new - low_old))
        if low_old - low_new:
            self.commands.append(InhibitPolarity(PolarityOp.INHIBIT_LOW, low_old - low_new))
        int_old = self._stations(old.interrupt, "interrupt mode")
        int_new = self._stations(new.interrupt, "interrupt mode")
        if int_new - int_old:
            self.commands.append(Mode(StationMode.INTERRUPT, int_new - int_old))
        if int_old - int_new:
            self.commands.append(Mode(StationMode.WAIT, int_old - int_new))
        if old.inhibit_time != new.inhibit_time:
            self.commands.append(InhibitTime(self._ms(new.inhibit_time, 1, 9999, "inhibit time")))
        if old.interrupt_delay != new.interrupt_delay:
            self.commands.append(
                InterruptDelay(self._ms(new.interrupt_delay, 0, 99, "interrupt delay"))
            )
        for n in STATIONS:
            before, after = old.receive_delay[n - 1], new.receive_delay[n - 1]
            if before != after:
                ms = self._ms(after, 0, 9999, f"station {n} receive delay")
                self.commands.append(ReceiveDelay(n, ms))

    def load_settings(self, state: SwitchState) -> None:
        """Every setting sent as a value: polarity, wait or interrupt mode of every
        station, the inhibit time, the interrupt delay and every receive delay."""
        low = self._stations(state.enable_low, "polarity")
        self.commands.append(InhibitPolarity(PolarityOp.ALL_INHIBIT_LOW))
        if low:
            self.commands.append(InhibitPolarity(PolarityOp.ENABLE_LOW, low))
        interrupt = self._stations(state.interrupt, "interrupt mode")
        wait = frozenset(STATIONS) - interrupt
        if wait:
            self.commands.append(Mode(StationMode.WAIT, wait))
        if interrupt:
            self.commands.append(Mode(StationMode.INTERRUPT, interrupt))
        self.commands.append(InhibitTime(self._ms(state.inhibit_time, 1, 9999, "inhibit time")))
        self.commands.append(
            InterruptDelay(self._ms(state.interrupt_delay, 0, 99, "interrupt delay")))
        for n in STATIONS:
            ms = self._ms(state.receive_delay[n - 1], 0, 9999, f"station {n} receive delay")
            self.commands.append(ReceiveDelay(n, ms))

    def load_interlocks(self, state: SwitchState) -> None:
        """Every station's inhibit-others and alternate list, and who is inhibited,
        sent as values."""
        for n in STATIONS:
            others = self._stations(state.inhibit_others[n - 1] - {n}, f"station {n} inhibits")
            self.commands.append(InhibitOthers(n, others))
        for n in STATIONS:
            others = self._stations(state.use_alternate[n - 1] - {n}, f"station {n} alternates")
            self.commands.append(UseAlternate(n, others))
        inhibited = self._stations(state.inhibited, "inhibit")
        if inhibited:
            self.commands.append(Inhibit(inhibited))
        if frozenset(STATIONS) - inhibited:
            self.commands.append(Uninhibit(frozenset(STATIONS) - inhibited))

    def interlocks(self, old: SwitchState, new: SwitchState) -> None:
        for n in STATIONS:
            if old.inhibit_others[n - 1] != new.inhibit_others[n - 1]:
                others = self._stations(new.inhibit_others[n - 1] - {n}, f"station {n} inhibits")
                self.commands.append(InhibitOthers(n, others))
        for n in STATIONS:
            if old.use_alternate[n - 1] != new.use_alternate[n - 1]:
                others = self._stations(new.use_alternate[n - 1] - {n}, f"station {n} alternates")
                self.commands.append(UseAlternate(n, others))
        inh_old = self._stations(old.inhibited, "inhibit")
        inh_new = self._stations(new.inhibited, "inhibit")
        if inh_new - inh_old:
            self.commands.append(Inhibit(inh_new - inh_old))
        if inh_old - inh_new:
            self.commands.append(Uninhibit(inh_old - inh_new))

    # ---------------------------------------------------------------- antennas

    def antennas(self, old: SwitchState, new: SwitchState, bracket: bool) -> None:
        commands: list[Command] = []
        for n in STATIONS:
            commands += self._station(n, old.station(n), new.station(n))
        if old.station0 != new.station0:
            relays = self._relays(new.station0, "station 0 relays")
            commands.append(SetAntenna(0, AntennaKind.EXTRA, 0, relays))
        station_commands = sum(1 for c in commands if isinstance(c, SetAntenna) and c.station)
        if bracket and station_commands >= 2:
            commands = [
                SetState((StateOp.RESOLVER_OFF,)),
                *commands,
                SetState((StateOp.RESOLVER_ON,)),
            ]
        self.commands += commands

    def _station(self, n: int, old: StationAntennas, new: StationAntennas) -> list[Command]:
        out: list[Command] = []
        tx_changed = (old.tx, old.tx_relays) != (new.tx, new.tx_relays)
        rx_changed = (old.rx, old.rx_relays) != (new.rx, new.rx_relays)
        what = f"station {n}"
        if tx_changed and rx_changed and (new.tx, new.tx_relays) == (new.rx, new.rx_relays):
            relays = self._relays(new.tx_relays, f"{what} antenna {new.tx}")
            out.append(SetAntenna(n, AntennaKind.BOTH, self._slot(new.tx, what), relays))
        else:
            if tx_changed:
                relays = self._relays(new.tx_relays, f"{what} TX antenna {new.tx}")
                out.append(SetAntenna(n, AntennaKind.TX, self._slot(new.tx, what), relays))
            if rx_changed:
                relays = self._relays(new.rx_relays, f"{what} RX antenna {new.rx}")
                out.append(SetAntenna(n, AntennaKind.RX, self._slot(new.rx, what), relays))
        if (old.alt, old.alt_relays) != (new.alt, new.alt_relays):
            relays = self._relays(new.alt_relays, f"{what} alternate antenna {new.alt}")
            out.append(SetAntenna(n, AntennaKind.ALT, self._slot(new.alt, what), relays))
        if old.extra != new.extra:
            relays = self._relays(new.extra, f"{what} extra relays")
            out.append(SetAntenna(n, AntennaKind.EXTRA, 0, relays))
        return out

    def _slot(self, slot: int, what: str) -> int:
        if 0 <= slot <= 63:
            return slot
        self.problems.append(f"{what}: antenna slot {slot} is outside 0-63; using 63 (none)")
        return 63


def _some(make: _PairCommand, pairs: Iterable[tuple[int, int]]) -> list[Command]:
    chosen = tuple(sorted(pairs))
    return [make(chosen)] if chosen else []


def _reload(empty: Command, on: _PairCommand, pairs: Iterable[tuple[int, int]]) -> list[Command]:
    """A pair table cleared (``empty``) and loaded with ``pairs``."""
    return [empty, *_some(on, pairs)]


def _system_reload(table: Mapping[int, int]) -> list[Command]:
    """The system table cleared and loaded with ``table`` (system 0 is "none")."""
    loaded = tuple((a, s) for a, s in sorted(table.items()) if s)
    return [SystemTable(True), *([SystemTable(False, loaded)] if loaded else [])]


def initialise(state: SwitchState, *, events: tuple[StateOp, ...] = DEFAULT_EVENTS) -> CommandPlan:
    """Everything a box needs after it is found: reset, tables, settings,
    event enables, antennas, and activation when ``state.active``."""
    p = _Planner()
    p.commands.append(SetState((StateOp.RESET,)))
    p.tables(POWER_ON, state)
    p.settings(POWER_ON, state)
    p.interlocks(POWER_ON, state)
    if events:
        p.commands.append(SetState(events))
    p.antennas(POWER_ON, state, bracket=False)
    if state.active:
        p.commands.append(SetState((StateOp.ACTIVATE,)))
    return p.plan()


def difference(
    old: SwitchState, new: SwitchState, *, events: tuple[StateOp, ...] = DEFAULT_EVENTS
) -> CommandPlan:
    """The fewest commands that take a box holding ``old`` to ``new``, never a reset.

    From active to inactive there are none: the box has no "deactivate", only a reset
    stops it, and only :func:`.plan.choose_plan` chooses a reset (Stop Switches), so
    that case is a :class:`ValueError` here."""
    if old == new:
        return CommandPlan()
    if old.active and not new.active:
        raise ValueError("stopping an active box takes a reset, which only "
                         "plan.choose_plan chooses")
    p = _Planner()
    p.tables(old, new)
    p.settings(old, new)
    p.interlocks(old, new)
    p.antennas(old, new, bracket=old.active and new.active)
    if new.active and not old.active:
        p.commands.append(SetState((StateOp.ACTIVATE,)))
    return p.plan()


UNSURE = StationAntennas(
    tx=-1, tx_relays=frozenset({-1}), rx=-1, rx_relays=frozenset({-1}),
    alt=-1, alt_relays=frozenset({-1}), extra=frozenset({-1}),
)
"""A station whose antennas and relays on the box are not known for sure: every
antenna command of the wanted state differs from it, so :func:`difference` sends
them all (a box that holds them already takes them as no change)."""


def absolute(
    state: SwitchState, *, box_active: bool, events: tuple[StateOp, ...] = DEFAULT_EVENTS
) -> CommandPlan:
    """Everything that makes a box hold ``state``, whatever it holds now, without a
    reset: every table cleared and loaded, every setting, interlock and station sent
    as a value (not as a change), the events asked for, and activation when
    ``state.active`` and the box is not active yet.

    On an active box (``box_active``) the whole load goes between "resolver off" and
    "resolver on", so no antenna moves until the box has every table, and then every
    antenna change goes through the box's own hot-switch rules: a transmitting station
    in wait mode keeps its relays until it receives.  This is how the link loads a box
    on its own initiative (a restart, a reconnection, a box found reset): it never
    resets a box (``*0``), which would open every relay at once (docs/switch.md)."""
    p = _Planner()
    if box_active:
        p.commands.append(SetState((StateOp.RESOLVER_OFF,)))
    p.load_tables(state)
    p.load_settings(state)
    p.load_interlocks(state)
    if events:
        p.commands.append(SetState(events))
    unsure = SwitchState(stations=(UNSURE,) * len(STATIONS), station0=frozenset({-1}))
    p.antennas(unsure, state, bracket=False)
    if box_active:
        p.commands.append(SetState((StateOp.RESOLVER_ON,)))
    elif state.active:
        p.commands.append(SetState((StateOp.ACTIVATE,)))
    return p.plan()


def count_bytes(old: SwitchState, new: SwitchState) -> int:
    """Bytes written on the wire to go from ``old`` to ``new``."""
    return len(difference(old, new).encode())


def stopped(state: SwitchState) -> SwitchState:
    """``state`` with the switch stopped (all relays off)."""
    return state if not state.active else replace(state, active=False)


__all__ = [
    "ALL_PAIRS",
    "DEFAULT_EVENTS",
    "POWER_ON",
    "UNSURE",
    "CommandPlan",
    "absolute",
    "count_bytes",
    "difference",
    "initialise",
    "stopped",
]
