"""The configuration as frozen, typed objects: one class per group of chapter 6.

Names follow the manual's keys (``LowerFrequency`` becomes ``lower``,
``ShortName`` becomes ``short_name``).  Frequencies are in kHz.  Defaults are
the manual's; where the manual is silent the default is written beside the
field and in ``docs/configuration.md``.  ``None`` for a station or radio in a
Control, Layout or RelativeAntennas group means "every station" or "every
radio".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import NamedTuple

from . import relays as relay_numbers
from .rigs import FlexRadioEntry, OtrspPort, RigDaemon


class RotatorControl(str, Enum):
    """How a rotator is driven (6.9, plus Rotator Genius and Hamlib)."""

    SERIAL = "Serial"
    ELECTRICAL = "Electrical"
    TEST = "Test"
    ROTATOR_GENIUS = "RotatorGenius"
    HAMLIB = "Hamlib"


class ButtonType(str, Enum):
    ANTENNA = "Antenna"
    FUNCTION = "Function"


FUNCTION_NAMES = (
    "AntennaSwap", "RXTX", "Store", "Recall", "Share",
    "Relay", "Inhibit", "Extra", "Partner", "AltActive",
)
"""The functions the server knows by name (6.6)."""


@dataclass(frozen=True, slots=True)
class FrequencyRange:
    """A closed range in kHz; ``None`` on either side means unbounded."""

    lower: float | None = None
    upper: float | None = None

    def contains(self, khz: float) -> bool:
        return (self.lower is None or khz >= self.lower) and (
            self.upper is None or khz <= self.upper
        )

    @property
    def unbounded(self) -> bool:
        return self.lower is None and self.upper is None


ALL_FREQUENCIES = FrequencyRange()


@dataclass(frozen=True, slots=True)
class TemplateInfo:
    """What an antenna template says of one frequency range: elements, 3 dB beamwidth, lobes."""

    range: FrequencyRange = ALL_FREQUENCIES
    elements: int | None = None
    beamwidth_3db: float | None = None
    lobes: int | None = None


@dataclass(frozen=True, slots=True)
class Template:
    """An antenna template: maker and model, and what it is on each of its ranges."""

    name: str
    manufacturer: str = ""
    model: str = ""
    type: str = ""
    info: tuple[TemplateInfo, ...] = ()


@dataclass(frozen=True, slots=True)
class StationRelays:
    """The relays that connect one station/radio to an antenna (6.4.2)."""

    station: int | None = None
    radio: int | None = None
    radio_rx_antenna: bool = False
    relays: frozenset[int] = frozenset()
    rx_relays: frozenset[int] | None = None
    """Relays when receiving on this antenna, if different from ``relays``."""
    persistent_relays: frozenset[int] = frozenset()

    def applies_to(self, station: int, radio: int) -> bool:
        return (self.station is None or self.station == station) and (
            self.radio is None or self.radio == radio
        )


@dataclass(frozen=True, slots=True)
class ControlRange:
    """One frequency range of an antenna and its relays per station (6.4.1)."""

    range: FrequencyRange = ALL_FREQUENCIES
    stations: tuple[StationRelays, ...] = ()


@dataclass(frozen=True, slots=True)
class Antenna:
    """An antenna (or an additive one made of others), its names, flags and relays per range."""

    id: int
    display_name: str = ""
    template: str = ""
    short_name: str = ""
    long_name: str = ""
    enabled: bool = True
    rx_only: bool = False
    tx_only: bool = False
    no_select: bool = False
    inhibit: bool = False
    shared_tx: bool = False
    in_use: tuple[int, ...] = ()
    """The additive antennas this one is made of (5.3); empty for a single antenna."""
    rotator: int | None = None
    offset: int = 0
    alternate: tuple[int, ...] = ()
    conflicts: tuple[int, ...] = ()
    fast: tuple[int, ...] = ()
    control: tuple[ControlRange, ...] = ()

    @property
    def label(self) -> str:
        """The name shown on a button."""
        return self.short_name or self.long_name or self.display_name or f"Antenna {self.id}"

    @property
    def title(self) -> str:
        """The name shown on a display line."""
        return self.long_name or self.short_name or self.display_name or f"Antenna {self.id}"


@dataclass(frozen=True, slots=True)
class System:
    """A system of antennas (stacks, arrays): its member antennas and systems by kind."""

    id: int
    display_name: str = ""
    antenna_count: int | None = None
    additive_antennas: tuple[int, ...] = ()
    exclusive_antennas: tuple[int, ...] = ()
    shared_antennas: tuple[int, ...] = ()
    additive_systems: tuple[int, ...] = ()
    exclusive_systems: tuple[int, ...] = ()
    shared_systems: tuple[int, ...] = ()
    shared: bool = False
    """Initial state of sharing (the Share function toggles it)."""

    @property
    def member_antennas(self) -> tuple[int, ...]:
        return self.additive_antennas + self.exclusive_antennas + self.shared_antennas

    @property
    def member_systems(self) -> tuple[int, ...]:
        return self.additive_systems + self.exclusive_systems + self.shared_systems


@dataclass(frozen=True, slots=True)
class Function:
    """A function button's action (one of :data:`FUNCTION_NAMES`) with its parameters."""

    id: int
    name: str
    """One of :data:`FUNCTION_NAMES`."""
    display_name: str = ""
    short_name: str = ""
    long_name: str = ""
    int_params: tuple[int, ...] = ()
    string_params: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        return self.short_name or self.long_name or self.display_name or self.name


