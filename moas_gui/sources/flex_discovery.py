"""The FlexRadio radios that announce themselves: their discovery datagrams on UDP 4992.

Each radio broadcasts a VITA-49 datagram about once a second
(:func:`~moas_gui.sources.flex_api.parse_discovery`).  A :class:`FlexDiscovery`
listens (SO_REUSEADDR, so SmartSDR or another program on the same computer
still hears them) and keeps the radios heard, at most :data:`MAX_RADIOS`, each
with when it was last heard; what is not a discovery datagram is dropped with a
rate-limited debug line.  :func:`list_radios` listens a few seconds and returns
what it heard (``moas-server --flex-list`` and the client window's *Sources*
menu).  Broadcasts do not cross routers or most VPNs: there a radio is named
by its address (docs/sources.md).
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable
from typing import Final

from moas_gui.sources.base import BadInputLog
from moas_gui.sources.flex_api import API_PORT, FlexAnnouncement, FlexLineError, parse_discovery
from moas_gui.sources.udp import DatagramSource

log = logging.getLogger(__name__)

MAX_RADIOS: Final = 64
"""Radios kept; a new one beyond them replaces the one heard longest ago."""
FORGET_AFTER: Final = 30.0
"""Seconds without a datagram after which :meth:`FlexDiscovery.radios` leaves a radio out."""


class FlexDiscovery(DatagramSource):
    """Listens for discovery datagrams and keeps who sent them (see the module notes)."""

    kind = "flex-discovery"
    label = "FlexRadio discovery"

    def __init__(self, *, port: int = API_PORT, host: str = "0.0.0.0",
                 on_found: Callable[[FlexAnnouncement], object] | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__()
        self._port = port
        self._host = host
        self._on_found = on_found
        self._clock = clock
        self._heard: dict[str, tuple[FlexAnnouncement, float]] = {}
        self.bad = BadInputLog(log, self.label, clock=clock)

    async def start(self, port: int | None = None, host: str | None = None) -> int:
        return await self.bind(self._port if port is None else port,
                               self._host if host is None else host)

    def handle(self, data: bytes, address: str) -> object:
        try:
            found = parse_discovery(data)
        except FlexLineError as exc:
            self.bad.drop(exc.reason, address, str(exc))
            return None
        if not found.ip:  # the datagram's own sender is where the radio is
            found = FlexAnnouncement({**found.fields, "ip": address})
        key = found.serial or found.ip
        new = key not in self._heard
        if new and len(self._heard) >= MAX_RADIOS:
            oldest = min(self._heard, key=lambda k: self._heard[k][1])
            del self._heard[oldest]
        self._heard[key] = (found, self._clock())
        if new:
            log.info("FlexRadio heard: %s", found.label())
        if self._on_found is not None:
            self._on_found(found)
        return found

    def radios(self) -> list[FlexAnnouncement]:
        """The radios heard in the last :data:`FORGET_AFTER` seconds, by nickname and serial."""
        now = self._clock()
        return sorted((a for a, at in self._heard.values() if now - at <= FORGET_AFTER),
                      key=lambda a: (a.nickname.casefold(), a.serial))

    def find(self, wanted: str) -> FlexAnnouncement | None:
        """The radio heard whose serial, nickname or address is ``wanted``."""
        return next((a for a in self.radios() if a.matches(wanted)), None)


async def list_radios(seconds: float = 3.0, *, port: int = API_PORT,
                      host: str = "0.0.0.0") -> list[FlexAnnouncement]:
    """The radios heard within ``seconds``; :class:`OSError` when the port cannot be bound."""
    discovery = FlexDiscovery(port=port, host=host)
    await discovery.start()
    try:
        await asyncio.sleep(seconds)
    finally:
        await discovery.close()
    return discovery.radios()


__all__ = ["FORGET_AFTER", "MAX_RADIOS", "FlexDiscovery", "list_radios"]
