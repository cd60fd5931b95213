"""A still picture of the emulated switch, for windows and tests."""

from __future__ import annotations

from dataclasses import dataclass

from ..messages import StationMode
from .station import Slot, StationPhase


@dataclass(frozen=True, slots=True)
class StationView:
    """One station as the box holds it right now."""

    number: int
    key: bool
    """The station's T/R input (amplifier key line)."""
    phase: StationPhase
    transmitting: bool
    """Its transmit relays (and extra relays) are the closed ones."""
    on_alternate: bool
    tx: Slot
    rx: Slot
    alt: Slot
    extra: frozenset[int]
    pending: tuple[tuple[str, int], ...]
    """Antenna commands not carried out yet: (kind letter, antenna)."""
    mode: StationMode
    receive_delay_ms: int
    inhibited: bool
    """Its inhibit is asserted (for any reason)."""
    inhibited_by_command: bool
    inhibited_by: frozenset[int]
    """Transmitting stations that inhibit it (``~``)."""
    inhibit_line_low: bool
    """The inhibit output is pulled down."""
    enable_low: bool
    """Its polarity is "pull down to enable"."""
    closed: frozenset[int]
    """The relays this station closes now."""


@dataclass(frozen=True, slots=True)
class BoxView:
    """The whole box."""

    active: bool
    resolver_on: bool
    relays: frozenset[int]
    station0: frozenset[int]
    stations: tuple[StationView, ...]
    unit_id: int
    version: str
    inhibit_ms: int
    interrupt_ms: int
    events: frozenset[str]
    """Enabled event letters: A (antenna), T (T/R), I (inhibit), X (extra)."""

    def station(self, number: int) -> StationView:
        return self.stations[number - 1]


__all__ = ["BoxView", "StationView"]
