"""The client server's clocks: how long a client has to say hello, to stay silent, to
send a web request.

Who gets a connection is the program's one admission policy,
:mod:`moas_gui.edge.admission` (tickets, the fair share, operators' own capacity, the
reserve before hello), and every listener admits through its one gate,
:mod:`moas_gui.edge.gate`.  The client port and the browser client's web port take
connections from the same pool, one :class:`~moas_gui.edge.admission.Admission`: at
most ``total`` open at once (the client server's limit, see :mod:`.fd_limit`), and at
most ``per_address`` from any one address, so that a crowd from one computer -- a program gone wrong, or an
attacker -- is refused while every other computer is still served.  Loopback
is no exception: ``127.0.0.1`` and ``127.0.0.2`` are two addresses, and a local
program holding many connections cannot shut out the local client either.

Each web connection counts from the moment it is accepted (before a byte of
its request has arrived), and a WebSocket is counted once, as the web
connection it grew from.  Addresses are compared as the admission normalises them
(:func:`~moas_gui.edge.admission.address_key`: an IPv4 client of a dual-stack socket is
its IPv4 address).
"""

from __future__ import annotations

from typing import Final

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


__all__ = ["HELLO_DEADLINE", "KEEPALIVE", "KEEPALIVE_SEND", "REQUEST_DEADLINE"]
