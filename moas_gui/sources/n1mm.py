"""The N1MM Logger+ source: RadioInfo datagrams in, radio frequencies and focus out.

The built-in "N1MM Logger client" of the manual (4.1, 6.12, appendix C), in
full.  N1MM Logger+ on each station computer sends one RadioInfo datagram per
radio at least every 10 seconds and at once when a frequency, the mode or the
transmit state changes.  not1mm and DXLog.net send the same packets (see
docs/sources.md).  The listener

- maps a packet to a station by its **StationName** (the sending computer's
  name, which survives a DHCP address change) when the configuration names
  it, else by the **sender's IP address** (the ``N1MMLogger`` list), or sends
  everything to one station (``every_sender``, as ``moas-client`` does on an
  operating computer); the packet's ``RadioNr`` is that station's radio number;
- calls ``on_frequency(station, radio, khz, tx_khz)`` and hands a
  :class:`~moas_gui.sources.base.FrequencyReport` to ``on_event`` **only when
  the pair of frequencies of that radio changed** since the last call for it
  (the heartbeats repeat the same frequency); :meth:`N1MMListener.forget`
  makes the next packet of every radio count as a change (for a restart);
- hands ``on_event`` an :class:`~moas_gui.sources.base.ActiveRadio` when the
  station's ``ActiveRadioNr`` (transmit focus) changes, a
  :class:`~moas_gui.sources.base.FocusRadio` when ``FocusRadioNr`` does and a
  :class:`~moas_gui.sources.base.RunOrSearch` when a radio's ``IsRunning`` does;
- calls the optional ``on_update(update)`` for every RadioInfo from a known
  station, changed or not (transmit state, staleness, a status display);
- hands the optional ``on_contact(packet, station, radio)`` each contact packet
  (``contactinfo``, ``contactreplace``, ``contactdelete``: :mod:`.n1mm_contact`) with
  the station and radio the same mapping gives (``None, None`` when its sender maps
  to no station); a contact whose StationName matches no entry takes the station its
  sender's RadioInfo last mapped to (not1mm names its host in a contact but its
  configured station name in RadioInfo): the antenna log joins them to its journal;
- ignores packets from senders it cannot map (a debug line, at most one per
  sender a minute and ten a minute from all senders together) and counts every
  packet it refuses, by reason
  (:data:`~moas_gui.sources.n1mm_packet.REASONS`), in :meth:`N1MMListener.stats`.
  Nothing a sender does stops the listener: a callback that raises is logged
  and counted too.

When packets arrive faster than they are read, the ones waiting are read as a
burst and each radio's newest frequency is acted on once (the others are
counted as ``superseded``).  No Qt: this runs on the asyncio loop of the
window and of the headless server alike.
"""

from __future__ import annotations

import asyncio
import functools
import ipaddress
import logging
import socket
import time
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Final

from moas_gui.config.model import Config, N1MMStation
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.sources.base import (
    ActiveRadio,
    FocusRadio,
    FrequencyReport,
    RunOrSearch,
    SourceEvent,
    SourceSink,
)
from moas_gui.sources.log_bursts import CrowdLimiter
from moas_gui.sources.n1mm_contact import ContactPacket, parse_contact
from moas_gui.sources.n1mm_packet import (
    REASONS,
    N1MMPacketError,
    RadioInfo,
    parse_radio_info,
    radio_info_packet,
)
from moas_gui.sources.udp import DatagramSource

log = logging.getLogger(__name__)

DEFAULT_PORT: Final = 12060
LOG_INTERVAL: Final = 60.0
"""Seconds between two debug lines about the same sender and reason."""
SENDERS_KEPT: Final = 256
"""Senders whose RadioInfo's station is remembered for their contacts."""

FrequencyCallback = Callable[[int, int, float, float], object]
"""``on_frequency(station, radio, khz, tx_khz)``."""


@dataclass(frozen=True, slots=True)
class RadioUpdate:
    """One accepted RadioInfo packet, mapped to this server's station and radio."""

    station: int
    radio: int
    address: str
    info: RadioInfo
    changed: bool
    """True when the frequencies differ from the last ones passed on for this radio."""


UpdateCallback = Callable[[RadioUpdate], object]
ContactCallback = Callable[[ContactPacket, int | None, int | None], object]
"""``on_contact(packet, station, radio)``; station and radio are None for an unknown sender."""


