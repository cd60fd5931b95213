"""What one MOAS II switch must hold: the engine's output for the switch link.

The engine computes a complete :class:`SwitchState` for every configured switch
after each input; the switch link compares it with the state it last sent and
writes only the commands needed to get from one to the other.  Nothing in here
knows about bytes: slots and relays are plain integers local to the switch
(slots 0-63, relays 0-63; slot 63 is "no antenna").
"""

from __future__ import annotations

from dataclasses import dataclass, field

NO_ANTENNA = 63
"""The switch slot that means "no antenna"."""

STATIONS = (1, 2, 3, 4, 5, 6)
"""The switch's station (port) numbers."""


@dataclass(frozen=True, slots=True)
class StationAntennas:
    """One switch port's antennas: switch slots and the relays that select them."""

    tx: int = NO_ANTENNA
    tx_relays: frozenset[int] = frozenset()
    rx: int = NO_ANTENNA
    rx_relays: frozenset[int] = frozenset()
    alt: int = NO_ANTENNA
    alt_relays: frozenset[int] = frozenset()
    extra: frozenset[int] = frozenset()
    """Relays closed while this station transmits (the ``!nX`` command)."""


def _idle_stations() -> tuple[StationAntennas, ...]:
    return tuple(StationAntennas() for _ in STATIONS)


def _empty_map() -> tuple[frozenset[int], ...]:
    return tuple(frozenset() for _ in STATIONS)


@dataclass(frozen=True, slots=True)
class SwitchState:
    """Everything the server wants one switch to hold.

    Per-station tuples have six entries: index 0 is station 1.  Pairs in
    ``conflicts`` and ``fast`` are ordered ``(low, high)``; a pair of a slot
    with itself is allowed.  ``systems`` maps slots to system numbers 1-63
    (slots not present have no system).
    """

    stations: tuple[StationAntennas, ...] = field(default_factory=_idle_stations)
    station0: frozenset[int] = frozenset()
    """Relays set regardless of any station (``!0X0...``)."""
    conflicts: frozenset[tuple[int, int]] = frozenset()
    fast: frozenset[tuple[int, int]] = frozenset()
    systems: tuple[tuple[int, int], ...] = ()
    """Sorted ``(slot, system)`` pairs."""
    inhibited: frozenset[int] = frozenset()
    """Stations inhibited by command (``(`` / ``)``)."""
    inhibit_others: tuple[frozenset[int], ...] = field(default_factory=_empty_map)
    """For each transmitting station, the stations it inhibits (``~``)."""
    use_alternate: tuple[frozenset[int], ...] = field(default_factory=_empty_map)
    """For each transmitting station, the stations moved to their alternate (``@``)."""
    interrupt: frozenset[int] = frozenset()
    """Stations in interrupt mode; the others wait."""
    enable_low: frozenset[int] = frozenset()
    """Stations whose inhibit output is pulled down to enable (``^E``)."""
    receive_delay: tuple[int, ...] = (0, 0, 0, 0, 0, 0)
    """Milliseconds per station (``\\``)."""
    inhibit_time: int = 20
    """Slow-transition inhibit in milliseconds (``[``)."""
    interrupt_delay: int = 0
    """Interrupt-mode delay in milliseconds (``]``)."""
    active: bool = True
    """False when the switches are stopped (all relays off)."""

    def station(self, number: int) -> StationAntennas:
        """The antennas of switch port ``number`` (1-6)."""
        return self.stations[number - 1]


__all__ = ["NO_ANTENNA", "STATIONS", "StationAntennas", "SwitchState"]
