"""The rig sources the server runs itself: rigctld, flrig and OTRSP entries, and their checks.

``"Rigctld"`` and ``"Flrig"`` list rig daemons the server polls, one radio each;
``"OTRSP"`` lists serial ports an SO2R logger writes OTRSP to.  Their names
are those of ``moas-client --source KIND[:OPTIONS]`` (docs/sources.md):

=============================  ==========================================
configuration                  command line
=============================  ==========================================
``"Address": "host:4534"``     ``rigctld:host:4534`` (the item without ``=``)
``"Port": "/dev/ttyUSB1"``     ``otrsp:/dev/ttyUSB1``
``"Station": 1``               ``station=1``
``"Radio": 2``                 ``radio=2``
``"Rate": 5``                  ``rate=5`` (polls a second)
``"Retry": 2``                 ``retry=2`` (seconds before the first new attempt)
``"Radio1"``, ``"Radio2"``     ``radio1=``, ``radio2=``
``"AUX1": [{"Value": 3,        ``ant1.3=5``
"Antenna": 5}]``
=============================  ==========================================

``"FlexRadios"`` lists FlexRadio 6000/8000 radios whose slices the server
follows (``moas-server --flex``, docs/sources.md): ``"Address"`` is the radio's
address, serial number or nickname, ``"Slices"`` which slice feeds which radio
(``"A=1/1,B=1/2"``, as ``--flex-radios``); without it the transmitting slice is
``"Station"``'s radio 1 and the other slice in use its radio 2.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from .reading import Reading

if TYPE_CHECKING:
    from .model import Config

RIGCTLD_PORT: Final = 4532
"""Hamlib's rigctld listens here unless told otherwise (``-t``)."""
FLRIG_PORT: Final = 12345
"""flrig's XML-RPC server port."""
DEFAULT_RATE: Final = 10.0
"""Polls a second when an entry gives no ``Rate``."""
LOWEST_RATE: Final = 0.1
HIGHEST_RATE: Final = 100.0
DEFAULT_RETRY: Final = 0.5
"""Seconds before the first new attempt after a daemon or port went away (then doubling
up to 10 s) when an entry gives no ``Retry``."""
LOWEST_RETRY: Final = 0.01
HIGHEST_RETRY: Final = 10.0


def split_address(text: str, default_port: int) -> tuple[str, int]:
    """``[HOST:]PORT`` (or ``HOST:``, or nothing) to a host and port; loopback when no host.

    :class:`ValueError` saying what is wrong when the port is not 1-65535."""
    host, colon, port = text.strip().rpartition(":")
    if not colon:
        host, port = "", text.strip()
    port = port.strip()
    if not port:
        return host or "127.0.0.1", default_port
    if not port.isascii() or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ValueError(f"port {port!r} is not between 1 and 65535")
    return host or "127.0.0.1", int(port)


@dataclass(frozen=True, slots=True)
class RigDaemon:
    """A rig daemon (rigctld or flrig) the server polls for one radio."""

    station: int
    radio: int = 1
    address: str = ""
    """``[HOST:]PORT``; empty: the daemon's default port on this computer."""
    rate: float = DEFAULT_RATE
    """Polls a second (0.1 to 100)."""
    retry: float = DEFAULT_RETRY
    """Seconds before the first new attempt after the daemon went away (0.01 to 10)."""
    enabled: bool = True


@dataclass(frozen=True, slots=True)
class AuxAntennaEntry:
    """OTRSP AUX value ``value`` of one radio selects antenna ``antenna``."""

    value: int
    antenna: int


@dataclass(frozen=True, slots=True)
class OtrspPort:
    """A serial port an SO2R logger writes OTRSP to, and what its radios and AUX values are."""

    station: int
    port: str
    radio1: int = 1
    """This station's radio that OTRSP calls radio 1."""
    radio2: int = 2
    aux1: tuple[AuxAntennaEntry, ...] = ()
    """Radio 1's AUX values and the antennas they select."""
    aux2: tuple[AuxAntennaEntry, ...] = ()
    retry: float = DEFAULT_RETRY
    """Seconds before the first new attempt after the port went away (0.01 to 10)."""
    enabled: bool = True

    def antennas(self) -> dict[tuple[int, int], int]:
        """(OTRSP radio 1 or 2, AUX value) to antenna ID."""
        table = {(1, e.value): e.antenna for e in self.aux1}
        table.update({(2, e.value): e.antenna for e in self.aux2})
        return table


