"""What to send a switch to take it from one :class:`SwitchState` to another.

Pure: states in, commands out.  The switch link calls :func:`initialise`
when it (re)connects and :func:`difference` for every later state.

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
    Antenna,
    AntennaKind,
    BoxStatus,
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
    PolarityStatus,
    Pong,
    ReceiveDelay,
    RelayStatus,
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
            self._systems(dict(old.systems), dict(new.systems))

    def _pair_table(
        self,
        old: frozenset[tuple[int, int]],
        new: frozenset[tuple[int, int]],
        on: _PairCommand,
        off: _PairCommand,
        empty: Command,
        full: Command,
    ) -> None:
        def some(make: _PairCommand, pairs: Iterable[tuple[int, int]]) -> list[Command]:
            chosen = tuple(sorted(pairs))
            return [make(chosen)] if chosen else []

        options = [
            some(on, new - old) + some(off, old - new),
            [empty, *some(on, new)],
        ]
        if len(new) > ALL_PAIRS // 2:
            options.append([full, *some(off, _EVERY_PAIR - new)])
        self.commands += min(options, key=lambda cmds: len(encode_all(cmds)))

    def _systems(self, old: Mapping[int, int], new: Mapping[int, int]) -> None:
        def valid(table: Mapping[int, int]) -> dict[int, int]:
            good = {}
            for antenna, system in table.items():
                if 0 <= antenna <= 63 and 0 <= system <= 63:
                    good[antenna] = system
                else:
                    self.problems.append(f"system pair ({antenna}, {system}) is outside 0-63")
            return good

        old, new = valid(old), valid(new)
        changed = tuple(
            (a, new.get(a, 0)) for a in sorted(set(old) | set(new)) if old.get(a, 0) != new.get(a, 0)
        )
        incremental: list[Command] = [SystemTable(False, changed)] if changed else []
        reload: list[Command] = [SystemTable(True)]
        loaded = tuple((a, s) for a, s in sorted(new.items()) if s)
        if loaded:
            reload.append(SystemTable(False, loaded))
        self.commands += min(incremental, reload, key=lambda cmds: len(encode_all(cmds)))

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
            commands.append(Antenna(0, AntennaKind.EXTRA, 0, relays))
        station_commands = sum(1 for c in commands if isinstance(c, Antenna) and c.station)
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
            out.append(Antenna(n, AntennaKind.BOTH, self._slot(new.tx, what), relays))
        else:
            if tx_changed:
                relays = self._relays(new.tx_relays, f"{what} TX antenna {new.tx}")
                out.append(Antenna(n, AntennaKind.TX, self._slot(new.tx, what), relays))
            if rx_changed:
                relays = self._relays(new.rx_relays, f"{what} RX antenna {new.rx}")
                out.append(Antenna(n, AntennaKind.RX, self._slot(new.rx, what), relays))
        if (old.alt, old.alt_relays) != (new.alt, new.alt_relays):
            relays = self._relays(new.alt_relays, f"{what} alternate antenna {new.alt}")
            out.append(Antenna(n, AntennaKind.ALT, self._slot(new.alt, what), relays))
        if old.extra != new.extra:
            relays = self._relays(new.extra, f"{what} extra relays")
            out.append(Antenna(n, AntennaKind.EXTRA, 0, relays))
        return out

    def _slot(self, slot: int, what: str) -> int:
        if 0 <= slot <= 63:
            return slot
        self.problems.append(f"{what}: antenna slot {slot} is outside 0-63; using 63 (none)")
        return 63


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
    """The fewest commands that take a box holding ``old`` to ``new``."""
    if old == new:
        return CommandPlan()
    if old.active and not new.active:
        return initialise(new, events=events)
    p = _Planner()
    p.tables(old, new)
    p.settings(old, new)
    p.interlocks(old, new)
    p.antennas(old, new, bracket=old.active and new.active)
    if new.active and not old.active:
        p.commands.append(SetState((StateOp.ACTIVATE,)))
    return p.plan()


def differs(
    held: SwitchState,
    pong: Pong | None,
    box: BoxStatus | None,
    polarity: PolarityStatus | None,
    relays: RelayStatus | None,
) -> str:
    """Why a box that answered these status requests does not hold ``held`` ("" when,
    as far as a box can tell, it does).

    The box reports whether it is active, every station's current antennas, the
    inhibit polarity and the closed relays; it cannot report its tables, timings,
    interlocks or the relays behind each antenna.  So: active, the same antennas,
    the same polarity, and closed relays that ``held`` explains (the always-on
    relays closed, nothing closed that no antenna of ``held`` selects).  A box
    reset or powered off since is inactive, and one driven by anyone else almost
    surely shows other antennas or relays.
    """
    if pong is None or box is None or polarity is None or relays is None:
        return "it did not answer every status request"
    if not held.active:
        return "the saved state is stopped"
    if min(len(box.tx), len(box.rx), len(box.alt)) < len(STATIONS):
        return "its box status is incomplete"
    if not pong.active:
        return "it is inactive (reset or powered off since)"
    for n, station in zip(STATIONS, held.stations, strict=True):
        at = n - 1
        if (box.tx[at], box.rx[at], box.alt[at]) != (station.tx, station.rx, station.alt):
            return f"station {n} has other antennas"
    if polarity.enable_low != held.enable_low:
        return "its inhibit polarity differs"
    possible = set(held.station0)
    for station in held.stations:
        possible |= station.tx_relays | station.rx_relays | station.alt_relays | station.extra
    if not relays.relays <= possible or not held.station0 <= relays.relays:
        return "its closed relays differ"
    return ""


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
    "CommandPlan",
    "count_bytes",
    "difference",
    "differs",
    "initialise",
    "stopped",
]
