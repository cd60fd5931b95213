"""What the Antenna Genius API's numbers stand for in a MOAS station.

* **Bands**: the AG numbers 16 bands (0 = none).  This server's are fixed: the HF
  amateur bands from 160 m to 6 m with the WARC bands (:data:`BANDS`,
  docs/antenna-genius.md has the table); 12-15 are unused.  ``band=B`` from a client
  is the middle of band B.
* **Antennas**: the configuration's antennas in its order, numbered from 1 whatever
  their IDs; names with ``_`` for spaces; ``tx``/``rx`` masks (bit N = band N) from
  the frequency ranges each antenna's relays are defined for, RX-only antennas with no
  ``tx`` bits, TX-only ones with no ``rx`` bits.
* **Ports**: an AG device has two radio ports, A (1) and B (2).  The station's main
  radios are served two by two: by default the first two; ``--ag-radios 1/1,2/1``
  chooses, and every further pair is one more AG device on the next TCP port, with
  its own serial number and discovery line.
"""

from __future__ import annotations

import re
import zlib
from collections.abc import Sequence
from dataclasses import dataclass

from moas_gui.config.model import ALL_FREQUENCIES, Antenna, Config, FrequencyRange, RadioRef

from .codec import name_text

PORTS_PER_DEVICE = 2


@dataclass(frozen=True, slots=True)
class AgBand:
    number: int
    name: str
    low_khz: float
    high_khz: float

    @property
    def middle_khz(self) -> float:
        return (self.low_khz + self.high_khz) / 2

    def contains(self, khz: float) -> bool:
        return self.high_khz > 0 and self.low_khz <= khz <= self.high_khz

    def text(self) -> str:
        """``band N name=... freq_start=MHz freq_stop=MHz``, as ``band list`` says it."""
        return (f"band {self.number} name={self.name} freq_start={self.low_khz / 1000:.6f} "
                f"freq_stop={self.high_khz / 1000:.6f}")


BANDS: tuple[AgBand, ...] = (
    AgBand(0, "None", 0, 0),
    AgBand(1, "160m", 1800, 2000),
    AgBand(2, "80m", 3500, 4000),
    AgBand(3, "60m", 5250, 5450),
    AgBand(4, "40m", 7000, 7300),
    AgBand(5, "30m", 10100, 10150),
    AgBand(6, "20m", 14000, 14350),
    AgBand(7, "17m", 18068, 18168),
    AgBand(8, "15m", 21000, 21450),
    AgBand(9, "12m", 24890, 24990),
    AgBand(10, "10m", 28000, 29700),
    AgBand(11, "6m", 50000, 54000),
    AgBand(12, "Unused", 0, 0),
    AgBand(13, "Unused", 0, 0),
    AgBand(14, "Unused", 0, 0),
    AgBand(15, "Unused", 0, 0),
)
"""The 16 AG bands this server defines (index = band number)."""


def band_of(khz: float | None) -> int:
    """The AG band a frequency is in; 0 when none (or no frequency)."""
    if khz is None:
        return 0
    for band in BANDS:
        if band.contains(khz):
            return band.number
    return 0


def _overlaps(span: FrequencyRange, band: AgBand) -> bool:
    low = span.lower if span.lower is not None else 0.0
    high = span.upper if span.upper is not None else float("inf")
    return low <= band.high_khz and band.low_khz <= high


def antenna_ranges(config: Config, antenna: Antenna) -> tuple[FrequencyRange, ...]:
    """Where an antenna works: the ranges its relays are defined for, else its
    template's ranges, else everywhere."""
    ranges = tuple(c.range for c in antenna.control if not c.range.unbounded)
    if ranges:
        return ranges
    for template in config.templates:
        if template.name == antenna.template and template.info:
            return tuple(i.range for i in template.info)
    return (ALL_FREQUENCIES,)


@dataclass(frozen=True, slots=True)
class AgAntenna:
    number: int
    """1-based, in the configuration's order."""
    id: int
    """The antenna's ID in the configuration."""
    name: str
    tx: int
    rx: int
    inband: int = 0
    label: str = ""
    """The antenna's button name (the engine's sentences say ``Antenna <ID> (<label>)``)."""

    @property
    def ag_name(self) -> str:
        """The name as ``antenna list`` gives it."""
        return name_text(self.name)

    def text(self) -> str:
        """``antenna N name=... tx=HHHH rx=HHHH inband=HHHH``."""
        return (f"antenna {self.number} name={name_text(self.name)} tx={self.tx:04X} "
                f"rx={self.rx:04X} inband={self.inband:04X}")


