"""How the emulated box moves its relays: the closed relays, the station
phase machine (:mod:`.station`), the timers and the conflict resolver
(:mod:`.resolver`), in one layer under the command handlers (see
:mod:`.model` for the rules in plain words)."""

from __future__ import annotations

from collections.abc import Mapping

from ..messages import (
    AntennaEvent,
    AntennaStatus,
    ExtraRelaysEvent,
    ReceiveEvent,
    StationMode,
    TransmitEvent,
)
from .boxstate import _SLACK, BoxState, StationConnection
from .record import Entry, EntryCause
from .resolver import CLAIMING, KIND_ORDER, Candidate, choose
from .station import Slot, SlotRole, Station, StationPhase, TimerChange, Trigger, next_phase


class Switching(BoxState):
    """Relays, timers and the resolver."""

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

    def _activate(self) -> None:
        if self.active:
            return
        self.active = True
        self.resolver_on = True
        for st in self.stations.values():
            if st.key:
                # Its radio transmits: it goes on the air where it stands (after a reset
                # or power-on, on no relays at all), and only then does the resolver look
                # at its antenna commands, which wait (wait mode) or interrupt (interrupt
                # mode) like any change on the air.
                self._key_down(st)
        self._resolve()

    def _advance_to(self, now: float) -> None:
        while (deadline := self.next_deadline()) is not None and deadline <= now + _SLACK:
            self._now = max(self._now, deadline)
            self._settle()
            self._note("timer")
        self._now = max(self._now, now)

    # ------------------------------------------------------------------ the record

    def _closed_now(self) -> tuple[frozenset[int], tuple[frozenset[int], ...]]:
        """The relays closed now (as :meth:`relays`) and each station's, worked out once
        (the record asks after every command)."""
        if not self.active:
            return frozenset(), tuple(frozenset() for _ in self.stations)
        closed = tuple(self._closed(st) for st in self.stations.values())
        return frozenset(self.station0).union(*closed), closed

    def _write(self, event: EntryCause, cause: str) -> None:
        """Add an entry to the record: the box as it is now."""
        relays, closed = self._closed_now()
        keyed = frozenset(n for n, st in self.stations.items() if st.key)
        interrupt_mode = frozenset(
            n for n, st in self.stations.items() if st.mode is StationMode.INTERRUPT)
        last = self.record.last
        if last is not None:
            # What did not change is the last entry's own: an entry costs little more
            # than what changed.
            relays = last.relays if relays == last.relays else relays
            closed = last.closed if closed == last.closed else tuple(
                old if old == new else new for old, new in zip(last.closed, closed, strict=True))
            keyed = last.keyed if keyed == last.keyed else keyed
            if interrupt_mode == last.interrupt_mode:
                interrupt_mode = last.interrupt_mode
        self._recorded = (relays, closed)
        self.record.add(Entry(
            seq=self.record.written + 1,
            at=self._now,
            event=event,
            cause=cause,
            active=self.active,
            relays=relays,
            keyed=keyed,
            closed=closed,
            interrupt_mode=interrupt_mode,
        ))

    def _note(self, cause: str) -> None:
        """Add an entry if the closed relays changed since the last one."""
        if self._closed_now() != self._recorded:
            self._write(EntryCause.RELAYS, cause)

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
                st
                for st in self.stations.values()
                if st.deadline is not None and st.deadline <= self._now + _SLACK
            ]
            if not due:
                return moved
            self._timeout(min(due, key=lambda st: (st.deadline, st.number)))
            moved = True

    def _timeout(self, st: Station) -> None:
        before = st.phase
        if before is StationPhase.RELEASE:
            trigger = Trigger.DEADLINE
        elif before in (StationPhase.SLOW, StationPhase.INTERRUPT):
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
        if before is StationPhase.INTERRUPT:
            switched = dict(st.incoming)
            st.current.update(switched)
            st.incoming.clear()
            for kind, slot in switched.items():
                self._announce(st, kind, slot)
        if st.phase is StationPhase.RECEIVE and st.tx_side:
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
        if timer is TimerChange.NONE:
            st.deadline = None
        elif timer is TimerChange.INHIBIT:
            end = now + self.inhibit_ms / 1000
            keep = before is StationPhase.SLOW and st.deadline is not None
            st.deadline = max(st.deadline, end) if keep and st.deadline is not None else end
        elif timer is TimerChange.INTERRUPT_DELAY:
            st.deadline = now + self.interrupt_ms / 1000
        elif timer is TimerChange.RECEIVE_DELAY:
            st.deadline = now + st.receive_delay_ms / 1000
        elif timer is TimerChange.RECEIVE_DELAY_REST:
            st.deadline = max(now, st.released_at + st.receive_delay_ms / 1000)
        return True

    def _key_down(self, st: Station) -> None:
        if st.tx_side:
            self._fire(st, Trigger.KEY_DOWN)
        else:
            old = self._receive_connection(st, st.current)
            tx = st.current[SlotRole.TX]
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
                self._emit(TransmitEvent(st.number, st.current[SlotRole.TX].antenna))

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
            held = [other.current[SlotRole.TX].antenna, other.current[SlotRole.RX].antenna]
            if SlotRole.TX in other.incoming:
                held.append(other.incoming[SlotRole.TX].antenna)
            if any(row >> a & 1 for a in held):
                return True
        return False

    def _receive_connection(
        self, st: Station, slots: Mapping[SlotRole, Slot], *, alternates: bool = True
    ) -> StationConnection:
        if alternates and self._alternate_selected(st):
            alt = slots[SlotRole.ALT]
            if self._alternate_blocked(st, alt.antenna):
                return StationConnection(SlotRole.ALT, None, frozenset())
            return StationConnection(SlotRole.ALT, alt.antenna, alt.relays)
        tx, rx = slots[SlotRole.TX], slots[SlotRole.RX]
        if self.fast.get(tx.antenna, rx.antenna):
            return StationConnection(SlotRole.RX, rx.antenna, rx.relays)
        return StationConnection(SlotRole.TX, tx.antenna, tx.relays)

    def _closed(self, st: Station) -> frozenset[int]:
        if st.tx_side:
            return st.current[SlotRole.TX].relays | st.current[SlotRole.EXTRA].relays
        return self._receive_connection(st, st.current).relays

    def _inhibited_by(self, st: Station) -> frozenset[int]:
        return frozenset(
            other.number
            for other in self.stations.values()
            if other.tx_side and st.number in self.inhibit_others[other.number]
        )

    def _classify(self, st: Station, changes: Mapping[SlotRole, Slot]) -> Trigger | None:
        """The trigger that carrying out ``changes`` would be for ``st``."""
        after = {**st.current, **changes}
        if st.tx_side:
            before_relays = st.current[SlotRole.TX].relays | st.current[SlotRole.EXTRA].relays
            if before_relays == after[SlotRole.TX].relays | after[SlotRole.EXTRA].relays:
                return None
            if st.mode is StationMode.INTERRUPT:
                return Trigger.ON_AIR_INTERRUPT
            return Trigger.ON_AIR_WAIT
        old = self._receive_connection(st, st.current)
        new = self._receive_connection(st, after)
        if old.relays == new.relays:
            return None
        if old.role is not SlotRole.TX and new.role is not SlotRole.TX:
            return Trigger.SWITCH
        if (
            old.antenna is not None
            and new.antenna is not None
            and self.fast.get(old.antenna, new.antenna)
        ):
            return Trigger.SWITCH
        return Trigger.SWITCH_SLOW

    def _allowed(self, number: int, changes: dict[SlotRole, Slot]) -> bool:
        st = self.stations[number]
        if st.phase is StationPhase.INTERRUPT and (SlotRole.TX in changes or SlotRole.EXTRA in changes):
            return False
        trigger = self._classify(st, changes)
        return trigger is None or next_phase(st.phase, trigger) is not None

    def _system_free(self, st: Station, kind: SlotRole, slot: Slot) -> bool:
        """Antenna-system rule: changes touching a system wait until the
        station is receiving and nobody transmits on that system."""
        touched = {self.systems[slot.antenna], self.systems[st.current[kind].antenna]} - {0}
        if not touched:
            return True
        if st.tx_side:
            return False
        return not any(
            other.tx_side and self.systems[other.current[SlotRole.TX].antenna] in touched
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
                    if kind is not SlotRole.EXTRA:
                        self._announce(st, kind, request.slot)
                    moved = True
                elif kind not in CLAIMING or self._system_free(st, kind, request.slot):
                    candidates.append(Candidate(st.number, kind, request.slot, request.seq))
        if not candidates:
            return moved
        choice = choose(
            candidates,
            {
                n: {SlotRole.TX: st.current[SlotRole.TX].antenna, SlotRole.RX: st.current[SlotRole.RX].antenna}
                for n, st in self.stations.items()
            },
            {n: self._reserved(st) for n, st in self.stations.items()},
            self.conflicts,
            self._allowed,
        )
        for c in sorted(choice.conflicted, key=lambda c: (c.seq, KIND_ORDER[c.kind])):
            request = self.stations[c.station].pending[c.kind]
            if not request.conflict_reported:
                request.conflict_reported = True
                if "A" in self.events:
                    status = (
                        AntennaStatus.TX_CONFLICT
                        if c.kind is SlotRole.TX
                        else AntennaStatus.RX_CONFLICT
                    )
                    self._emit(AntennaEvent(c.station, status, c.slot.antenna))
        grouped: dict[int, dict[SlotRole, Slot]] = {}
        for c in choice.granted:
            grouped.setdefault(c.station, {})[c.kind] = c.slot
        for number, changes in grouped.items():
            self._carry_out(self.stations[number], changes)
        return moved or bool(grouped)

    @staticmethod
    def _reserved(st: Station) -> list[int]:
        """Antennas ``st`` holds beyond its current ones, whatever it is
        granted now: an interrupt's incoming transmit antenna, and, while an
        interrupt-mode station is on the air, the transmit antenna it is on
        (its relays stay there through the interrupt delay, so another
        station may not take that antenna in the same step)."""
        held = []
        if SlotRole.TX in st.incoming:
            held.append(st.incoming[SlotRole.TX].antenna)
        if st.tx_side and st.mode is StationMode.INTERRUPT:
            held.append(st.current[SlotRole.TX].antenna)
        return held

    def _carry_out(self, st: Station, changes: dict[SlotRole, Slot]) -> None:
        trigger = self._classify(st, changes)
        for kind in changes:
            del st.pending[kind]
        if trigger is Trigger.ON_AIR_INTERRUPT:
            self._fire(st, trigger)
            for kind, slot in changes.items():
                if kind in (SlotRole.TX, SlotRole.EXTRA):
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

    def _announce(self, st: Station, kind: SlotRole, slot: Slot) -> None:
        if kind is SlotRole.EXTRA:
            if "X" in self.events:
                self._emit(ExtraRelaysEvent(st.number))
            return
        if "A" not in self.events:
            return
        tx, rx = st.current[SlotRole.TX].antenna, st.current[SlotRole.RX].antenna
        if kind is SlotRole.TX:
            status = (
                AntennaStatus.TX_FAST if self.fast.get(slot.antenna, rx) else AntennaStatus.TX_SLOW
            )
        elif kind is SlotRole.RX:
            status = (
                AntennaStatus.RX_FAST if self.fast.get(tx, slot.antenna) else AntennaStatus.RX_SLOW
            )
        elif self._alternate_blocked(st, slot.antenna):
            status = AntennaStatus.ALT_CONFLICT
        else:
            status = AntennaStatus.ALT_FREE
        self._emit(AntennaEvent(st.number, status, slot.antenna))


__all__ = ["Switching"]
