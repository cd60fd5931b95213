"""What each command does to the emulated box: one method per command of
the manual, and the table :data:`HANDLERS` from command type to method."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..messages import (
    AntennaKind,
    BoxStatus,
    ConflictOp,
    ConflictTable,
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
    RelayStatus,
    RelayStatusRequest,
    SetAntenna,
    SetState,
    StateOp,
    StatusKind,
    StatusRequest,
    SystemTable,
    TRState,
    Uninhibit,
    UninhibitReply,
    UnitId,
    UnitIdReply,
    UseAlternate,
    VendorExtension,
    VendorReply,
)
from .boxstate import _EVENT_FLAGS, _KIND_OF, STATIONS, VENDOR_TEXT
from .record import EntryCause
from .station import PendingCommand, Slot, SlotRole
from .switching import Switching


class CommandHandlers(Switching):
    """The commands of the manual."""

    def _antenna(self, c: SetAntenna) -> None:
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
            st.pending[kind] = PendingCommand(slot, self._seq)

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
                self._write(EntryCause.RESET, self._command)
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
                tuple(st.current[SlotRole.TX].antenna for st in sts),
                tuple(st.current[SlotRole.RX].antenna for st in sts),
                tuple(st.current[SlotRole.ALT].antenna for st in sts),
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


HANDLERS: dict[type, Callable[[CommandHandlers, Any], None]] = {
    SetAntenna: CommandHandlers._antenna,
    ConflictTable: CommandHandlers._conflict_table,
    FastTable: CommandHandlers._fast_table,
    Inhibit: CommandHandlers._inhibit,
    Uninhibit: CommandHandlers._uninhibit,
    InhibitOthers: CommandHandlers._inhibit_others,
    InhibitPolarity: CommandHandlers._polarity,
    InhibitTime: CommandHandlers._inhibit_time,
    InterruptDelay: CommandHandlers._interrupt_delay,
    Mode: CommandHandlers._mode,
    Ping: CommandHandlers._ping,
    ReceiveDelay: CommandHandlers._receive_delay,
    RelayStatusRequest: CommandHandlers._relay_status,
    SetState: CommandHandlers._set_state,
    StatusRequest: CommandHandlers._status,
    SystemTable: CommandHandlers._system,
    UnitId: CommandHandlers._unit_id,
    UseAlternate: CommandHandlers._use_alternate,
    VendorExtension: CommandHandlers._vendor,
}
"""What each command does to the box."""

__all__ = ["HANDLERS", "CommandHandlers"]
