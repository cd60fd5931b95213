"""The engine's state: what each radio has now, and the operator's settings.

Operations work on a :meth:`State.clone` and the engine keeps the clone only
when the operation succeeded, so a refused request leaves nothing behind.
Values inside the dicts are immutable (frozen dataclasses, tuples, frozensets,
or dicts that are replaced, never edited), which keeps cloning cheap.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from moas_gui.config.model import RadioRef

from .ranges import Segment
from .why import Why


@dataclass(frozen=True, slots=True)
class RadioState:
    """What the engine holds of one radio: its frequencies, its transmit and receive
    antennas, whether it transmits, and where it is in its relative antenna list."""

    khz: float | None = None
    tx_khz: float | None = None
    """The transmit frequency when split; None means the same as ``khz``."""
    tx: int | None = None
    rx: int | None = None
    transmitting: bool = False
    note: str = ""
    """Why selection left this radio without a suitable antenna (empty when fine)."""
    rel_pos: int | None = None
    """Appendix G: position of the current relative antenna in its list."""
    rel_key: tuple[int, int] | None = None
    """Which relative list ``rel_pos`` belongs to (group, range index)."""

    @property
    def tx_freq(self) -> float | None:
        return self.khz if self.tx_khz is None else self.tx_khz

    def with_(self, **changes: object) -> RadioState:
        return replace(self, **changes)  # type: ignore[arg-type]


History = Mapping[Segment, tuple[int | None, int | None]]


class State:
    """Everything that changes while the engine runs (see the module docstring)."""

    __slots__ = (
        "alt_active",
        "busses",
        "extra_on",
        "held",
        "held_since",
        "history",
        "latched",
        "now",
        "partners",
        "ports_tr",
        "radios",
        "relay_auto_off",
        "relay_on",
        "running",
        "shared",
        "stored",
        "why",
    )

    def __init__(self) -> None:
        self.radios: dict[RadioRef, RadioState] = {}
        self.history: dict[RadioRef, History] = {}
        self.shared: dict[int, bool] = {}
        self.busses: dict[RadioRef, frozenset[int]] = {}
        self.partners: dict[RadioRef, RadioRef] = {}
        self.alt_active: dict[RadioRef, frozenset[RadioRef] | None] = {}
        self.relay_on: frozenset[int] = frozenset()
        """Relay functions switched on (function IDs)."""
        self.relay_auto_off: frozenset[int] = frozenset()
        """Relay functions with "S" that an antenna change switched off."""
        self.extra_on: frozenset[int] = frozenset()
        self.latched: frozenset[int] = frozenset()
        """Relays turned on by a ``Set`` at the start of a transmission (6.10.4)."""
        self.stored: dict[RadioRef, tuple[int | None, int | None]] = {}
        self.running = True
        self.ports_tr: dict[tuple[int, int], bool] = {}
        """Last T/R event per (switch, port): True while transmitting."""
        self.now = 0.0
        self.why: dict[RadioRef, Why] = {}
        """The reason for each radio's antennas (recorded where they were decided)."""
        self.held: dict[RadioRef, str] = {}
        """Radios whose antennas an operator holds against frequency changes, and who
        holds them ("AetherSDR at 192.168.1.20"): their frequency is kept, no selection."""
        self.held_since: dict[RadioRef, float] = {}
        """When each hold began, in seconds since the epoch (the wall clock of the one
        who asked), for people: "held since 14:32".  Not the engine's clock."""

    def clone(self) -> State:
        c = State.__new__(State)
        c.radios = dict(self.radios)
        c.history = dict(self.history)
        c.shared = dict(self.shared)
        c.busses = dict(self.busses)
        c.partners = dict(self.partners)
        c.alt_active = dict(self.alt_active)
        c.relay_on = self.relay_on
        c.relay_auto_off = self.relay_auto_off
        c.extra_on = self.extra_on
        c.latched = self.latched
        c.stored = dict(self.stored)
        c.running = self.running
        c.ports_tr = dict(self.ports_tr)
        c.now = self.now
        c.why = dict(self.why)
        c.held = dict(self.held)
        c.held_since = dict(self.held_since)
        return c

    def remember(self, ref: RadioRef, band: Segment,
                 pair: tuple[int | None, int | None]) -> None:
        old = self.history.get(ref, {})
        if old.get(band) != pair:
            new = dict(old)
            new[band] = pair
            self.history[ref] = new


__all__ = ["History", "RadioState", "State"]
