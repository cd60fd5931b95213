"""What clients are shown: radios, antennas and button layouts, in the client
protocol's shapes (``to_dict()`` gives the JSON object of the protocol)."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from .why import Why


def utc_text(seconds: float) -> str:
    """A moment as the client protocol gives it: ISO 8601 in UTC to the second
    (``2026-11-29T08:14:03Z``)."""
    return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


@dataclass(frozen=True, slots=True)
class RadioView:
    """One entry of the protocol's ``radios`` list."""

    station: int
    radio: int
    khz: float | None = None
    tx_khz: float | None = None
    tx: int | None = None
    rx: int | None = None
    alt: int | None = None
    transmitting: bool = False
    inhibited: bool = False
    note: str = ""
    relative: tuple[int, ...] | None = None
    """The radio's relative antenna list at its frequency (antenna IDs), if it has one."""
    radio_rx_antenna: bool = False
    """The receive antenna is wired to the radio's own RX-antenna input (6.4
    ``RadioRXAntenna``): a client controlling the radio switches that input on."""
    why: Why | None = None
    """Why the radio has these antennas (None before any decision)."""
    held_by: str | None = None
    """Who holds this radio's antennas against frequency changes (:meth:`Engine.hold`),
    None when its antennas follow its frequency."""
    held_since: float | None = None
    """When that hold began, seconds since the epoch (None: not held, or not known)."""
    alt_why: str = ""
    """Why the radio has no alternate receive antenna while a radio transmitting would
    switch it to one ("" when it has one, or needs none): the 5.13 condition that fails,
    the radio using the antenna, ... (sent as ``alt_why`` when not empty)."""

    def to_dict(self) -> dict[str, Any]:
        out = {
            "station": self.station, "radio": self.radio, "khz": self.khz,
            "tx_khz": self.tx_khz, "tx": self.tx, "rx": self.rx, "alt": self.alt,
            "transmitting": self.transmitting, "inhibited": self.inhibited, "note": self.note,
            "relative": None if self.relative is None else list(self.relative),
            "radio_rx_antenna": self.radio_rx_antenna,
            "why": None if self.why is None else self.why.to_dict(full=False),
            "held_by": self.held_by,
            "held_since": None if self.held_since is None else utc_text(self.held_since),
        }
        if self.alt_why:
            out["alt_why"] = self.alt_why
        return out


@dataclass(frozen=True, slots=True)
class AntennaView:
    """One entry of the protocol's ``antennas`` list."""

    id: int
    short: str
    long: str
    rotator: int | None = None
    offset: int = 0
    """Degrees between the rotator's heading and the antenna's (its mounting, 6.4)."""

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "short": self.short, "long": self.long, "rotator": self.rotator,
                "offset": self.offset}


SELECTED = "selected"
AVAILABLE = "available"
UNAVAILABLE = "unavailable"


@dataclass(frozen=True, slots=True)
class ButtonView:
    """One button as a client shows it: its place, what it is, its label and state."""

    row: int
    column: int
    type: str
    """``"Antenna"`` or ``"Function"``."""
    id: int
    label: str
    state: str
    """``selected``, ``available`` or ``unavailable``."""
    reason: str = ""
    """Why an unavailable button is unavailable: the refusal a press would get ("" else)."""

    def to_dict(self) -> dict[str, Any]:
        out = {"row": self.row, "column": self.column, "type": self.type, "id": self.id,
               "label": self.label, "state": self.state}
        if self.reason:
            out["reason"] = self.reason
        return out


@dataclass(frozen=True, slots=True)
class LayoutView:
    """The layout a client asked for: the configured one closest to its size."""

    station: int
    radio: int
    rows: int
    columns: int
    buttons: tuple[ButtonView, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"station": self.station, "radio": self.radio, "rows": self.rows,
                "columns": self.columns, "buttons": [b.to_dict() for b in self.buttons]}


__all__ = [
    "AVAILABLE",
    "SELECTED",
    "UNAVAILABLE",
    "AntennaView",
    "ButtonView",
    "LayoutView",
    "RadioView",
]
