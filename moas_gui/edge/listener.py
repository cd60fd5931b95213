"""Listening on a TCP port: an accept loop that backs off instead of spinning.

asyncio's own accept loop, when the process is out of file handles, tries again as
many times as its backlog in one turn and once a second after that, each failure
reported.  :class:`Listener` accepts one connection at a time in a task per listening
socket; when the system refuses (out of file handles ``EMFILE``/``ENFILE``, of buffers
or memory) it waits before trying again -- :data:`BACKOFF_FIRST` seconds, twice as long
each time it fails again, at most :data:`BACKOFF_MOST` -- and writes one Warning line a
minute about it, with the count of those left out.  The system keeps the waiting
connections in its queue (:data:`BACKLOG` long) meanwhile.

It accepts one connection a turn of the event loop, and waits while
:data:`HANDING_MOST` are still being handed over, so that a crowd is refused as fast as
it is accepted instead of taking every file handle first.  Each accepted socket is
handed to asyncio as a transport whose protocol is a :class:`~.gate.Gate` of the
listener's :class:`~.gate.Door` (the one door of every listener), told the peer's
address as ``accept()`` gave it; the gate decides at once whether it may stay.

``ssl`` serves TLS on it, and then the admission comes *before* the handshake: the
gate asks for its place (the address's reserve, the fair share) on the bare socket
(:meth:`~.gate.Gate.admit_early`); a socket refused is closed there and then, without
a handshake (nothing can be said to it before one).  The handshake of one admitted runs
in a task of its own, never counted among those being handed over (a silent or slow
peer cannot hold the accept loop), within ``handshake_deadline`` seconds
(:data:`HANDSHAKE_DEADLINE`, the client protocol's hello deadline's size); it holds its
admission ticket meanwhile, as a connection that has not said who it is, so the
admission's limits and evictions count it and may end it (the handshake is then
cancelled).  A handshake that fails or runs out of time gives the ticket back.  A new
front listens with::

    listener = await Listener.open(door, host, port, what="the rotctld port")
    ...
    await listener.close()
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import os
import socket
import ssl as ssl_module
from collections.abc import Awaitable, Callable, Coroutine
from typing import Final

from moas_gui.log_limit import LogLimiter, held_text

from .admission import Ticket
from .gate import Door, Gate

log = logging.getLogger(__name__)

BACKLOG: Final = 1024
"""Connections the system keeps waiting to be accepted, on each port: a crowd
reconnecting as fast as it is refused then does not make the system drop newcomers."""

BACKOFF_FIRST: Final = 0.1
BACKOFF_MOST: Final = 2.0

HANDING_MOST: Final = 8
"""Accepted connections being handed to asyncio at once, at most, per listening socket
(a TLS handshake is not counted: it runs beside the accept loop, admitted first)."""

HANDSHAKE_DEADLINE: Final = 5.0
"""Seconds a TLS handshake may take before the connection is closed: the client
protocol's hello deadline's size (asyncio's own default is a minute)."""

OUT_OF_RESOURCES: Final = frozenset(
    code
    for code in (getattr(errno, name, None) for name in ("EMFILE", "ENFILE", "ENOBUFS", "ENOMEM"))
    if code is not None
)
"""Errors of accept() that say the system has nothing left for a new connection now."""

Accept = Callable[[socket.socket], Awaitable[tuple[socket.socket, object]]]
Sleep = Callable[[float], Awaitable[None]]


def bind(host: str | None, port: int, backlog: int = BACKLOG) -> list[socket.socket]:
    """Listening sockets on ``host`` (``None`` or ``""``: every interface, IPv4 and IPv6)
    and ``port``; raises :class:`OSError` when one cannot be bound."""
    infos = socket.getaddrinfo(host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    made: list[socket.socket] = []
    seen: set[tuple[int, object]] = set()
    try:
        for family, kind, proto, _name, address in infos:
            if (family, address) in seen:
                continue
            seen.add((family, address))
            sock = socket.socket(family, kind, proto)
            made.append(sock)
            if os.name == "posix":  # on Windows the option would let two programs share it
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6 and hasattr(socket, "IPPROTO_IPV6"):
                sock.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            sock.bind(address)
            sock.listen(backlog)
            sock.setblocking(False)
    except OSError:
        for sock in made:
            sock.close()
        raise
    return made


class Listener:
    """Accepts connections on bound ``sockets`` (see the module notes)."""

    def __init__(
        self,
        door: Door,
        sockets: list[socket.socket],
        *,
        what: str = "connections",
        ssl: ssl_module.SSLContext | None = None,
        trouble: LogLimiter | None = None,
        accept: Accept | None = None,
        sleep: Sleep = asyncio.sleep,
        handshake_deadline: float = HANDSHAKE_DEADLINE,
    ) -> None:
        self.door = door
        self.sockets = sockets
        self.what = what
        self.ssl = ssl
        self.handshake_deadline = handshake_deadline
        self.trouble = trouble if trouble is not None else LogLimiter()
        self._loop = asyncio.get_running_loop()
        self._accept = accept if accept is not None else self._loop.sock_accept
        self._sleep = sleep
        self.pauses: list[float] = []
        """Every wait after a refused accept, in order (what the tests read)."""
        self._handing: set[asyncio.Task[object]] = set()
        self._handshakes: set[asyncio.Task[object]] = set()
        """TLS handshakes under way (admitted, not counted in :data:`HANDING_MOST`)."""
        self._tasks = [
            self._loop.create_task(self._accept_forever(sock), name=f"accept {what}")
            for sock in sockets
        ]

    @classmethod
    async def open(
        cls,
        door: Door,
        host: str | None,
        port: int,
        *,
        what: str = "connections",
        ssl: ssl_module.SSLContext | None = None,
        trouble: LogLimiter | None = None,
        handshake_deadline: float = HANDSHAKE_DEADLINE,
    ) -> Listener:
        """Binds ``host``:``port`` and starts accepting; raises :class:`OSError`."""
        return cls(door, bind(host, port), what=what, ssl=ssl, trouble=trouble,
                   handshake_deadline=handshake_deadline)

    @property
    def port(self) -> int:
        return int(self.sockets[0].getsockname()[1]) if self.sockets else 0

    async def _accept_forever(self, sock: socket.socket) -> None:
        pause = BACKOFF_FIRST
        while True:
            try:
                conn, peer = await self._accept(sock)
            except OSError as exc:
                if exc.errno not in OUT_OF_RESOURCES:
                    if sock.fileno() < 0:
                        return  # closed under us
                    self._complain("accept failed", exc, "trying again")
                    await self._sleep(BACKOFF_FIRST)
                    continue
                self._complain("out of resources", exc, f"trying again in {pause:g} s")
                self.pauses.append(pause)
                await self._sleep(pause)
                pause = min(pause * 2, BACKOFF_MOST)
                continue
            pause = BACKOFF_FIRST
            self._hand_over(conn, peer)
            # One connection a turn of the loop, and a few being handed over at most: the
            # ones refused are closed before more are accepted (an accept that finds a
            # connection waiting does not yield, and a crowd would otherwise take every
            # file handle before the first refusal is carried out).
            if len(self._handing) >= HANDING_MOST:
                await asyncio.wait(set(self._handing), return_when=asyncio.FIRST_COMPLETED)
            await asyncio.sleep(0)

    def _complain(self, kind: str, exc: OSError, then: str) -> None:
        held = self.trouble.allow(("accept", kind, self.what))
        if held is not None:
            log.warning(
                "Cannot accept %s for now: %s (%s)%s",
                self.what,
                exc.strerror or exc,
                then,
                held_text(held, "more such failures"),
            )

    def _hand_over(self, conn: socket.socket, peer: object) -> None:
        conn.setblocking(False)
        gate = Gate(self.door, peer)  # the peer's address, read once
        if self.ssl is None:
            self._start(self._connect(conn, gate, None), self._handing)
            return
        handshake: list[asyncio.Task[object]] = []

        def evict(_why: str) -> None:
            if handshake and not handshake[0].done():
                handshake[0].cancel()  # asyncio closes the socket as it gives up
            elif not handshake:
                conn.close()

        ticket = gate.admit_early(evict)
        if ticket is None:
            conn.close()  # refused before a byte of TLS: no handshake spent on it
            return
        task = self._start(self._connect(conn, gate, ticket), self._handshakes)
        # cancelled before it even began (evicted at once): nothing else closes the socket
        task.add_done_callback(lambda done: conn.close() if done.cancelled() else None)
        handshake.append(task)

    def _start(self, work: Coroutine[object, object, object], into: set[asyncio.Task[object]]
               ) -> asyncio.Task[object]:
        task: asyncio.Task[object] = self._loop.create_task(work)
        into.add(task)
        task.add_done_callback(into.discard)
        return task

    async def _connect(self, conn: socket.socket, gate: Gate, ticket: Ticket | None) -> object:
        try:
            if self.ssl is None:
                return await self._loop.connect_accepted_socket(lambda: gate, conn)
            return await self._loop.connect_accepted_socket(
                lambda: gate, conn, ssl=self.ssl, ssl_handshake_timeout=self.handshake_deadline)
        except (OSError, ssl_module.SSLError, asyncio.CancelledError, TimeoutError) as exc:
            conn.close()
            if ticket is not None:
                ticket.release()  # the protocol never saw a connection: its place is free
            held = self.trouble.allow(("handshake", self.what))
            if held is not None:
                why = ("closed by the admission during its handshake"
                       if isinstance(exc, asyncio.CancelledError)
                       else str(exc) or type(exc).__name__)
                log.info("A connection to %s ended before it began: %s%s", self.what, why,
                         held_text(held))
            return None

    async def close(self) -> None:
        """Stops accepting and closes the listening sockets (open connections stay)."""
        for task in (*self._tasks, *self._handshakes):
            task.cancel()
        waiting: list[asyncio.Task[object] | asyncio.Task[None]] = [
            *self._tasks, *self._handing, *self._handshakes]
        for each in waiting:
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await each
        self._tasks = []
        for sock in self.sockets:
            sock.close()


__all__ = [
    "BACKLOG",
    "BACKOFF_FIRST",
    "BACKOFF_MOST",
    "HANDING_MOST",
    "HANDSHAKE_DEADLINE",
    "OUT_OF_RESOURCES",
    "Listener",
    "bind",
]