@dataclass(frozen=True, slots=True)
class FlexRadioEntry:
    """A FlexRadio whose slices feed this server's radios (``FlexRadios``)."""

    address: str
    """``host[:port]``, the radio's serial number or its nickname."""
    station: int = 1
    """Without ``slices``: the station whose radio 1 follows the transmitting slice and
    radio 2 the other slice in use."""
    slices: str = ""
    """``A=1/1,B=1/2``: slice letter to station/radio; empty: by transmit, as above."""
    retry: float = DEFAULT_RETRY
    enabled: bool = True


def parse_slice_map(text: str) -> dict[str, tuple[int, int]]:
    """``A=1/1,B=1/2`` to ``{"A": (1, 1), "B": (1, 2)}``; :class:`ValueError` saying what is
    wrong."""
    table: dict[str, tuple[int, int]] = {}
    for item in (i.strip() for i in text.split(",")):
        if not item:
            continue
        letter, eq, ref = item.partition("=")
        letter = letter.strip().upper()
        station, slash, radio = ref.strip().partition("/")
        if not eq or len(letter) != 1 or not letter.isalpha() or not letter.isascii():
            raise ValueError(f"{item!r}: write a slice letter and a radio, such as A=1/1")
        if not slash or not station.isdigit() or not radio.isdigit() \
                or not 1 <= int(station) <= 999 or not 1 <= int(radio) <= 999:
            raise ValueError(f"{item!r}: the radio is written station/radio, such as 1/2")
        if letter in table:
            raise ValueError(f"slice {letter} is given twice")
        table[letter] = (int(station), int(radio))
    if not table:
        raise ValueError("no slice given; write A=1/1,B=1/2")
    return table


def check_flex_radios(config: Config, reading: Reading) -> None:
    """Report what is wrong with the ``FlexRadios`` entries, at their place."""
    radios = {(r.station, r.radio) for r in config.radios}
    seen: dict[str, FlexRadioEntry] = {}
    for entry in config.flex_radios:
        label = "this FlexRadios entry"
        name = entry.address.strip()
        if not name:
            reading.error(reading.at(entry, "Address"), f"\"Address\" of {label} is empty; "
                          "write the radio's address, serial number or nickname")
        elif name.casefold() in seen and entry.enabled and seen[name.casefold()].enabled:
            line = getattr(reading.at(seen[name.casefold()]), "line", "?")
            reading.warning(reading.at(entry, "Address"), f"{label} reads \"{name}\" again "
                            f"(also on line {line})")
        seen.setdefault(name.casefold(), entry)
        if entry.slices.strip():
            try:
                table = parse_slice_map(entry.slices)
            except ValueError as exc:
                reading.error(reading.at(entry, "Slices"), f"\"Slices\" of {label}: {exc}")
                continue
            wanted = sorted(set(table.values()))
        else:
            wanted = [(entry.station, 1)]
        for station, radio in wanted:
            if (station, radio) not in radios:
                reading.error(reading.at(entry, "Slices" if entry.slices.strip() else "Station"),
                              f"{label} feeds station {station} radio {radio}, which is not "
                              "in \"Radios\"")


def check_rig_sources(config: Config, reading: Reading) -> None:
    """Report what is wrong with the ``Rigctld``, ``Flrig`` and ``OTRSP`` entries, at their place."""
    radios = {(r.station, r.radio) for r in config.radios}
    stations = {station for station, _ in radios}
    antennas = {a.id for a in config.antennas}
    for key, entries, default_port in (("Rigctld", config.rigctld, RIGCTLD_PORT),
                                       ("Flrig", config.flrig, FLRIG_PORT)):
        polled: dict[tuple[str, int], RigDaemon] = {}
        for entry in entries:
            label = f"this {key} entry"
            if (entry.station, entry.radio) not in radios:
                reading.error(reading.at(entry, "Radio" if reading_has(reading, entry, "Radio")
                                         else "Station"),
                              f"{label} names station {entry.station} radio {entry.radio}, "
                              "which is not in \"Radios\"")
            try:
                where = split_address(entry.address, default_port)
            except ValueError as exc:
                reading.error(reading.at(entry, "Address"), f"\"Address\" of {label} is "
                              f"\"{entry.address}\": {exc}; write [host:]port, such as "
                              f"127.0.0.1:{default_port}")
                continue
            first = polled.setdefault(where, entry)
            if first is not entry and entry.enabled and first.enabled:
                line = getattr(reading.at(first), "line", "?")
                reading.warning(reading.at(entry, "Address"), f"{label} polls "
                                f"{where[0]}:{where[1]} again (also on line {line}); one rig "
                                "daemon serves one radio")
    _check_otrsp(config, reading, radios, stations, antennas)
    check_flex_radios(config, reading)