def ag_antennas(config: Config) -> tuple[AgAntenna, ...]:
    """Every antenna of the configuration as the AG numbers and describes it."""
    out = []
    for number, antenna in enumerate(config.antennas, start=1):
        mask = 0
        if antenna.enabled:
            ranges = antenna_ranges(config, antenna)
            for band in BANDS:
                if band.number and band.high_khz and any(_overlaps(r, band) for r in ranges):
                    mask |= 1 << band.number
        out.append(AgAntenna(number, antenna.id, antenna.title,
                             0 if antenna.rx_only else mask, 0 if antenna.tx_only else mask,
                             label=antenna.label))
    return tuple(out)


def main_radios(config: Config) -> tuple[RadioRef, ...]:
    """The main radios, in the configuration's order (not sub or alternate receivers)."""
    extra = set()
    for radio in config.radios:
        for number in (radio.sub_receiver, radio.alt_receiver):
            if number is not None:
                extra.add(RadioRef(radio.station, number))
    return tuple(r.ref for r in config.radios if r.ref not in extra)


def parse_radios(text: str) -> tuple[RadioRef, ...]:
    """``1/1,2/1`` as radios; raises ValueError saying which part is wrong."""
    out = []
    for part in text.split(","):
        station, slash, radio = part.strip().partition("/")
        if not slash or not station.isdigit() or not radio.isdigit():
            raise ValueError(f"{part.strip()!r} is not STATION/RADIO (as 1/1)")
        out.append(RadioRef(int(station), int(radio)))
    if not out:
        raise ValueError("no radio given")
    return tuple(out)


@dataclass(frozen=True, slots=True)
class Device:
    """One AG device the server plays: its index (0 for the first), TCP port offset and
    the radios on its ports A and B (None: that port has no radio)."""

    index: int
    radios: tuple[RadioRef | None, ...]

    def radio(self, port: int) -> RadioRef | None:
        if 1 <= port <= len(self.radios):
            return self.radios[port - 1]
        return None

    def port_of(self, ref: RadioRef) -> int | None:
        for port, radio in enumerate(self.radios, start=1):
            if radio == ref:
                return port
        return None


def devices(config: Config, chosen: Sequence[RadioRef] | None = None) -> tuple[Device, ...]:
    """The AG devices for a station: ``chosen`` radios (``--ag-radios``) two by two, or
    the first two main radios.  Raises ValueError for a chosen radio the station has
    not."""
    mains = main_radios(config)
    if chosen is None:
        radios: Sequence[RadioRef] = mains[:PORTS_PER_DEVICE]
    else:
        for ref in chosen:
            if ref not in mains:
                raise ValueError(f"--ag-radios: the configuration has no main radio {ref}")
        radios = chosen
    out = []
    for index in range(0, max(len(radios), 1), PORTS_PER_DEVICE):
        pair: list[RadioRef | None] = list(radios[index:index + PORTS_PER_DEVICE])
        pair += [None] * (PORTS_PER_DEVICE - len(pair))
        out.append(Device(index // PORTS_PER_DEVICE, tuple(pair)))
    return tuple(out)


def ag_words(message: str, antennas: Sequence[AgAntenna], device: Device | None = None) -> str:
    """An engine's sentence in the AG's words: each antenna it names (``Antenna 2 (80
    Dipole)``, or its title alone) becomes ``AG antenna 3 (80_m_Dipole)``, the number and
    name ``antenna list`` gives; a radio on one of ``device``'s ports gets that port
    (``station 1 radio 2 (port 2)``)."""
    words: dict[str, str] = {}
    for antenna in antennas:
        ag = f"AG antenna {antenna.number} ({antenna.ag_name})"
        words.setdefault(f"Antenna {antenna.id} ({antenna.label})", ag)
        if antenna.name:
            words.setdefault(antenna.name, ag)
    if words:
        # the engine's ``Antenna ID (label)`` first, then titles alone, longest first
        keys = sorted(words, key=lambda k: (not k.startswith("Antenna "), -len(k)))
        pattern = re.compile("|".join(rf"(?<!\w){re.escape(k)}(?!\w)" for k in keys))
        message = pattern.sub(lambda m: words[m.group(0)], message)
    if device is not None:
        def port(m: re.Match[str]) -> str:
            found = device.port_of(RadioRef(int(m.group(1)), int(m.group(2))))
            return m.group(0) if found is None else f"{m.group(0)} (port {found})"
        message = re.sub(r"(?i)\bstation (\d+) radio (\d+)\b", port, message)
    return message


def serial_for(name: str, port: int) -> str:
    """A serial number as the AG gives one (``XX-XX-XX``), stable for a station's name
    and port, different between the devices of one server."""
    value = zlib.crc32(f"{name}:{port}".encode()) & 0xFFFFFF
    return f"{value >> 16:02X}-{(value >> 8) & 0xFF:02X}-{value & 0xFF:02X}"


__all__ = [
    "BANDS",
    "PORTS_PER_DEVICE",
    "AgAntenna",
    "AgBand",
    "Device",
    "ag_antennas",
    "ag_words",
    "antenna_ranges",
    "band_of",
    "devices",
    "main_radios",
    "parse_radios",
    "serial_for",
]