@dataclass(frozen=True, slots=True)
class Button:
    """One button of a layout's matrix: where it sits and the antenna, system or function it is."""

    row: int
    column: int
    type: ButtonType
    id: int


@dataclass(frozen=True, slots=True)
class MatrixEntry:
    """The buttons a layout shows on one frequency range."""

    range: FrequencyRange = ALL_FREQUENCIES
    buttons: tuple[Button, ...] = ()


@dataclass(frozen=True, slots=True)
class Layout:
    """A button layout: its size, the station and radio it is for, and its matrix by range."""

    rows: int = 0
    columns: int = 0
    station: int | None = None
    radio: int | None = None
    matrix: tuple[MatrixEntry, ...] = ()


@dataclass(frozen=True, slots=True)
class RelativeRange:
    """The antennas (and receive antennas) a radio may use on one frequency range."""

    range: FrequencyRange = ALL_FREQUENCIES
    ids: tuple[int, ...] = ()
    rx_ids: tuple[int, ...] | None = None


@dataclass(frozen=True, slots=True)
class RelativeAntennas:
    """The antennas one station and radio may use, by frequency range."""

    station: int | None = None
    radio: int | None = None
    antennas: tuple[RelativeRange, ...] = ()


@dataclass(frozen=True, slots=True)
class Rotator:
    """A rotator: its names, travel, the controller that drives it and how to reach it."""

    id: int
    short_name: str = ""
    long_name: str = ""
    invisible: bool = False
    ccw_limit: int = 0
    rotation: int = 360
    has_stop: bool = False
    control: RotatorControl = RotatorControl.TEST
    address: str = "127.0.0.1"
    """Serial: the computer running MOAS Rotator.  RotatorGenius: ``host[:port]``
    (port 9006 by default).  Hamlib: ``host[:port]`` of rotctld (4533)."""
    comm_port: str = ""
    model: str = ""
    poll: int = 1000
    """Milliseconds between position polls."""
    port: int = 1
    """RotatorGenius: which of the controller's two rotators (1 or 2)."""
    rotctld_port: int | None = None
    """When set, a rotctld-compatible listener for this rotator on that TCP port."""
    park_heading: int | None = None
    """Where the rotctld listener's park (``K``) turns it; None: it cannot park."""

    @property
    def label(self) -> str:
        return self.short_name or self.long_name or f"Rotator {self.id}"


