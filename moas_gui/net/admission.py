"""Who gets a connection: one count of open connections for every transport.

The client port and the browser client's web port take connections from the
same pool, an :class:`Admission`: at most ``total`` open at once (the client
server's limit, see :mod:`.fd_limit`), and at most ``per_address`` from any
one address, so that a crowd from one computer -- a program gone wrong, or an
attacker -- is refused while every other computer is still served.  Loopback
is no exception: ``127.0.0.1`` and ``127.0.0.2`` are two addresses, and a local
program holding many connections cannot shut out the local client either.

Each web connection counts from the moment it is accepted (before a byte of
its request has arrived), and a WebSocket is counted once, as the web
connection it grew from.  Addresses are compared as :func:`~.access.peer_address`
normalises them (an IPv4 client of a dual-stack socket is its IPv4 address).
"""

from __future__ import annotations

import os
import socket
from collections.abc import Iterable
from typing import Any, Final

from .access import peer_address

DEFAULT_PER_ADDRESS: Final = 32
"""Connections from one address at once unless ``--max-per-address`` says otherwise:
far more than one computer's clients and browser pages need, well under the
server's whole limit (200)."""

HELLO_DEADLINE: Final = 5.0
"""Seconds a client connection (TCP or WebSocket) has to say ``hello``."""

KEEPALIVE: Final = 120.0
"""Seconds a greeted client may stay silent; the project's clients send a blank line
every :data:`KEEPALIVE_SEND` seconds when they have nothing to ask."""

KEEPALIVE_SEND: Final = 30.0
"""How often the project's own clients send a blank line (docs/client-protocol.md)."""

REQUEST_DEADLINE: Final = 5.0
"""Seconds an HTTP request has, from its connection (or the end of the previous
response), until its headers and body have all arrived."""


BACKLOG: Final = 1024
"""Connections the system keeps waiting to be accepted, on each port.  asyncio's 100
overflows under a crowd reconnecting as fast as it is refused, and then the system
drops newcomers -- a legitimate client among them -- who try again only a second later;
with a longer queue everyone is accepted, and the crowd refused, in turn."""


def deepen_backlog(sockets: Iterable[Any], backlog: int = BACKLOG) -> None:
    """Lengthens the system's queue of waiting connections on listening ``sockets``.

    Not through asyncio's own ``backlog``: asyncio also accepts that many connections
    at once in one turn of the loop, before any of them can be refused, and a thousand
    at once would use up the file handles a small limit allows."""
    for listening in sockets:
        try:
            twin = socket.socket(fileno=os.dup(listening.fileno()))
        except OSError:
            continue
        try:
            twin.listen(backlog)
        except OSError:
            pass
        finally:
            twin.close()


def address_key(host: str) -> str:
    """The key under which a peer is counted: its normalised address."""
    parsed = peer_address(host)
    return str(parsed) if parsed is not None else host


class Admission:
    """Counts open connections, in all and per address, and refuses those over."""

    def __init__(self, total: int, per_address: int = DEFAULT_PER_ADDRESS) -> None:
        if total < 1 or per_address < 1:
            raise ValueError(f"limits must be at least 1, not {total} and {per_address}")
        self.total = total
        self.per_address = per_address
        self._open: dict[str, int] = {}
        self._count = 0

    @property
    def count(self) -> int:
        """Connections open now, all addresses together."""
        return self._count

    def open_from(self, host: str) -> int:
        return self._open.get(address_key(host), 0)

    def admit(self, host: str) -> str | None:
        """Counts a new connection from ``host`` and returns ``None``; or, when it is
        over a limit, counts nothing and returns why (which limit, in words)."""
        key = address_key(host)
        held = self._open.get(key, 0)
        if held >= self.per_address:
            return (f"{held} connections from that address are open, the most one address "
                    "may hold (moas-server --max-per-address sets it)")
        if self._count >= self.total:
            return (f"{self._count} connections are open, the most this server takes at once "
                    "(moas-server --max-clients sets it)")
        self._open[key] = held + 1
        self._count += 1
        return None

    def release(self, host: str) -> None:
        """A connection :meth:`admit` counted has closed."""
        key = address_key(host)
        held = self._open.get(key, 0)
        if held <= 1:
            self._open.pop(key, None)
        else:
            self._open[key] = held - 1
        if held:
            self._count -= 1


__all__ = [
    "BACKLOG",
    "DEFAULT_PER_ADDRESS",
    "HELLO_DEADLINE",
    "KEEPALIVE",
    "KEEPALIVE_SEND",
    "REQUEST_DEADLINE",
    "Admission",
    "address_key",
    "deepen_backlog",
]