@dataclass(frozen=True, slots=True)
class N1MMStats:
    """Counters since the listener was made."""

    received: int = 0
    """Every datagram, good or bad."""
    accepted: int = 0
    """RadioInfo packets from a known station with a frequency (changed or not)."""
    delivered: int = 0
    """Calls of ``on_frequency`` (accepted packets that changed a radio's frequencies)."""
    superseded: int = 0
    """Changes never passed on because a newer packet for the same radio was read
    in the same burst (only the newest frequency is acted on)."""
    no_frequency: int = 0
    """RadioInfo packets from a known station saying the radio has no frequency (``Freq`` 0)."""
    unknown_sender: int = 0
    callback_errors: int = 0
    contacts: int = 0
    """Contact packets (logged, replaced, deleted QSOs) handed to ``on_contact``."""
    refused: Mapping[str, int] = field(default_factory=dict)
    """Refused packets by reason (``not_xml``, ``not_radio_info``, ...)."""

    @property
    def malformed(self) -> int:
        """Refused packets except the other N1MM packet types, which are simply not ours."""
        return sum(n for reason, n in self.refused.items() if reason != "not_radio_info")


@functools.lru_cache(maxsize=256)
def _address_key(address: str) -> str:
    """The canonical text of an IP address (IPv4-mapped IPv6 becomes IPv4); other text as is.

    Remembered for the last 256 addresses: every datagram asks it again for its sender, and
    parsing the address cost more than parsing the RadioInfo it carried."""
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return address.strip().lower()
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        ip = ip.ipv4_mapped
    return str(ip)


def _name_key(name: str) -> str:
    """StationName is a Windows computer name: compared without case."""
    return name.strip().casefold()


def _tables(
    stations: Iterable[N1MMStation] | Mapping[str, int],
    names: Mapping[str, int] | None,
) -> tuple[dict[str, int], dict[str, int]]:
    if isinstance(stations, Mapping):
        by_address = list(stations.items())
        by_name = list((names or {}).items())
    else:
        listed = list(stations)
        by_address = [(s.address, s.station) for s in listed if s.address]
        by_name = [(s.station_name, s.station) for s in listed if s.station_name]
        by_name += list((names or {}).items())
    return (_table(by_address, _address_key, "address"), _table(by_name, _name_key, "StationName"))


def _table(pairs: Iterable[tuple[str, int]], key_of: Callable[[str], str],
           what: str) -> dict[str, int]:
    table: dict[str, int] = {}
    for text, station in pairs:
        key = key_of(text)
        if key in table and table[key] != station:
            log.warning("N1MMLogger: %s %s is listed for station %d and station %d; "
                        "using station %d", what, text, table[key], station, table[key])
            continue
        table[key] = station
    return table