class RadioRef(NamedTuple):
    """A station and radio number pair."""

    station: int
    radio: int

    def __str__(self) -> str:
        return f"station {self.station} radio {self.radio}"


@dataclass(frozen=True, slots=True)
class SwitchPort:
    """A port of a switch a radio is wired to."""

    switch: int
    port: int


@dataclass(frozen=True, slots=True)
class AlternateRule:
    """6.10.2: receive on ``antenna`` instead of one of ``this_antennas`` while
    another station transmits on one of ``other_antennas`` in ``range``."""

    range: FrequencyRange = ALL_FREQUENCIES
    this_antennas: tuple[int, ...] = ()
    other_antennas: tuple[int, ...] = ()
    antenna: int | None = None


@dataclass(frozen=True, slots=True)
class TransmitRelays:
    """6.10.4: relays set during transmit (Extra) or on the start of transmit (Set/Reset)."""

    range: FrequencyRange = ALL_FREQUENCIES
    extra: frozenset[int] = frozenset()
    set: frozenset[int] = frozenset()
    reset: frozenset[int] = frozenset()


@dataclass(frozen=True, slots=True)
class Radio:
    """A radio of a station: the switch ports it is wired to and its rules with other radios."""

    station: int
    radio: int
    switches: tuple[SwitchPort, ...] = ()
    sub_receiver: int | None = None
    persist_sub_receiver: bool = False
    use_main_freq: bool = False
    alt_receiver: int | None = None
    interrupt: bool = False
    interrupt_mode_delay: int | None = None
    always: tuple[RadioRef, ...] = ()
    same_band: tuple[RadioRef, ...] = ()
    partner: tuple[RadioRef, ...] = ()
    inhibit_buss: tuple[int, ...] = ()
    alternate: tuple[AlternateRule, ...] = ()
    alt_active: tuple[RadioRef, ...] = ()
    out_of_band: bool = False
    inhibit_only_on_transmit: bool = False
    relays: tuple[TransmitRelays, ...] = ()

    @property
    def ref(self) -> RadioRef:
        return RadioRef(self.station, self.radio)


@dataclass(frozen=True, slots=True)
class Switch:
    """A MOAS II switch: the serial port (or the built-in emulator) and how it is driven."""

    id: int
    port: str
    """``"emulator"`` for the built-in emulator, otherwise a serial port name."""
    type: str = "MOAS II"
    method: str = "Serial"
    echo: int | None = None
    inhibit_time: int = 20
    interrupt_mode_delay: int = 0
    indicate_tr: bool = False

    @property
    def first_relay(self) -> int:
        return relay_numbers.first_relay(self.id)

    def owns_relay(self, relay: int) -> bool:
        return relay_numbers.owns_relay(self.id, relay)


@dataclass(frozen=True, slots=True)
class N1MMStation:
    """An N1MM Logger+ computer, by address or station name, and the station it is."""

    address: str = ""
    station: int = 0
    station_name: str = ""
    """N1MM's StationName (the sending computer's name): maps the station when the address
    changes (DHCP).  Either this or ``address`` may be empty."""


@dataclass(frozen=True, slots=True)
class WinTestStation:
    """A Win-Test computer, by the station name it broadcasts, and the radio it runs."""

    station_name: str = ""
    station: int = 0
    radio: int = 1


