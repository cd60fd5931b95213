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

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from ...engine.switchstate import NO_ANTENNA, STATIONS, StationAntennas, SwitchState
from .commands import MAX_RELAYS, encode_all
from .messages import (
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
    SetAntenna,
    SetState,
    StateOp,
    StationMode,
    SystemTable,
    TRState,
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
    p.commands += [ConflictTable(ConflictOp.NONE)]
    conflicts = tuple(sorted(p._pairs(state.conflicts, "conflict")))
    if conflicts:
        p.commands.append(ConflictTable(ConflictOp.SET, conflicts))
    p.commands.append(FastTable(FastOp.ALL_SLOW))
    fast = tuple(sorted(p._pairs(state.fast, "fast")))
    if fast:
        p.commands.append(FastTable(FastOp.FAST, fast))
    p.commands.append(SystemTable(True))
    systems = tuple((a, n) for a, n in sorted(state.systems) if 0 <= a <= 63 and 1 <= n <= 63)
    if systems:
        p.commands.append(SystemTable(False, systems))
    low = p._stations(state.enable_low, "polarity")
    p.commands.append(InhibitPolarity(PolarityOp.ALL_INHIBIT_LOW))
    if low:
        p.commands.append(InhibitPolarity(PolarityOp.ENABLE_LOW, low))
    interrupt = p._stations(state.interrupt, "interrupt mode")
    wait = frozenset(STATIONS) - interrupt
    if wait:
        p.commands.append(Mode(StationMode.WAIT, wait))
    if interrupt:
        p.commands.append(Mode(StationMode.INTERRUPT, interrupt))
    p.commands.append(InhibitTime(p._ms(state.inhibit_time, 1, 9999, "inhibit time")))
    p.commands.append(
        InterruptDelay(p._ms(state.interrupt_delay, 0, 99, "interrupt delay")))
    for n in STATIONS:
        ms = p._ms(state.receive_delay[n - 1], 0, 9999, f"station {n} receive delay")
        p.commands.append(ReceiveDelay(n, ms))
    for n in STATIONS:
        others = p._stations(state.inhibit_others[n - 1] - {n}, f"station {n} inhibits")
        p.commands.append(InhibitOthers(n, others))
    for n in STATIONS:
        others = p._stations(state.use_alternate[n - 1] - {n}, f"station {n} alternates")
        p.commands.append(UseAlternate(n, others))
    inhibited = p._stations(state.inhibited, "inhibit")
    if inhibited:
        p.commands.append(Inhibit(inhibited))
    if frozenset(STATIONS) - inhibited:
        p.commands.append(Uninhibit(frozenset(STATIONS) - inhibited))
    if events:
        p.commands.append(SetState(events))
    unsure = SwitchState(stations=(UNSURE,) * len(STATIONS), station0=frozenset({-1}))
    p.antennas(unsure, state, bracket=False)
    if box_active:
        p.commands.append(SetState((StateOp.RESOLVER_ON,)))
    elif state.active:
        p.commands.append(SetState((StateOp.ACTIVATE,)))
    return p.plan()


Slots = tuple[int, int, int]
"""A station's transmit, receive and alternate antennas (switch slots)."""


@dataclass(frozen=True, slots=True)
class Survey:
    """What a box answered when the link asked what it holds."""

    pong: Pong
    box: BoxStatus
    polarity: PolarityStatus
    relays: RelayStatus

    def keyed(self) -> frozenset[int]:
        """Stations that transmit, or may: a station shown inhibited by command (``I``)
        does not say whether its key line is up, so it counts as transmitting."""
        return frozenset(
            n for n, letter in zip(STATIONS, self.box.tr, strict=False)
            if letter is not TRState.RECEIVE
        ) | frozenset(STATIONS[len(self.box.tr):])

    def slots(self, station: int) -> Slots:
        at = station - 1
        return (self.box.tx[at], self.box.rx[at], self.box.alt[at])


@dataclass(frozen=True, slots=True)
class Reconciliation:
    """How a box found on (re)connection is brought to the wanted state."""

    keyed: frozenset[int]
    """Stations transmitting (or that may be) when the box answered."""
    believed: SwitchState | None
    """What the box is taken to hold: the wanted state goes out as the difference from
    it; None when the box's contents are not known well enough, and the whole state goes
    out as values (:func:`absolute`), never as a reset."""
    adopt: Mapping[int, Slots] = field(default_factory=lambda: MappingProxyType({}))
    """Stations whose antennas on the box win over the saved state: the engine takes
    them as the radio's antennas (the saved state is older than the box)."""
    waiting: frozenset[int] = frozenset()
    """Transmitting stations whose last change the box still holds back (wait mode):
    consistent, and sent again so that it is surely what the box applies at receive."""
    why: str = ""
    """Why the box does not simply hold the saved state ("" when it does)."""
    inactive: bool = False
    """The box is inactive: reset or powered off since it was loaded."""


def slots_of(station: StationAntennas) -> Slots:
    return (station.tx, station.rx, station.alt)


def reconcile(
    held: SwitchState | None, seen: Sequence[Slots] | None, survey: Survey
) -> Reconciliation:
    """Compare what a box reports (``survey``) with what it was last told (``held``,
    from this server or the saved state) and last seen holding (``seen``: the antennas
    it reported as in use), station by station.

    * An inactive box lost what it held (reset, power): it is loaded again as values.
    * A station showing what it was told is consistent.
    * A transmitting station showing what it was *seen* holding, not what it was told
      since, has a change waiting for it to receive (wait mode): consistent.
    * Any other station shows a change the saved state does not know (the state could
      not be saved, or the box was driven from elsewhere): what the box holds wins and
      the engine adopts it (stations transmitting always, receiving ones when a saved
      state exists to be wrong).
    * What cannot be judged station by station (inhibit polarity, closed relays that
      the saved state cannot explain while nobody transmits) loads the box as values.
    """
    keyed = survey.keyed()
    if not survey.pong.active:
        return Reconciliation(keyed, None, why="it is inactive (reset or powered off since)",
                              inactive=True)
    if held is None or not held.active:
        adopt = {n: survey.slots(n) for n in sorted(keyed)
                 if survey.slots(n) != (NO_ANTENNA,) * 3}
        why = "there is no saved state" if held is None else "the saved state is stopped"
        return Reconciliation(keyed, None, MappingProxyType(adopt), why=why)
    adopt, waiting = _compare_stations(held, seen, survey, keyed)
    why = _unexplained(held, survey, keyed, adopt)
    believed: SwitchState | None = None
    if not why:
        believed = _resend_antennas(held, keyed)
    if adopt and not why:
        why = "; ".join(f"station {n} holds other antennas" for n in sorted(adopt))
    return Reconciliation(keyed, believed, MappingProxyType(adopt), frozenset(waiting), why)


def _compare_stations(held: SwitchState, seen: Sequence[Slots] | None, survey: Survey,
                      keyed: frozenset[int]) -> tuple[dict[int, Slots], set[int]]:
    """Station by station: the stations whose antennas on the box win (a change the
    saved state does not know), and the transmitting ones whose change waits for them
    to receive (each antenna is the one told, or still the one seen before)."""
    adopt: dict[int, Slots] = {}
    waiting = set()
    for n, station in zip(STATIONS, held.stations, strict=True):
        found = survey.slots(n)
        if found == slots_of(station):
            continue
        told, before = slots_of(station), tuple(seen[n - 1]) if seen is not None else None
        if n in keyed and before is not None and all(
                f in (t, b) for f, t, b in zip(found, told, before, strict=True)):
            waiting.add(n)  # each antenna is the one told, or still the one seen before
        else:
            adopt[n] = found
    return adopt, waiting


def _unexplained(held: SwitchState, survey: Survey, keyed: frozenset[int],
                 adopt: Mapping[int, Slots]) -> str:
    """What cannot be judged station by station, so the box is loaded as values: another
    inhibit polarity, or (while nobody transmits and every station is consistent) closed
    relays the saved state cannot explain.  Empty when there is none."""
    if survey.polarity.enable_low != held.enable_low:
        return "its inhibit polarity differs"
    if keyed or adopt:
        return ""
    possible = set(held.station0)
    for station in held.stations:
        possible |= station.tx_relays | station.rx_relays | station.alt_relays
    if not survey.relays.relays <= possible | _extras(held) \
            or not held.station0 <= survey.relays.relays:
        return "its closed relays differ"
    return ""


def _resend_antennas(held: SwitchState, keyed: frozenset[int]) -> SwitchState:
    """The box reports antennas (slots), not the relays behind them: a command lost on
    the line leaves the right slot with other relays, which no status shows.  So every
    station's antenna commands go again; the box takes the same antenna and relays as no
    change, and anything else under its hot-switch rules.  A keyed station's extra relays
    (closed while it transmits, at once) are not resent."""
    return replace(held, stations=tuple(
        replace(UNSURE, extra=s.extra) if n in keyed else UNSURE
        for n, s in zip(STATIONS, held.stations, strict=True)))


def _extras(state: SwitchState) -> set[int]:
    found: set[int] = set()
    for station in state.stations:
        found |= station.extra
    return found


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
    "Reconciliation",
    "Slots",
    "Survey",
    "absolute",
    "count_bytes",
    "difference",
    "initialise",
    "reconcile",
    "slots_of",
    "stopped",
]
