"""Who gets a connection: one count of open connections for every transport.

The rules themselves (tickets, the fair share, operators' own capacity, the reserve
before hello) are the program's one admission policy, :mod:`moas_gui.edge.admission`;
this module gives the client server's numbers.

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

from moas_gui.edge.admission import (
    DEFAULT_BEFORE_HELLO,
    DEFAULT_OPERATORS,
    DEFAULT_PER_ADDRESS,
    Admission,
    Refused,
    Standing,
    Ticket,
    address_key,
)

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


__all__ = [
    "BACKLOG",
    "DEFAULT_BEFORE_HELLO",
    "DEFAULT_OPERATORS",
    "DEFAULT_PER_ADDRESS",
    "HELLO_DEADLINE",
    "KEEPALIVE",
    "KEEPALIVE_SEND",
    "REQUEST_DEADLINE",
    "Admission",
    "Refused",
    "Standing",
    "Ticket",
    "address_key",
    "deepen_backlog",
]
