"""The asyncio part shared by the UDP sources: bind, read bursts, close.

A :class:`DatagramSource` binds one UDP port with SO_REUSEADDR and
SO_BROADCAST (so several programs can listen to a logger's broadcasts, as
N1MM's documentation asks of listeners), and calls :meth:`~DatagramSource.handle`
for each datagram.  When datagrams arrive faster than they are read, the ones
waiting behind the first are read at once as a *burst*; a subclass collects
what they say and acts on each radio's newest value once, in
:meth:`~DatagramSource.end_burst`, so stale frequencies never queue up.  The server
gives each listener its sources' intake as :attr:`~DatagramSource.bursts`, held around
the burst, so what the burst said is decided as it ends, in the loop turn that read it.
"""

from __future__ import annotations

import asyncio
import logging
import socket
import sys
from typing import Final

from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.sources.base import Bursts

MAX_BURST: Final = 1000
"""Datagrams taken at once behind the one the event loop delivered."""
MAX_DATAGRAM: Final = 65536

log = logging.getLogger(__name__)
_SOCKET_ERRORS: Final = LogLimiter()
"""One line a minute per listener and kind of socket error."""


class DatagramSource(asyncio.DatagramProtocol):
    """Base of the UDP listeners: subclasses give :meth:`handle` and, if they batch, the
    :meth:`begin_burst` / :meth:`end_burst` pair."""

    kind = "udp"
    label = "UDP source"
    """How log lines and errors name the listener (``"N1MM Logger"``)."""

    def __init__(self) -> None:
        self._transport: asyncio.BaseTransport | None = None
        self._sock: socket.socket | None = None
        self._closed: asyncio.Future[None] | None = None
        self.bursts: Bursts | None = None
        """Told around each burst (the server's sources' intake: :class:`~.base.Bursts`),
        so what the burst said is decided in the turn that read it; None: nobody."""

    # -- what a subclass gives -------------------------------------------------------
    def handle(self, data: bytes, address: str) -> object:
        raise NotImplementedError

    def begin_burst(self) -> None:
        """Called before a burst of datagrams is handled."""

    def end_burst(self) -> None:
        """Called after the burst (also when handling raised)."""

    async def start(self, port: int | None = None, host: str | None = None) -> int:
        """Bind (defaults: the port and host the listener was made with); return the port."""
        raise NotImplementedError

    async def prepare(self, loop: asyncio.AbstractEventLoop) -> None:
        """Called by :meth:`bind` before the socket is opened (name lookups...)."""

    # -- asyncio -----------------------------------------------------------------------
    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        self._transport = transport

    def datagram_received(self, data: bytes, addr: tuple[str | int, ...]) -> None:
        bursts = self.bursts
        if bursts is None:
            self._take(data, addr)
            return
        bursts.hold()
        try:
            self._take(data, addr)
        finally:
            try:
                bursts.release()
            except Exception:  # a listener never stops on what its sink does
                if _SOCKET_ERRORS.allow((self.label, "decision")) is not None:
                    log.exception("%s: what a burst said could not be decided", self.label)

    def _take(self, data: bytes, addr: tuple[str | int, ...]) -> None:
        """The datagram the loop delivered and those waiting behind it, as one burst."""
        if self._sock is None:
            self.begin_burst()
            try:
                self.handle(data, str(addr[0]))
            finally:
                self.end_burst()
            return
        self.begin_burst()
        try:
            self.handle(data, str(addr[0]))
            for _ in range(MAX_BURST):
                try:
                    more, where = self._sock.recvfrom(MAX_DATAGRAM)
                except OSError:  # nothing more waiting (or the socket is closing)
                    break
                self.handle(more, str(where[0]))
        finally:
            self.end_burst()

    def error_received(self, exc: Exception) -> None:
        # a peer's ICMP answers to the headings sent (port unreachable) repeat at its will
        held = _SOCKET_ERRORS.allow((self.label, type(exc).__name__))
        if held is not None:
            log.debug("%s socket error (ignored): %s%s", self.label, exc, held_text(held))

    def connection_lost(self, exc: Exception | None) -> None:
        self._transport = None
        self._sock = None
        if self._closed is not None and not self._closed.done():
            self._closed.set_result(None)

    async def bind(self, port: int, host: str = "0.0.0.0") -> int:
        """Bind ``host:port`` (port 0: any free port) and listen; return the bound port.

        Raises :class:`OSError` with the address in its message when the port
        cannot be had (another program holding it without SO_REUSEADDR).
        """
        if self._transport is not None:
            raise RuntimeError(f"the {self.label} listener is already started")
        loop = asyncio.get_running_loop()
        await self.prepare(loop)
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        sock = socket.socket(family, socket.SOCK_DGRAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
            sock.bind((host, port))
        except OSError as exc:
            sock.close()
            raise OSError(exc.errno, f"{self.label} listener cannot bind UDP {host}:{port}: "
                                     f"{exc.strerror}") from exc
        self._closed = loop.create_future()
        await loop.create_datagram_endpoint(lambda: self, sock=sock)
        # Reading what waits behind a datagram needs the socket itself; the proactor
        # loops of Windows read through their own pending operation, so not there.
        self._sock = sock if sys.platform != "win32" else None
        return int(sock.getsockname()[1])

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


__all__ = ["MAX_BURST", "MAX_DATAGRAM", "DatagramSource"]
