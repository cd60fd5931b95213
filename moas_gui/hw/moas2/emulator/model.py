"""The MOAS II firmware as a pure model: bytes and time in, bytes out.

``model.feed(data, now)`` takes what the computer sent, ``model.set_tr(station,
transmitting, now)`` what a radio's key line did, ``model.advance(now)`` lets
time pass; each returns the bytes the box sends.  ``now`` is in seconds from
any fixed point; the model never reads a clock, so tests can step time by
hand and watch an inhibit come and go.

What it does, in plain words (docs/switch.md has the full list of decisions
where the manual is silent):

* Input: characters at or below space are ignored, ``$`` throws away the
  command so far, ``;`` ends a command.  The input buffer holds 128
  characters; a longer command is answered ``?F`` and dropped up to its ``;``.
* After power-on or ``*0`` the box is inactive: all relays open, nothing
  switches, antenna commands are remembered.  ``*1`` activates it and turns
  the conflict resolver on; a station whose key line is already asserted then
  gets the slow-transition inhibit while its relays close.
* Antenna commands become requests; the resolver (see :mod:`.resolver`)
  carries them out when there is no conflict and the station's phase table
  (see :mod:`.station`) allows, and holds them otherwise.  A newer request of
  the same kind for a station replaces a held one.
* The closed relays are: station 0's relays, plus for each station its
  transmit relays and extra relays while it is on the air, otherwise its
  receive relays -- the alternate's while a station listed for it with ``@``
  is on the air (none at all if the alternate conflicts with another
  station's antenna), the transmit antenna's if the transmit/receive pair is
  not in the fast table.
* A station's inhibit is asserted while it is inhibited by command, while a
  station that ``~`` lists it for is on the air, and during slow transitions
  and interrupts.  The output is pulled down when inhibited (or, with ``^E``,
  when not inhibited); an inactive box pulls nothing down.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

from ..commands import parse_command
from ..errors import CommandRejected
from ..messages import (
    Antenna,
    AntennaEvent,
    AntennaKind,
    AntennaStatus,
    BoxMessage,
    BoxStatus,
    ConflictOp,
    ConflictTable,
    ErrorReply,
    ExtraRelaysEvent,
    FastOp,
    FastTable,
    Inhibit,
    InhibitOthers,
    InhibitPolarity,
    InhibitReply,
    InhibitTime,
    InterruptDelay,
    Mode,
    Ping,
    PolarityOp,
    PolarityStatus,
    Pong,
    ReceiveDelay,
    ReceiveEvent,
    RelayStatus,
    RelayStatusRequest,
    SetState,
    StateOp,
    StationMode,
    StatusKind,
    StatusRequest,
    SystemTable,
    TransmitEvent,
    TRState,
    Uninhibit,
    UninhibitReply,
    UnitId,
    UnitIdReply,
    UseAlternate,
    VendorExtension,
    VendorReply,
)
from ..replies import encode_reply
from .pairs import PairTable
from .resolver import CLAIMING, KIND_ORDER, Candidate, choose
from .station import NO_SLOT, Kind, Phase, Request, Slot, Station, Timer, Trigger, next_phase
from .view import BoxView, StationView

STATIONS = (1, 2, 3, 4, 5, 6)

INPUT_BUFFER = 128
"""Characters the box can hold of one command."""

VENDOR_TEXT = "moas-gui-emulator"

_SLACK = 1e-9
"""Seconds a timer may be early and still count as run out (float rounding)."""

_KIND_OF: dict[AntennaKind, tuple[Kind, ...]] = {
    AntennaKind.TX: (Kind.TX,),
    AntennaKind.RX: (Kind.RX,),
    AntennaKind.BOTH: (Kind.TX, Kind.RX),
    AntennaKind.ALT: (Kind.ALT,),
    AntennaKind.EXTRA: (Kind.EXTRA,),
}

_EVENT_FLAGS: dict[StateOp, tuple[str, bool]] = {
    StateOp.ANTENNA_EVENTS_ON: ("A", True),
    StateOp.ANTENNA_EVENTS_OFF: ("A", False),
    StateOp.TR_EVENTS_ON: ("T", True),
    StateOp.TR_EVENTS_OFF: ("T", False),
    StateOp.INHIBIT_EVENTS_ON: ("I", True),
    StateOp.INHIBIT_EVENTS_OFF: ("I", False),
    StateOp.EXTRA_EVENTS_ON: ("X", True),
    StateOp.EXTRA_EVENTS_OFF: ("X", False),
}


class Connection(NamedTuple):
    """What a receiving station is connected to."""

    role: Kind
    antenna: int | None
    relays: frozenset[int]


class EmulatorModel:
    """One MOAS II box."""

    def __init__(self, unit_id: int = 0, version: str = "100") -> None:
        self.unit_id = unit_id
        self.version = version
        self._now = 0.0
        self._seq = 0
        self._input = bytearray()
        self._overflowed = False
        self._out: list[BoxMessage] = []
        self.stations: dict[int, Station] = {n: Station(n) for n in STATIONS}
        self._power_on()

    # ------------------------------------------------------------------ public

    @property
    def now(self) -> float:
        return self._now

    def feed(self, data: bytes, now: float) -> bytes:
        """Take bytes from the computer; return the box's answer."""
        self._advance_to(now)
        for byte in data:
            self._take(byte)
        return self._flush()

    def advance(self, now: float) -> bytes:
        """Let time pass up to ``now``; return what the box sent meanwhile."""
        self._advance_to(now)
        return self._flush()

    def set_tr(self, station: int, transmitting: bool, now: float) -> bytes:
        """A station's key line changed (True: asserted)."""
        self._advance_to(now)
        st = self.stations[station]
        if st.key != transmitting:
            st.key = transmitting
            if not transmitting:
                st.released_at = self._now
            if self.active:
                if transmitting:
                    self._key_down(st)
                else:
                    self._fire(st, Trigger.KEY_UP)
                self._settle()
        return self._flush()

    def next_deadline(self) -> float | None:
        """When the next timer runs out (seconds), or None."""
        deadlines = [st.deadline for st in self.stations.values() if st.deadline is not None]
        return min(deadlines) if deadlines else None

    def relays(self) -> frozenset[int]:
        """The relays closed now."""
        if not self.active:
            return frozenset()
        closed = set(self.station0)
        for st in self.stations.values():
            closed |= self._closed(st)
        return frozenset(closed)

    def inhibited(self, station: int) -> bool:
        """Whether ``station``'s inhibit is asserted now."""
        st = self.stations[station]
        return self.active and (
            station in self.cmd_inhibited or st.inhibiting or bool(self._inhibited_by(st))
        )

    def view(self) -> BoxView:
        """A still picture of everything."""
        return BoxView(
            active=self.active,
            resolver_on=self.resolver_on,
            relays=self.relays(),
            station0=self.station0,
            stations=tuple(self._station_view(st) for st in self.stations.values()),
            unit_id=self.unit_id,
            version=self.version,
            inhibit_ms=self.inhibit_ms,
            interrupt_ms=self.interrupt_ms,
            events=frozenset(self.events),
        )

    # ------------------------------------------------------------------ state

    def _power_on(self) -> None:
        self.active = False
        self.resolver_on = False
        self.events: set[str] = set()
        self.conflicts = PairTable()
        self.fast = PairTable()
        self.systems = [0] * 64
        self.inhibit_ms = 20
        self.interrupt_ms = 0
        self.enable_low: set[int] = set()
        self.cmd_inhibited: set[int] = set()
        self.inhibit_others: dict[int, frozenset[int]] = {n: frozenset() for n in STATIONS}
        self.use_alternate: dict[int, frozenset[int]] = {n: frozenset() for n in STATIONS}
        self.station0: frozenset[int] = frozenset()
        for n, old in self.stations.items():
            self.stations[n] = Station(n, key=old.key, released_at=old.released_at)

    def _emit(self, message: BoxMessage) -> None:
        self._out.append(message)

    def _flush(self) -> bytes:
        out = b"".join(encode_reply(m) for m in self._out)
        self._out.clear()
        return out

    # ------------------------------------------------------------------ input

    def _take(self, byte: int) -> None:
        if byte <= 0x20:
            return
        if byte == 0x24:  # "$"
            self._input.clear()
            self._overflowed = False
        elif byte == 0x3B:  # ";"
            if not self._overflowed and self._input:
                self._execute(self._input.decode("latin-1"))
            self._input.clear()
            self._overflowed = False
        elif not self._overflowed:
            if len(self._input) >= INPUT_BUFFER:
                self._overflowed = True
                self._input.clear()
                self._emit(ErrorReply("F"))
            else:
                self._input.append(byte)

    def _execute(self, text: str) -> None:
        try:
            command = parse_command(text)
        except CommandRejected as exc:
            self._emit(ErrorReply(exc.code))
            return
        _HANDLERS[type(command)](self, command)
        self._settle()

    # ------------------------------------------------------------------ commands

    def _antenna(self, c: Antenna) -> None:
        if c.station == 0:
            self.station0 = frozenset(c.relays)
            if self.active and "X" in self.events:
                self._emit(ExtraRelaysEvent(0))
            return
        st = self.stations[c.station]
        self._seq += 1
        # Extra relays belong to no antenna: the antenna character is ignored.
        antenna = 63 if c.kind is AntennaKind.EXTRA else c.antenna
        slot = Slot(antenna, frozenset(c.relays))
        for kind in _KIND_OF[c.kind]:
            st.pending[kind] = Request(slot, self._seq)

    def _conflict_table(self, c: ConflictTable) -> None:
        if c.op in (ConflictOp.NONE, ConflictOp.ALL):
            self.conflicts.fill(c.op is ConflictOp.ALL)
        else:
            self.conflicts.set_many(c.pairs, c.op is ConflictOp.SET)

    def _fast_table(self, c: FastTable) -> None:
        if c.op in (FastOp.ALL_SLOW, FastOp.ALL_FAST):
            self.fast.fill(c.op is FastOp.ALL_FAST)
        else:
            self.fast.set_many(c.pairs, c.op is FastOp.FAST)

    def _inhibit(self, c: Inhibit) -> None:
        self.cmd_inhibited |= c.stations
        if self.active and "I" in self.events:
            self._emit(InhibitReply(frozenset(self.cmd_inhibited)))

    def _uninhibit(self, c: Uninhibit) -> None:
        self.cmd_inhibited -= c.stations
        if self.active and "I" in self.events:
            self._emit(UninhibitReply(frozenset(self.cmd_inhibited)))

    def _inhibit_others(self, c: InhibitOthers) -> None:
        self.inhibit_others[c.station] = c.stations

    def _use_alternate(self, c: UseAlternate) -> None:
        self.use_alternate[c.station] = c.stations

    def _polarity(self, c: InhibitPolarity) -> None:
        if c.op is PolarityOp.ALL_INHIBIT_LOW:
            self.enable_low = set()
        elif c.op is PolarityOp.ALL_ENABLE_LOW:
            self.enable_low = set(STATIONS)
        elif c.op is PolarityOp.ENABLE_LOW:
            self.enable_low |= c.stations
        else:
            self.enable_low -= c.stations

    def _inhibit_time(self, c: InhibitTime) -> None:
        self.inhibit_ms = c.ms

    def _interrupt_delay(self, c: InterruptDelay) -> None:
        self.interrupt_ms = c.ms

    def _mode(self, c: Mode) -> None:
        for n in c.stations:
            self.stations[n].mode = c.mode

    def _ping(self, c: Ping) -> None:
        self._emit(Pong(self.active))

    def _receive_delay(self, c: ReceiveDelay) -> None:
        self.stations[c.station].receive_delay_ms = c.ms

    def _relay_status(self, c: RelayStatusRequest) -> None:
        self._emit(RelayStatus(self.relays()))

    def _set_state(self, c: SetState) -> None:
        for op in c.ops:
            if op is StateOp.RESET:
                self._power_on()
            elif op is StateOp.ACTIVATE:
                self._activate()
            elif op is StateOp.RESOLVER_ON:
                self.resolver_on = True
            elif op is StateOp.RESOLVER_OFF:
                self.resolver_on = False
            else:
                letter, on = _EVENT_FLAGS[op]
                if on:
                    self.events.add(letter)
                else:
                    self.events.discard(letter)

    def _status(self, c: StatusRequest) -> None:
        if c.kind is StatusKind.POLARITY:
            self._emit(PolarityStatus(frozenset(self.enable_low)))
            return
        sts = list(self.stations.values())
        self._emit(
            BoxStatus(
                tuple(
                    TRState.TRANSMIT
                    if st.tx_side
                    else TRState.INHIBITED
                    if st.number in self.cmd_inhibited
                    else TRState.RECEIVE
                    for st in sts
                ),
                tuple(st.current[Kind.TX].antenna for st in sts),
                tuple(st.current[Kind.RX].antenna for st in sts),
                tuple(st.current[Kind.ALT].antenna for st in sts),
            )
        )

    def _system(self, c: SystemTable) -> None:
        if c.clear:
            self.systems = [0] * 64
        for antenna, system in c.pairs:
            self.systems[antenna] = system

    def _unit_id(self, c: UnitId) -> None:
        if c.unit is not None:
            self.unit_id = c.unit
        self._emit(UnitIdReply(self.version, self.unit_id))

    def _vendor(self, c: VendorExtension) -> None:
        self._emit(VendorReply(VENDOR_TEXT))

    def _activate(self) -> None:
        if self.active:
            return
        self.active = True
        self.resolver_on = True
        self._resolve()
        for st in self.stations.values():
            if st.key:
                # Relays close under a transmitting radio: inhibit it meanwhile.
                self._fire(st, Trigger.KEY_DOWN_SLOW)
                self._go_on_air(st)

    # ------------------------------------------------------------------ time

    def _advance_to(self, now: float) -> None:
        while (deadline := self.next_deadline()) is not None and deadline <= now + _SLACK:
            self._now = max(self._now, deadline)
            self._settle()
        self._now = max(self._now, now)

    def _settle(self) -> None:
        """Run timers that are due and the resolver until nothing moves."""
        for _ in range(64):
            moved = self._run_due()
            moved = self._resolve() or moved
            if not moved:
                return

    def _run_due(self) -> bool:
        moved = False
        while True:
            due = [
                st for st in self.stations.values()
                if st.deadline is not None and st.deadline <= self._now + _SLACK
            ]
            if not due:
                return moved
            self._timeout(min(due, key=lambda st: (st.deadline, st.number)))
            moved = True

    def _timeout(self, st: Station) -> None:
        before = st.phase
        if before is Phase.RELEASE:
            trigger = Trigger.DEADLINE
        elif before in (Phase.SLOW, Phase.INTERRUPT):
            trigger = (
                Trigger.DEADLINE_KEYED
                if st.key
                else Trigger.DEADLINE_RELEASED
                if st.tx_side
                else Trigger.DEADLINE
            )
        else:
            st.deadline = None
            return
        if not self._fire(st, trigger):
            st.deadline = None
            return
        if before is Phase.INTERRUPT:
            switched = dict(st.incoming)
            st.current.update(switched)
            st.incoming.clear()
            for kind, slot in switched.items():
                self._announce(st, kind, slot)
        if st.phase is Phase.RECEIVE and st.tx_side:
            st.tx_side = False
            if st.reported_tx:
                st.reported_tx = False
                if "T" in self.events:
                    shown = self._receive_connection(st, st.current, alternates=False)
                    antenna = shown.antenna if shown.antenna is not None else 63
                    self._emit(ReceiveEvent(st.number, antenna))

    def _fire(self, st: Station, trigger: Trigger) -> bool:
        entry = next_phase(st.phase, trigger)
        if entry is None:
            return False
        before = st.phase
        st.phase, timer = entry
        now = self._now
        if timer is Timer.NONE:
            st.deadline = None
        elif timer is Timer.INHIBIT:
            end = now + self.inhibit_ms / 1000
            keep = before is Phase.SLOW and st.deadline is not None
            st.deadline = max(st.deadline, end) if keep and st.deadline is not None else end
        elif timer is Timer.INTERRUPT_DELAY:
            st.deadline = now + self.interrupt_ms / 1000
        elif timer is Timer.RECEIVE_DELAY:
            st.deadline = now + st.receive_delay_ms / 1000
        elif timer is Timer.RECEIVE_DELAY_REST:
            st.deadline = max(now, st.released_at + st.receive_delay_ms / 1000)
        return True

    # ------------------------------------------------------------------ key line

    def _key_down(self, st: Station) -> None:
        if st.tx_side:
            self._fire(st, Trigger.KEY_DOWN)
        else:
            old = self._receive_connection(st, st.current)
            tx = st.current[Kind.TX]
            fast = old.relays == tx.relays or (
                old.antenna is not None and self.fast.get(old.antenna, tx.antenna)
            )
            self._fire(st, Trigger.KEY_DOWN if fast else Trigger.KEY_DOWN_SLOW)
        self._go_on_air(st)

    def _go_on_air(self, st: Station) -> None:
        st.tx_side = True
        if not st.reported_tx:
            st.reported_tx = True
            if "T" in self.events:
                self._emit(TransmitEvent(st.number, st.current[Kind.TX].antenna))

    # ------------------------------------------------------------------ relays

    def _alternate_selected(self, st: Station) -> bool:
        return not st.tx_side and any(
            other.tx_side and st.number in self.use_alternate[other.number]
            for other in self.stations.values()
        )

    def _alternate_blocked(self, st: Station, antenna: int) -> bool:
        row = self.conflicts.row(antenna)
        for other in self.stations.values():
            if other is st:
                continue
            held = [other.current[Kind.TX].antenna, other.current[Kind.RX].antenna]
            if Kind.TX in other.incoming:
                held.append(other.incoming[Kind.TX].antenna)
            if any(row >> a & 1 for a in held):
                return True
        return False

    def _receive_connection(
        self, st: Station, slots: Mapping[Kind, Slot], *, alternates: bool = True
    ) -> Connection:
        if alternates and self._alternate_selected(st):
            alt = slots[Kind.ALT]
            if self._alternate_blocked(st, alt.antenna):
                return Connection(Kind.ALT, None, frozenset())
            return Connection(Kind.ALT, alt.antenna, alt.relays)
        tx, rx = slots[Kind.TX], slots[Kind.RX]
        if self.fast.get(tx.antenna, rx.antenna):
            return Connection(Kind.RX, rx.antenna, rx.relays)
        return Connection(Kind.TX, tx.antenna, tx.relays)

    def _closed(self, st: Station) -> frozenset[int]:
        if st.tx_side:
            return st.current[Kind.TX].relays | st.current[Kind.EXTRA].relays
        return self._receive_connection(st, st.current).relays

    def _inhibited_by(self, st: Station) -> frozenset[int]:
        return frozenset(
            other.number
            for other in self.stations.values()
            if other.tx_side and st.number in self.inhibit_others[other.number]
        )

    # ------------------------------------------------------------------ resolver

    def _classify(self, st: Station, changes: Mapping[Kind, Slot]) -> Trigger | None:
        """The trigger that carrying out ``changes`` would be for ``st``."""
        after = {**st.current, **changes}
        if st.tx_side:
            before_relays = st.current[Kind.TX].relays | st.current[Kind.EXTRA].relays
            if before_relays == after[Kind.TX].relays | after[Kind.EXTRA].relays:
                return None
            if st.mode is StationMode.INTERRUPT:
                return Trigger.ON_AIR_INTERRUPT
            return Trigger.ON_AIR_WAIT
        old = self._receive_connection(st, st.current)
        new = self._receive_connection(st, after)
        if old.relays == new.relays:
            return None
        if old.role is not Kind.TX and new.role is not Kind.TX:
            return Trigger.SWITCH
        if (
            old.antenna is not None
            and new.antenna is not None
            and self.fast.get(old.antenna, new.antenna)
        ):
            return Trigger.SWITCH
        return Trigger.SWITCH_SLOW

    def _allowed(self, number: int, changes: dict[Kind, Slot]) -> bool:
        st = self.stations[number]
        if st.phase is Phase.INTERRUPT and (Kind.TX in changes or Kind.EXTRA in changes):
            return False
        trigger = self._classify(st, changes)
        return trigger is None or next_phase(st.phase, trigger) is not None

    def _system_free(self, st: Station, kind: Kind, slot: Slot) -> bool:
        """Antenna-system rule: changes touching a system wait until the
        station is receiving and nobody transmits on that system."""
        touched = {self.systems[slot.antenna], self.systems[st.current[kind].antenna]} - {0}
        if not touched:
            return True
        if st.tx_side:
            return False
        return not any(
            other.tx_side and self.systems[other.current[Kind.TX].antenna] in touched
            for other in self.stations.values()
        )

    def _resolve(self) -> bool:
        if not (self.active and self.resolver_on):
            return False
        moved = False
        candidates: list[Candidate] = []
        for st in self.stations.values():
            for kind, request in list(st.pending.items()):
                if request.slot == st.incoming.get(kind, st.current[kind]):
                    del st.pending[kind]
                    if kind is not Kind.EXTRA:
                        self._announce(st, kind, request.slot)
                    moved = True
                elif kind not in CLAIMING or self._system_free(st, kind, request.slot):
                    candidates.append(Candidate(st.number, kind, request.slot, request.seq))
        if not candidates:
            return moved
        choice = choose(
            candidates,
            {
                n: {Kind.TX: st.current[Kind.TX].antenna, Kind.RX: st.current[Kind.RX].antenna}
                for n, st in self.stations.items()
            },
            {n: [st.incoming[Kind.TX].antenna] for n, st in self.stations.items()
             if Kind.TX in st.incoming},
            self.conflicts,
            self._allowed,
        )
        for c in sorted(choice.conflicted, key=lambda c: (c.seq, KIND_ORDER[c.kind])):
            request = self.stations[c.station].pending[c.kind]
            if not request.conflict_reported:
                request.conflict_reported = True
                if "A" in self.events:
                    status = AntennaStatus.TX_CONFLICT if c.kind is Kind.TX else AntennaStatus.RX_CONFLICT
                    self._emit(AntennaEvent(c.station, status, c.slot.antenna))
        grouped: dict[int, dict[Kind, Slot]] = {}
        for c in choice.granted:
            grouped.setdefault(c.station, {})[c.kind] = c.slot
        for number, changes in grouped.items():
            self._carry_out(self.stations[number], changes)
        return moved or bool(grouped)

    def _carry_out(self, st: Station, changes: dict[Kind, Slot]) -> None:
        trigger = self._classify(st, changes)
        for kind in changes:
            del st.pending[kind]
        if trigger is Trigger.ON_AIR_INTERRUPT:
            self._fire(st, trigger)
            for kind, slot in changes.items():
                if kind in (Kind.TX, Kind.EXTRA):
                    st.incoming[kind] = slot
                else:
                    st.current[kind] = slot
                    self._announce(st, kind, slot)
            return
        st.current.update(changes)
        if trigger is not None:
            self._fire(st, trigger)
        for kind, slot in changes.items():
            self._announce(st, kind, slot)

    def _announce(self, st: Station, kind: Kind, slot: Slot) -> None:
        if kind is Kind.EXTRA:
            if "X" in self.events:
                self._emit(ExtraRelaysEvent(st.number))
            return
        if "A" not in self.events:
            return
        tx, rx = st.current[Kind.TX].antenna, st.current[Kind.RX].antenna
        if kind is Kind.TX:
            status = AntennaStatus.TX_FAST if self.fast.get(slot.antenna, rx) else AntennaStatus.TX_SLOW
        elif kind is Kind.RX:
            status = AntennaStatus.RX_FAST if self.fast.get(tx, slot.antenna) else AntennaStatus.RX_SLOW
        elif self._alternate_blocked(st, slot.antenna):
            status = AntennaStatus.ALT_CONFLICT
        else:
            status = AntennaStatus.ALT_FREE
        self._emit(AntennaEvent(st.number, status, slot.antenna))

    # ------------------------------------------------------------------ view

    def _station_view(self, st: Station) -> StationView:
        inhibited = self.inhibited(st.number)
        enable_low = st.number in self.enable_low
        return StationView(
            number=st.number,
            key=st.key,
            phase=st.phase,
            transmitting=st.tx_side,
            on_alternate=self._alternate_selected(st),
            tx=st.current[Kind.TX],
            rx=st.current[Kind.RX],
            alt=st.current[Kind.ALT],
            extra=st.current[Kind.EXTRA].relays,
            pending=tuple((k.value, r.slot.antenna) for k, r in st.pending.items()),
            mode=st.mode,
            receive_delay_ms=st.receive_delay_ms,
            inhibited=inhibited,
            inhibited_by_command=st.number in self.cmd_inhibited,
            inhibited_by=self._inhibited_by(st),
            inhibit_line_low=self.active and inhibited != enable_low,
            enable_low=enable_low,
            closed=self._closed(st) if self.active else frozenset(),
        )


_HANDLERS: dict[type, Callable[[EmulatorModel, Any], None]] = {
    Antenna: EmulatorModel._antenna,
    ConflictTable: EmulatorModel._conflict_table,
    FastTable: EmulatorModel._fast_table,
    Inhibit: EmulatorModel._inhibit,
    Uninhibit: EmulatorModel._uninhibit,
    InhibitOthers: EmulatorModel._inhibit_others,
    InhibitPolarity: EmulatorModel._polarity,
    InhibitTime: EmulatorModel._inhibit_time,
    InterruptDelay: EmulatorModel._interrupt_delay,
    Mode: EmulatorModel._mode,
    Ping: EmulatorModel._ping,
    ReceiveDelay: EmulatorModel._receive_delay,
    RelayStatusRequest: EmulatorModel._relay_status,
    SetState: EmulatorModel._set_state,
    StatusRequest: EmulatorModel._status,
    SystemTable: EmulatorModel._system,
    UnitId: EmulatorModel._unit_id,
    UseAlternate: EmulatorModel._use_alternate,
    VendorExtension: EmulatorModel._vendor,
}
"""What each command does to the box."""

__all__ = ["INPUT_BUFFER", "NO_SLOT", "Connection", "EmulatorModel"]
