"""The Antenna Genius discovery datagrams: ``AG ip=... port=... v=... serial=... name=...
ports=2 antennas=N mode=master uptime=S``, one a second per device, on UDP port 9007.

They go to the broadcast address of every interface the server listens on, and only
when it listens beyond loopback: a server bound to loopback announces nothing, and
nothing is ever sent beyond the station's own networks.  ``--ag-discovery ADDR:PORT``
sends them to that one address instead (tests use loopback).
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import logging
import socket
import struct
import sys
from collections.abc import Callable
from dataclasses import dataclass

log = logging.getLogger(__name__)

DISCOVERY_PORT = 9007


@dataclass(frozen=True, slots=True)
class AgAnnouncement:
    port: int
    firmware: str
    serial: str
    name: str
    ports: int
    antennas: int
    uptime: int

    def text(self, ip: str) -> str:
        return (f"AG ip={ip} port={self.port} v={self.firmware} serial={self.serial} "
                f"name={self.name} ports={self.ports} antennas={self.antennas} mode=master "
                f"uptime={self.uptime}")


def _interface_addresses() -> list[tuple[str, str]]:
    """``(address, broadcast)`` of every IPv4 interface that has a broadcast address
    (Linux; elsewhere the empty list, and the announcer says so once)."""
    if not sys.platform.startswith("linux"):
        return []
    import fcntl

    out = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        for _, name in socket.if_nameindex():
            request = struct.pack("256s", name.encode()[:15])
            try:
                address = fcntl.ioctl(probe.fileno(), 0x8915, request)[20:24]  # SIOCGIFADDR
                broadcast = fcntl.ioctl(probe.fileno(), 0x8919, request)[20:24]  # SIOCGIFBRDADDR
            except OSError:
                continue
            ip, bcast = socket.inet_ntoa(address), socket.inet_ntoa(broadcast)
            if not ipaddress.ip_address(ip).is_loopback and bcast != "0.0.0.0":
                out.append((ip, bcast))
    return out


def _source_address(target: tuple[str, int]) -> str:
    """The address this computer reaches ``target`` from (a UDP socket's connect sends
    nothing); loopback when that cannot be told."""
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            probe.connect(target)
            return str(probe.getsockname()[0])
    except OSError:
        return "127.0.0.1"


def broadcast_targets(bind: str) -> list[tuple[str, str]]:
    """``(our address, broadcast address)`` pairs for a server bound to ``bind``: every
    interface's for the wildcard, the one interface's for one address, none for
    loopback (or anything not IPv4)."""
    try:
        bound = ipaddress.ip_address(bind or "0.0.0.0")
    except ValueError:
        return []
    if bound.is_loopback or bound.version != 4:
        return []
    interfaces = _interface_addresses()
    if bound.is_unspecified:
        return interfaces
    return [(ip, b) for ip, b in interfaces if ip == str(bound)]


class Announcer:
    """Sends the announcements every ``interval`` seconds while it runs."""

    def __init__(self, bind: str, target: tuple[str, int] | None,
                 announcements: Callable[[], list[AgAnnouncement]], interval: float = 1.0) -> None:
        self.bind, self.target = bind, target
        self.announcements = announcements
        self.interval = interval
        self._task: asyncio.Task[None] | None = None

    def destinations(self) -> list[tuple[str, tuple[str, int]]]:
        """``(ip said in the datagram, where it goes)`` pairs."""
        if self.target is not None:
            host = self.bind
            if host in ("", "0.0.0.0", "::"):
                host = _source_address(self.target)
            return [(host, self.target)]
        return [(ip, (bcast, DISCOVERY_PORT)) for ip, bcast in broadcast_targets(self.bind)]

    def start(self) -> None:
        destinations = self.destinations()
        if not destinations:
            log.info("Antenna Genius discovery: not announced (the server listens on "
                     "loopback only, or no interface has a broadcast address)")
            return
        self._task = asyncio.get_running_loop().create_task(self._run(destinations))

    async def _run(self, destinations: list[tuple[str, tuple[str, int]]]) -> None:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.setblocking(False)
        if self.target is None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
        warned = False
        try:
            while True:
                for announcement in self.announcements():
                    for ip, where in destinations:
                        try:
                            sock.sendto(announcement.text(ip).encode(), where)
                        except OSError as exc:
                            if not warned:
                                log.warning("Antenna Genius discovery to %s:%d: %s", *where,
                                            exc.strerror or exc)
                                warned = True
                await asyncio.sleep(self.interval)
        finally:
            sock.close()

    def close(self) -> None:
        if self._task is not None:
            self._task.cancel()
            self._task = None


def parse_target(text: str) -> tuple[str, int]:
    """``ADDR:PORT`` for ``--ag-discovery``; raises ValueError saying what is wrong."""
    host, colon, port = text.rpartition(":")
    if not colon or not host or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ValueError(f"{text!r} is not ADDR:PORT (as 127.0.0.1:9007)")
    with contextlib.suppress(ValueError):
        ipaddress.ip_address(host)
        return host, int(port)
    raise ValueError(f"{host!r} is not an IP address")


__all__ = ["DISCOVERY_PORT", "AgAnnouncement", "Announcer", "broadcast_targets", "parse_target"]