def _check_otrsp(config: Config, reading: Reading, radios: set[tuple[int, int]],
                 stations: set[int], antennas: set[int]) -> None:
    switch_ports = {s.port.strip().casefold(): s.id for s in config.switches}
    opened: dict[str, OtrspPort] = {}
    for entry in config.otrsp:
        label = "this OTRSP entry"
        port = entry.port.strip()
        if not port:
            reading.error(reading.at(entry, "Port"), f"\"Port\" of {label} is empty; write the "
                          "serial port the logger writes OTRSP to, such as \"COM7\" or "
                          "\"/dev/ttyUSB1\"")
        elif port.casefold() in switch_ports:
            reading.error(reading.at(entry, "Port"), f"{label}'s port \"{port}\" is switch "
                          f"{switch_ports[port.casefold()]}'s port; OTRSP needs a port of its "
                          "own (the second end of a virtual serial pair, a splitter)")
        elif port.casefold() in opened:
            line = getattr(reading.at(opened[port.casefold()]), "line", "?")
            reading.error(reading.at(entry, "Port"), f"{label}'s port \"{port}\" is read by "
                          f"another OTRSP entry too (line {line}); a port can be read once")
        else:
            opened[port.casefold()] = entry
        if entry.station not in stations:
            reading.error(reading.at(entry, "Station"), f"{label} names station "
                          f"{entry.station}, which has no radio in \"Radios\"")
            continue
        for key, radio in (("Radio1", entry.radio1), ("Radio2", entry.radio2)):
            # a radio named by default (1, 2) may be missing: an SO1R station's OTRSP
            if reading_has(reading, entry, key) and (entry.station, radio) not in radios:
                reading.error(reading.at(entry, key), f"\"{key}\" of {label} names station "
                              f"{entry.station} radio {radio}, which is not in \"Radios\"")
        if entry.radio1 == entry.radio2:
            reading.error(reading.at(entry, "Radio2" if reading_has(reading, entry, "Radio2")
                                     else "Radio1"),
                          f"{label} makes both OTRSP radios station {entry.station} radio "
                          f"{entry.radio1}; \"Radio1\" and \"Radio2\" must differ")
        for key, table in (("AUX1", entry.aux1), ("AUX2", entry.aux2)):
            seen: dict[int, AuxAntennaEntry] = {}
            for aux in table:
                if aux.antenna not in antennas:
                    reading.error(reading.at(aux, "Antenna"), f"{key} value {aux.value} of "
                                  f"{label} selects antenna {aux.antenna}, which is not in "
                                  "\"Antennas\"")
                if aux.value in seen and seen[aux.value].antenna != aux.antenna:
                    line = getattr(reading.at(seen[aux.value]), "line", "?")
                    reading.error(reading.at(aux, "Value"), f"{key} value {aux.value} of "
                                  f"{label} is given twice (also on line {line}), for "
                                  f"antennas {seen[aux.value].antenna} and {aux.antenna}")
                seen.setdefault(aux.value, aux)


def reading_has(reading: Reading, obj: object, key: str) -> bool:
    """Whether the group ``obj`` was read from names ``key`` (not left to its default)."""
    node = reading.node_of(obj)
    return node is not None and node.get(key) is not None


__all__ = [
    "DEFAULT_RATE", "DEFAULT_RETRY", "FLRIG_PORT", "HIGHEST_RATE", "HIGHEST_RETRY",
    "LOWEST_RATE", "LOWEST_RETRY", "RIGCTLD_PORT",
    "AuxAntennaEntry", "FlexRadioEntry", "OtrspPort", "RigDaemon", "check_flex_radios",
    "check_rig_sources", "parse_slice_map", "split_address",
]
