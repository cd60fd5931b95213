"""The station a :class:`~moas_gui.testing.fake_backend.FakeBackend` pretends to run.

Plain frozen values, much smaller than a ``.moas`` configuration: antennas
with one frequency range each, radios with a starting frequency, a few
functions, layouts and relative lists, rotators and switches.
:data:`DEMO_STATION` is a two-station contest station that the tests, the
benchmark and ``python -m moas_gui.testing.fake_server`` use.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

FunctionKind = Literal["swap", "rx_tx"]
"""``swap``: exchange antennas with the other station's radio (when both cover
the other's frequency); ``rx_tx``: receive on the transmit antenna."""


@dataclass(frozen=True, slots=True)
class FakeAntenna:
    id: int
    short: str
    long: str
    low_khz: float
    high_khz: float
    rotator: int | None = None
    tx_only: bool = False
    rx_only: bool = False

    def covers(self, khz: float) -> bool:
        return self.low_khz <= khz <= self.high_khz

    def __str__(self) -> str:
        return f"Antenna {self.id} ({self.short})"


@dataclass(frozen=True, slots=True)
class FakeRadio:
    station: int
    radio: int
    khz: float
    tx: int | None = None
    rx: int | None = None


@dataclass(frozen=True, slots=True)
class FakeFunction:
    id: int
    name: str
    kind: FunctionKind


@dataclass(frozen=True, slots=True)
class FakeButton:
    row: int
    column: int
    type: Literal["Antenna", "Function"]
    id: int


@dataclass(frozen=True, slots=True)
class FakeMatrix:
    """Buttons shown while the radio's frequency is in the range (always, without one)."""

    buttons: tuple[FakeButton, ...]
    low_khz: float | None = None
    high_khz: float | None = None

    def holds(self, khz: float) -> bool:
        if self.low_khz is None or self.high_khz is None:
            return True
        return self.low_khz <= khz <= self.high_khz


@dataclass(frozen=True, slots=True)
class FakeLayout:
    rows: int
    columns: int
    matrix: tuple[FakeMatrix, ...]
    station: int | None = None
    radio: int | None = None


@dataclass(frozen=True, slots=True)
class FakeRelative:
    """A relative antenna list for a frequency range."""

    low_khz: float
    high_khz: float
    ids: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class FakeRotator:
    id: int
    short: str
    heading: float = 0.0
    online: bool = True


@dataclass(frozen=True, slots=True)
class FakeStation:
    name: str
    antennas: tuple[FakeAntenna, ...]
    radios: tuple[FakeRadio, ...]
    functions: tuple[FakeFunction, ...] = ()
    layouts: tuple[FakeLayout, ...] = ()
    relative: tuple[FakeRelative, ...] = ()
    rotators: tuple[FakeRotator, ...] = ()
    switches: tuple[int, ...] = (1,)


def _buttons(kind: Literal["Antenna", "Function"], *cells: tuple[int, int, int]) -> tuple[
    FakeButton, ...
]:
    return tuple(FakeButton(row, column, kind, ident) for row, column, ident in cells)


DEMO_STATION = FakeStation(
    name="fake two-station.moas",
    antennas=(
        FakeAntenna(1, "Tribander", "TH6 tribander", 14000, 29700, rotator=1),
        FakeAntenna(2, "20 Stack", "20m stack all", 14000, 14350, rotator=2),
        FakeAntenna(3, "40 Beam", "40m 2-element Yagi", 7000, 7300, rotator=3),
        FakeAntenna(4, "40 Dipole", "40m inverted V", 7000, 7300),
        FakeAntenna(5, "80 Vert", "80m vertical", 3500, 4000),
        FakeAntenna(6, "Bev NE", "Beverage north-east", 1800, 7300, rx_only=True),
        FakeAntenna(7, "Bev SE", "Beverage south-east", 1800, 7300, rx_only=True),
        FakeAntenna(8, "Amp Load", "Dummy load", 1800, 29700, tx_only=True),
    ),
    radios=(
        FakeRadio(1, 1, 14025.0, tx=2, rx=2),
        FakeRadio(2, 1, 7025.0, tx=3, rx=3),
    ),
    functions=(FakeFunction(0, "Swap", "swap"), FakeFunction(1, "RX=TX", "rx_tx")),
    layouts=(
        FakeLayout(
            4, 3,
            (
                FakeMatrix(_buttons("Antenna", (0, 0, 2), (0, 1, 1)), 14000, 14350),
                FakeMatrix(_buttons("Antenna", (0, 0, 1)), 14351, 29700),
                FakeMatrix(_buttons("Antenna", (0, 0, 3), (0, 1, 4), (1, 0, 6), (1, 1, 7)),
                           7000, 7300),
                FakeMatrix(_buttons("Antenna", (0, 0, 5), (1, 0, 6), (1, 1, 7)), 3500, 4000),
                FakeMatrix(_buttons("Function", (3, 0, 0), (3, 1, 1))),
            ),
        ),
        FakeLayout(
            1, 10,
            (
                FakeMatrix(_buttons("Antenna", (0, 0, 2), (0, 1, 1)), 14000, 14350),
                FakeMatrix(_buttons("Antenna", (0, 0, 3), (0, 1, 4)), 7000, 7300),
                FakeMatrix(_buttons("Antenna", (0, 0, 5)), 3500, 4000),
            ),
        ),
    ),
    relative=(
        FakeRelative(14000, 14350, (2, 1)),
        FakeRelative(7000, 7300, (3, 4)),
        FakeRelative(3500, 4000, (5,)),
    ),
    rotators=(
        FakeRotator(1, "Tribander", 0.0),
        FakeRotator(2, "20 Stack", 45.0),
        FakeRotator(3, "40 Beam", 300.0, online=False),
    ),
)


__all__ = [
    "DEMO_STATION",
    "FakeAntenna",
    "FakeButton",
    "FakeFunction",
    "FakeLayout",
    "FakeMatrix",
    "FakeRadio",
    "FakeRelative",
    "FakeRotator",
    "FakeStation",
    "FunctionKind",
]
