"""The emulated box's state, and the power-on values (see :mod:`.model`)."""

from __future__ import annotations

from typing import NamedTuple

from ..messages import (
    AntennaKind,
    BoxMessage,
    StateOp,
)
from .pairs import PairTable
from .record import Record
from .station import SlotRole, Station

STATIONS = (1, 2, 3, 4, 5, 6)

INPUT_BUFFER = 128
"""Characters the box can hold of one command."""

VENDOR_TEXT = "moas-gui-emulator"

_SLACK = 1e-9
"""Seconds a timer may be early and still count as run out (float rounding)."""

_KIND_OF: dict[AntennaKind, tuple[SlotRole, ...]] = {
    AntennaKind.TX: (SlotRole.TX,),
    AntennaKind.RX: (SlotRole.RX,),
    AntennaKind.BOTH: (SlotRole.TX, SlotRole.RX),
    AntennaKind.ALT: (SlotRole.ALT,),
    AntennaKind.EXTRA: (SlotRole.EXTRA,),
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


class StationConnection(NamedTuple):
    """What a receiving station is connected to."""

    role: SlotRole
    antenna: int | None
    relays: frozenset[int]


class BoxState:
    """Every setting and table of the box, and each station's live state."""

    def __init__(self, unit_id: int = 0, version: str = "100") -> None:
        self.unit_id = unit_id
        self.version = version
        self._now = 0.0
        self._seq = 0
        self._out: list[BoxMessage] = []
        self.stations: dict[int, Station] = {n: Station(n) for n in STATIONS}
        self.record = Record()
        """Every change of the closed relays, key line and reset (see :mod:`.record`)."""
        self._recorded: tuple[frozenset[int], tuple[frozenset[int], ...]] = (
            frozenset(), tuple(frozenset() for _ in STATIONS))
        self._command = ""
        """The command being carried out (for the record)."""
        self._power_on()

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


__all__ = ["INPUT_BUFFER", "STATIONS", "BoxState", "StationConnection"]
