"""The N1MM Logger listener: RadioInfo datagrams on ``UDPPort`` in, radio frequencies out.

The built-in "N1MM Logger client" of the manual (4.1, 6.12, appendix C).  N1MM
Logger+ on each station computer sends one RadioInfo datagram per radio at
least every 10 seconds and at once when a frequency, the mode or the transmit
state changes.  The listener

- maps the **sender's IP address** to a station with the configuration's
  ``N1MMLogger`` list, and the packet's ``RadioNr`` to that station's radio
  number (``RadioNr`` 2 is radio 2);
- calls ``on_frequency(station, radio, khz, tx_khz)`` **only when the pair of
  frequencies of that radio changed** since the last call for it.  The 10-second
  heartbeats repeat the same frequency; passing them on would only make the
  engine re-decide and the switch link re-check nothing.  :meth:`N1MMListener.forget`
  makes the next packet of every radio count as a change (for a restart);
- calls the optional ``on_update(update)`` for every RadioInfo from a known
  station, changed or not, with or without a frequency (transmit state,
  staleness, a status display);
- ignores packets from addresses not in the list (a debug line, at most one per
  address a minute) and counts every packet it refuses, by reason
  (:data:`~moas_gui.net.n1mm_packet.REASONS`), in :meth:`N1MMListener.stats`.
  Nothing a sender does stops the listener: a callback that raises is logged
  and counted too.

The socket is opened with SO_REUSEADDR and SO_BROADCAST, as N1MM's
documentation asks of listeners, so other programs can share the port when
N1MM sends to a broadcast address.  No Qt: this runs on the asyncio loop of
the window and of the headless server alike.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
import socket
import sys
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Final

from moas_gui.config.model import Config, N1MMStation
from moas_gui.net.log_limit import LogLimiter, held_text
from moas_gui.net.n1mm_packet import (
    REASONS,
    N1MMPacketError,
    RadioInfo,
    parse_radio_info,
    radio_info_packet,
)

log = logging.getLogger("moas_gui.net.n1mm")

DEFAULT_PORT: Final = 12060
LOG_INTERVAL: Final = 60.0
"""Seconds between two debug lines about the same sender and reason."""

FrequencyCallback = Callable[[int, int, float, float], object]
"""``on_frequency(station, radio, khz, tx_khz)``."""


MAX_BURST: Final = 1000
"""Datagrams taken at once behind the one the event loop delivered."""
MAX_DATAGRAM: Final = 65536


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
    refused: Mapping[str, int] = field(default_factory=dict)
    """Refused packets by reason (``not_xml``, ``not_radio_info``, ...)."""

    @property
    def malformed(self) -> int:
        """Refused packets except the other N1MM packet types, which are simply not ours."""
        return sum(n for reason, n in self.refused.items() if reason != "not_radio_info")


def _address_key(address: str) -> str:
    """The canonical text of an IP address (IPv4-mapped IPv6 becomes IPv4); other text as is."""
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return address.strip().lower()
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        ip = ip.ipv4_mapped
    return str(ip)


def _station_table(stations: Iterable[N1MMStation] | Mapping[str, int]) -> dict[str, int]:
    pairs = stations.items() if isinstance(stations, Mapping) else (
        (s.address, s.station) for s in stations)
    table: dict[str, int] = {}
    for address, station in pairs:
        key = _address_key(address)
        if key in table and table[key] != station:
            log.warning("N1MMLogger: address %s is listed for station %d and station %d; "
                        "using station %d", address, table[key], station, table[key])
            continue
        table[key] = station
    return table


class N1MMListener(asyncio.DatagramProtocol):
    """Receives N1MM Logger RadioInfo datagrams and reports radio frequencies.

    Use :meth:`start` to bind it (or hand it to ``create_datagram_endpoint``
    yourself), :meth:`close` to stop.  :meth:`handle` is the whole logic for
    one datagram, callable without a socket.
    """

    def __init__(
        self,
        stations: Iterable[N1MMStation] | Mapping[str, int],
        on_frequency: FrequencyCallback,
        *,
        on_update: UpdateCallback | None = None,
        clock: Callable[[], float] = time.monotonic,
        log_interval: float = LOG_INTERVAL,
    ) -> None:
        self._stations = _station_table(stations)
        self._on_frequency = on_frequency
        self._on_update = on_update
        self._clock = clock
        self._limiter = LogLimiter(log_interval, clock)
        self._last: dict[tuple[int, int], tuple[float, float]] = {}
        self._heard: dict[tuple[int, int], float] = {}
        self._transport: asyncio.BaseTransport | None = None
        self._sock: socket.socket | None = None
        self._batch: dict[tuple[int, int], tuple[int, int, float, float]] | None = None
        self._closed: asyncio.Future[None] | None = None
        self._received = self._accepted = self._delivered = self._superseded = 0
        self._no_frequency = self._unknown = self._callback_errors = 0
        self._refused = dict.fromkeys(REASONS, 0)

    @classmethod
    def from_config(
        cls,
        config: Config,
        on_frequency: FrequencyCallback,
        *,
        on_update: UpdateCallback | None = None,
    ) -> N1MMListener:
        """A listener for the configuration's ``N1MMLogger`` list (bind it on ``config.udp_port``)."""
        return cls(config.n1mm_logger, on_frequency, on_update=on_update)

    # -- the logic ---------------------------------------------------------------

    def handle(self, data: bytes, address: str) -> RadioUpdate | None:
        """Take one datagram from ``address``; return what it changed, if it was accepted."""
        self._received += 1
        key = _address_key(address)
        station = self._stations.get(key)
        if station is None:
            self._unknown += 1
            held = self._limiter.allow(("unknown", key))
            if held is not None:
                log.debug("N1MM packet from %s ignored: that address is not in N1MMLogger%s",
                          address, held_text(held))
            return None
        try:
            info = parse_radio_info(data)
        except N1MMPacketError as exc:
            self._refused[exc.reason] += 1
            held = self._limiter.allow((exc.reason, key))
            if held is not None:
                log.debug("N1MM packet from %s (station %d) ignored: %s%s",
                          address, station, exc, held_text(held))
            return None
        radio_key = (station, info.radio_nr)
        self._heard[radio_key] = self._clock()
        changed = False
        if info.khz is None or info.tx_khz is None:
            self._no_frequency += 1
        else:
            self._accepted += 1
            pair = (info.khz, info.tx_khz)
            changed = self._last.get(radio_key) != pair
            if changed:
                self._last[radio_key] = pair
                if self._batch is not None:  # a burst: only each radio's latest counts
                    if self._batch.pop(radio_key, None) is not None:
                        self._superseded += 1
                    self._batch[radio_key] = (station, info.radio_nr, info.khz, info.tx_khz)
                else:
                    self._delivered += 1
                    self._call(self._on_frequency, station, info.radio_nr, info.khz,
                               info.tx_khz)
        update = RadioUpdate(station, info.radio_nr, address, info, changed)
        if self._on_update is not None:
            self._call(self._on_update, update)
        return update

    def _call(self, callback: Callable[..., object], *args: object) -> None:
        try:
            callback(*args)
        except Exception:
            self._callback_errors += 1
            if self._limiter.allow(("callback", getattr(callback, "__name__", ""))) is not None:
                log.exception("N1MM listener: %r failed on %r", callback, args)

    def forget(self) -> None:
        """Make the next packet of every radio count as a change (after a restart of the engine)."""
        self._last.clear()

    def last_heard(self, station: int, radio: int) -> float | None:
        """The clock reading of the last RadioInfo for that radio, ``None`` if never heard."""
        return self._heard.get((station, radio))

    def stats(self) -> N1MMStats:
        return N1MMStats(
            received=self._received, accepted=self._accepted, delivered=self._delivered,
            superseded=self._superseded,
            no_frequency=self._no_frequency, unknown_sender=self._unknown,
            callback_errors=self._callback_errors,
            refused={r: n for r, n in self._refused.items() if n},
        )

    # -- asyncio -----------------------------------------------------------------

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self._transport = transport

    def datagram_received(self, data: bytes, addr: tuple[str | int, ...]) -> None:
        """Take this datagram and every one already waiting behind it; then tell each
        radio's latest frequency once.  When packets come faster than antennas can be
        chosen, stale frequencies are skipped instead of queueing up (the switch only
        ever needs the newest)."""
        if self._sock is None:
            self.handle(data, str(addr[0]))
            return
        self._batch = {}
        try:
            self.handle(data, str(addr[0]))
            for _ in range(MAX_BURST):
                try:
                    more, where = self._sock.recvfrom(MAX_DATAGRAM)
                except OSError:  # nothing more waiting (or the socket is closing)
                    break
                self.handle(more, str(where[0]))
        finally:
            batch, self._batch = self._batch, None
        for station, radio, khz, tx_khz in batch.values():
            self._delivered += 1
            self._call(self._on_frequency, station, radio, khz, tx_khz)

    def error_received(self, exc: Exception) -> None:
        log.debug("N1MM listener socket error (ignored): %s", exc)

    def connection_lost(self, exc: Exception | None) -> None:
        self._transport = None
        self._sock = None
        if self._closed is not None and not self._closed.done():
            self._closed.set_result(None)

    async def start(self, port: int = DEFAULT_PORT, host: str = "0.0.0.0") -> int:
        """Bind ``host:port`` (port 0: any free port) and listen; return the bound port.

        Raises :class:`OSError` with the address in its message when the port
        cannot be had (another program holding it without SO_REUSEADDR).
        """
        if self._transport is not None:
            raise RuntimeError("the N1MM listener is already started")
        loop = asyncio.get_running_loop()
        await self._resolve_names(loop)
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        sock = socket.socket(family, socket.SOCK_DGRAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
            sock.bind((host, port))
        except OSError as exc:
            sock.close()
            raise OSError(exc.errno, f"N1MM listener cannot bind UDP {host}:{port}: "
                                     f"{exc.strerror}") from exc
        self._closed = loop.create_future()
        await loop.create_datagram_endpoint(lambda: self, sock=sock)
        # Reading what waits behind a datagram needs the socket itself; the proactor
        # loops of Windows read through their own pending operation, so not there.
        self._sock = sock if sys.platform != "win32" else None
        bound = int(sock.getsockname()[1])
        log.info("Listening for N1MM Logger on UDP %s:%d (%d station%s)", host, bound,
                 len(self._stations), "" if len(self._stations) == 1 else "s")
        return bound

    async def _resolve_names(self, loop: asyncio.AbstractEventLoop) -> None:
        """Replace host names in the station list by their IPv4 addresses."""
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

    @property
    def port(self) -> int | None:
        """The bound port, ``None`` when not listening."""
        if self._transport is None:
            return None
        return int(self._transport.get_extra_info("sockname")[1])

    async def close(self) -> None:
        """Stop listening (idempotent)."""
        if self._transport is None:
            return
        self._transport.close()
        if self._closed is not None:
            await self._closed


__all__ = [
    "DEFAULT_PORT", "FrequencyCallback", "N1MMListener", "N1MMPacketError", "N1MMStats",
    "RadioInfo", "RadioUpdate", "UpdateCallback", "parse_radio_info", "radio_info_packet",
]