class N1MMListener(DatagramSource):
    """Receives RadioInfo datagrams (N1MM Logger+, not1mm, DXLog.net) and reports radios.

    Use :meth:`start` to bind it, :meth:`close` to stop.  :meth:`handle` is the
    whole logic for one datagram, callable without a socket.
    """

    kind = "n1mm"
    label = "N1MM"
    title = "N1MM Logger"
    """How the "Listening for ..." line names the program."""

    def __init__(
        self,
        stations: Iterable[N1MMStation] | Mapping[str, int],
        on_frequency: FrequencyCallback | None = None,
        *,
        on_update: UpdateCallback | None = None,
        on_event: SourceSink | None = None,
        on_contact: ContactCallback | None = None,
        names: Mapping[str, int] | None = None,
        every_sender: int | None = None,
        port: int = DEFAULT_PORT,
        host: str = "0.0.0.0",
        label: str | None = None,
        clock: Callable[[], float] = time.monotonic,
        log_interval: float = LOG_INTERVAL,
    ) -> None:
        super().__init__()
        self._stations, self._names = _tables(stations, names)
        self._every_sender = every_sender
        self._on_frequency = on_frequency
        self._on_update = on_update
        self._on_event = on_event
        self._on_contact = on_contact
        self._contacts = 0
        self._port = port
        self._host = host
        if label is not None:
            self.label = label
        self._clock = clock
        self._limiter = LogLimiter(log_interval, clock)
        self._senders = CrowdLimiter(log_interval, clock)
        """Lines about one sender: a minute each, and a few a minute for all of them."""
        self._last: dict[tuple[int, int], tuple[float, float]] = {}
        self._heard: dict[tuple[int, int], float] = {}
        self._focus: dict[tuple[str, int], int] = {}
        self._running: dict[tuple[int, int], bool] = {}
        self._batch: dict[tuple[int, int], FrequencyReport] | None = None
        self._received = self._accepted = self._delivered = self._superseded = 0
        self._no_frequency = self._unknown = self._callback_errors = 0
        self._refused = dict.fromkeys(REASONS, 0)
        self._stations_heard: OrderedDict[str, int] = OrderedDict()
        """The station each sender's RadioInfo last mapped to (the last SENDERS_KEPT
        senders): a contact whose StationName matches no entry takes its sender's."""

    @classmethod
    def from_config(
        cls,
        config: Config,
        on_frequency: FrequencyCallback | None = None,
        *,
        on_update: UpdateCallback | None = None,
        on_event: SourceSink | None = None,
    ) -> N1MMListener:
        """A listener for the configuration's ``N1MMLogger`` list (bind it on ``config.udp_port``)."""
        return cls(config.n1mm_logger, on_frequency, on_update=on_update, on_event=on_event,
                   port=config.udp_port)

    # -- the logic ---------------------------------------------------------------

    def _station_of(self, key: str, info: RadioInfo | None, name: str = "") -> int | None:
        if self._every_sender is not None:
            return self._every_sender
        name = info.station_name if info is not None else name
        if name and self._names:
            station = self._names.get(_name_key(name))
            if station is not None:
                return station
        return self._stations.get(key)

    def handle(self, data: bytes, address: str) -> RadioUpdate | None:
        """Take one datagram from ``address``; return what it changed, if it was accepted."""
        self._received += 1
        key = _address_key(address)
        station = self._station_of(key, None)
        if station is None and not self._names:
            self._unknown_sender(address, key)
            return None
        try:
            info = parse_radio_info(data)
        except N1MMPacketError as exc:
            if exc.reason == "not_radio_info" and self._on_contact is not None \
                    and self._contact(data, key, address):
                return None
            self._refused[exc.reason] += 1
            held = self._senders.allow(exc.reason, key)
            if held is not None:
                where = address if station is None else f"{address} (station {station})"
                log.debug("%s packet from %s ignored: %s%s", self.label, where, exc,
                          held_text(held))
            return None
        station = self._station_of(key, info)
        if station is None:
            self._unknown_sender(address, key, info.station_name)
            return None
        return self._accept(station, address, info)

    def _contact(self, data: bytes, key: str, address: str) -> bool:
        """A contact packet handed to ``on_contact``: True; False for any other packet
        (counted as not ours); a bad contact packet is counted by its reason (True)."""
        try:
            packet = parse_contact(data)
        except N1MMPacketError as exc:
            if exc.reason == "not_contact":
                return False
            self._refused[exc.reason] += 1
            held = self._senders.allow(("contact", exc.reason), key)
            if held is not None:
                log.debug("%s contact packet from %s ignored: %s%s", self.label, address, exc,
                          held_text(held))
            return True
        station = self._station_of(key, None, packet.station_name)
        if station is None:  # not1mm: the host name here, its configured name in RadioInfo
            station = self._stations_heard.get(key)
        self._contacts += 1
        if self._on_contact is not None:
            self._call(self._on_contact, packet, station,
                       None if station is None else packet.radio_nr)
        return True

    def _unknown_sender(self, address: str, key: str, name: str = "") -> None:
        self._unknown += 1
        held = self._senders.allow("unknown", (key, name))
        if held is not None:
            what = (f"neither that address nor StationName {name!r} is in N1MMLogger" if name
                    else "that address is not in N1MMLogger")
            log.debug("%s packet from %s ignored: %s%s", self.label, address, what,
                      held_text(held))

    def _origin(self, info: RadioInfo, address: str) -> str:
        who = info.app or self.label
        return f"{who} {info.station_name} ({address})" if info.station_name else f"{who} {address}"

    def _accept(self, station: int, address: str, info: RadioInfo) -> RadioUpdate:
        radio_key = (station, info.radio_nr)
        self._remember_sender(_address_key(address), station)
        self._heard[radio_key] = self._clock()
        origin = self._origin(info, address)
        self._focus_events(station, origin, info)
        changed = False
        if info.khz is None or info.tx_khz is None:
            self._no_frequency += 1
        else:
            self._accepted += 1
            pair = (info.khz, info.tx_khz)
            changed = self._last.get(radio_key) != pair
            if changed:
                self._last[radio_key] = pair
                report = FrequencyReport(station, info.radio_nr, info.khz, info.tx_khz, origin,
                                         mode=info.mode, transmitting=info.is_transmitting)
                if self._batch is not None:  # a burst: only each radio's latest counts
                    if self._batch.pop(radio_key, None) is not None:
                        self._superseded += 1
                    self._batch[radio_key] = report
                else:
                    self._deliver(report)
        update = RadioUpdate(station, info.radio_nr, address, info, changed)
        if self._on_update is not None:
            self._call(self._on_update, update)
        return update

    def _remember_sender(self, key: str, station: int) -> None:
        senders = self._stations_heard
        if senders.get(key) == station:
            senders.move_to_end(key)
            return
        senders[key] = station
        senders.move_to_end(key)
        while len(senders) > SENDERS_KEPT:
            senders.popitem(last=False)

    def _focus_events(self, station: int, origin: str, info: RadioInfo) -> None:
        for name, value, event_type in (
            ("active", info.active_radio_nr, ActiveRadio),
            ("focus", info.focus_radio_nr, FocusRadio),
        ):
            if value is None or not 1 <= value <= 99 or self._focus.get((name, station)) == value:
                continue
            self._focus[(name, station)] = value
            self._emit(event_type(station, value, origin))
        if info.is_running is not None:
            radio_key = (station, info.radio_nr)
            if self._running.get(radio_key) != info.is_running:
                self._running[radio_key] = info.is_running
                self._emit(RunOrSearch(station, info.radio_nr, info.is_running, origin))

    def _deliver(self, report: FrequencyReport) -> None:
        self._delivered += 1
        if self._on_frequency is not None:
            self._call(self._on_frequency, report.station, report.radio, report.rx_khz,
                       report.tx_khz)
        self._emit(report)

    def _emit(self, event: SourceEvent) -> None:
        if self._on_event is not None:
            self._call(self._on_event, event)

    def _call(self, callback: Callable[..., object], *args: object) -> None:
        try:
            callback(*args)
        except Exception:
            self._callback_errors += 1
            if self._limiter.allow(("callback", getattr(callback, "__name__", ""))) is not None:
                log.exception("%s listener: %r failed on %r", self.label, callback, args)

    def begin_burst(self) -> None:
        self._batch = {}

    def end_burst(self) -> None:
        batch, self._batch = self._batch, None
        for report in (batch or {}).values():
            self._deliver(report)

    def forget(self) -> None:
        """Make the next packet of every radio count as a change (after a restart of the engine)."""
        self._last.clear()
        self._focus.clear()
        self._running.clear()

    def last_heard(self, station: int, radio: int) -> float | None:
        """The clock reading of the last RadioInfo for that radio, ``None`` if never heard."""
        return self._heard.get((station, radio))

    def stats(self) -> N1MMStats:
        return N1MMStats(
            received=self._received, accepted=self._accepted, delivered=self._delivered,
            superseded=self._superseded,
            no_frequency=self._no_frequency, unknown_sender=self._unknown,
            callback_errors=self._callback_errors, contacts=self._contacts,
            refused={r: n for r, n in self._refused.items() if n},
        )

    # -- asyncio -----------------------------------------------------------------

    async def start(self, port: int | None = None, host: str | None = None) -> int:
        """Bind ``host:port`` (defaults: those given when made; port 0 picks a free port)
        and listen; return the bound port.

        Raises :class:`OSError` with the address in its message when the port
        cannot be had (another program holding it without SO_REUSEADDR).
        """
        host = self._host if host is None else host
        bound = await self.bind(self._port if port is None else port, host)
        mapped = len(set(self._stations.values()) | set(self._names.values()))
        log.info("Listening for %s on UDP %s:%d (%s)", self.title, host, bound,
                 f"every sender is station {self._every_sender}" if self._every_sender
                 else f"{mapped} station{'' if mapped == 1 else 's'}")
        return bound

    async def prepare(self, loop: asyncio.AbstractEventLoop) -> None:
        """Replace host names in the address list by their IPv4 addresses."""
        for key, station in list(self._stations.items()):
            try:
                ipaddress.ip_address(key)
                continue
            except ValueError:
                pass
            try:
                infos = await loop.getaddrinfo(key, None, family=socket.AF_INET,
                                               type=socket.SOCK_DGRAM)
            except OSError as exc:
                log.warning("N1MMLogger: cannot resolve %r for station %d: %s", key, station, exc)
                continue
            for info in infos:
                self._stations.setdefault(_address_key(str(info[4][0])), station)


__all__ = [
    "DEFAULT_PORT", "ContactCallback", "FrequencyCallback", "N1MMListener", "N1MMPacketError", "N1MMStats",
    "RadioInfo", "RadioUpdate", "UpdateCallback", "parse_radio_info", "radio_info_packet",
]