@dataclass(frozen=True, slots=True)
class Config:
    """A whole, valid configuration file."""

    path: Path | None = None
    templates: tuple[Template, ...] = ()
    antennas: tuple[Antenna, ...] = ()
    systems: tuple[System, ...] = ()
    functions: tuple[Function, ...] = ()
    layouts: tuple[Layout, ...] = ()
    relative_antennas: tuple[RelativeAntennas, ...] = ()
    rotators: tuple[Rotator, ...] = ()
    radios: tuple[Radio, ...] = ()
    switches: tuple[Switch, ...] = ()
    tcp_port: int = 12059
    udp_port: int = 12060
    web_port: int | None = None
    """The browser client's port; ``None``: no browser client."""
    ag_port: int | None = None
    """The Antenna Genius API's first port (docs/antenna-genius.md); ``None``: not served."""
    use_n1mm_logger: bool = False
    n1mm_logger: tuple[N1MMStation, ...] = ()
    use_dxlog: bool = False
    """Also listen for DXLog.net's RadioInfo on ``dxlog_port`` (mapped by ``n1mm_logger``)."""
    dxlog_port: int = 12060
    use_wintest: bool = False
    wintest_port: int = 9871
    wintest: tuple[WinTestStation, ...] = ()
    use_n1mm_rotor: bool = False
    """Serve N1MM's rotor window: commands on ``n1mm_rotor_port``, headings to
    ``n1mm_rotor_headings`` (``host:port`` texts)."""
    n1mm_rotor_port: int = 12040
    n1mm_rotor_headings: tuple[str, ...] = ()
    rigctld: tuple[RigDaemon, ...] = ()
    """Hamlib rig daemons the server polls, one radio each (``Rigctld``)."""
    flrig: tuple[RigDaemon, ...] = ()
    otrsp: tuple[OtrspPort, ...] = ()
    """Serial ports an SO2R logger writes OTRSP to (``OTRSP``)."""
    flex_radios: tuple[FlexRadioEntry, ...] = ()
    """FlexRadio radios whose slices feed this station's radios (``FlexRadios``)."""
    protect_same_band: bool = False
    start_moas_rotator: bool = True
    client_allow: tuple[str, ...] | None = None
    """Addresses or networks allowed to connect; ``None`` means loopback and private networks."""
    _index: dict[str, dict[object, object]] = field(
        default_factory=dict, compare=False, repr=False
    )

    def __post_init__(self) -> None:
        self._index["antenna"] = {a.id: a for a in self.antennas}
        self._index["system"] = {s.id: s for s in self.systems}
        self._index["function"] = {f.id: f for f in self.functions}
        self._index["rotator"] = {r.id: r for r in self.rotators}
        self._index["radio"] = {r.ref: r for r in self.radios}
        self._index["switch"] = {s.id: s for s in self.switches}

    def antenna(self, antenna_id: int) -> Antenna | None:
        return self._index["antenna"].get(antenna_id)  # type: ignore[return-value]

    def system(self, system_id: int) -> System | None:
        return self._index["system"].get(system_id)  # type: ignore[return-value]

    def function(self, function_id: int) -> Function | None:
        return self._index["function"].get(function_id)  # type: ignore[return-value]

    def rotator(self, rotator_id: int) -> Rotator | None:
        return self._index["rotator"].get(rotator_id)  # type: ignore[return-value]

    def radio(self, station: int, radio: int) -> Radio | None:
        return self._index["radio"].get(RadioRef(station, radio))  # type: ignore[return-value]

    def switch(self, switch_id: int) -> Switch | None:
        return self._index["switch"].get(switch_id)  # type: ignore[return-value]

    @property
    def name(self) -> str:
        return self.path.name if self.path else "(unsaved)"


__all__ = [
    "ALL_FREQUENCIES",
    "FUNCTION_NAMES",
    "AlternateRule",
    "Antenna",
    "Button",
    "ButtonType",
    "Config",
    "ControlRange",
    "FrequencyRange",
    "Function",
    "Layout",
    "MatrixEntry",
    "N1MMStation",
    "Radio",
    "RadioRef",
    "RelativeAntennas",
    "RelativeRange",
    "Rotator",
    "RotatorControl",
    "StationRelays",
    "Switch",
    "SwitchPort",
    "System",
    "Template",
    "TemplateInfo",
    "TransmitRelays",
    "WinTestStation",
]
