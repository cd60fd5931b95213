"""The one door of every listener: each connection admitted (:mod:`.admission`) before
anything is made for it, its peer read once, its ticket given back when it closes.

A front says how it takes connections in a :class:`Door` -- its :class:`~.admission.Admission`,
its name in log lines, its deadlines, whom it takes at all (``allows``), what a refused
peer is told (``refusal``), and what serves a connection once admitted (``open``) -- and
the listener (:class:`~.listener.Listener`) makes a :class:`Gate` of that door for each
connection it accepts.  A stream front (``async def serve(reader, writer)``, the way
:func:`asyncio.start_server` serves) makes its door with :func:`gate_factory`::

    listener = await Listener.open(
        gate_factory(admission, serve, front="rotctld connection",
                     deadlines=Deadlines(hello=30, idle=600), refusal=lambda why: b"..."),
        host, port, what="rotctld connections")

The peer's address is read once, when the connection is accepted (from the socket
``accept()`` gave, or from the transport for a Unix socket), and carried on the
connection's :class:`~.admission.Ticket` (``host``, ``address``): ``serve`` finds it
with :func:`ticket_of` (and calls :meth:`~.admission.Ticket.greeted` and
:meth:`~.admission.Ticket.touch` on it), a protocol made by ``open`` with
:func:`gate_of` or the gate it is given.

A peer a front does not take at all (``allows``: the rotctld ports under
``--require-token``, the client port's ``ClientAllow``) is closed without a word; one
the admission refuses is told ``refusal(reason)`` (when the door has one) and closed.
Refusals are one Warning line a minute per kind for each admission, whichever of its
fronts refused (:attr:`~.admission.Admission.trouble`: the client port and the web
port, which share one, write one between them), with the count of those left out.  One the
admission closes later (a deadline, or another's fair share) is aborted, or told why by
its front when the front has set its own way (:meth:`~.admission.Ticket.set_evict`).

Over TLS the listener asks for the ticket on the bare socket, before the handshake
(:meth:`Gate.admit_early`); once the handshake is done the gate keeps that ticket.

A door may also give each request a deadline (``request_deadline``, the web port's
defence against a request sent a byte at a time): the gate closes a connection whose
next request has not fully arrived within that many seconds of :meth:`Gate.arm` (at the
connection's start, and by the front after each response), ``late`` told first.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass, field

from moas_gui.log_limit import held_text

from .admission import NO_DEADLINES, Admission, Deadlines, Evict, Refused, Ticket

log = logging.getLogger(__name__)

Serve = Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]

Allows = Callable[[str], "str | None"]
"""Whether a front takes a peer at all, by its host: ``None`` if it does, else why not
(one sentence); asked before the admission's limits."""

Open = Callable[["Gate"], asyncio.Protocol]
"""What serves a connection once it is admitted: a protocol made for its gate (which
then hands it the transport and everything the peer sends)."""


def peer_names(peer: object) -> tuple[str, str]:
    """``(host, "host:port")`` of a socket's peer name (``[host]:port`` for IPv6; a Unix
    socket's peer, usually ``""``, as it is)."""
    if isinstance(peer, tuple) and len(peer) >= 2:
        host = str(peer[0])
        return host, (f"[{host}]:{peer[1]}" if ":" in host else f"{host}:{peer[1]}")
    return str(peer), str(peer)


@dataclass(frozen=True, slots=True)
class Door:
    """How one front takes its connections (see the module notes); calling it makes the
    :class:`Gate` of one connection (a protocol factory)."""

    admission: Admission
    open: Open
    front: str
    """The connection's name in the admission's and the gate's log lines."""
    who: str = ""
    """How a refusal line names the peer (``"a client"``); ``"a FRONT"`` when empty."""
    deadlines: Deadlines = NO_DEADLINES
    allows: Allows | None = None
    refusal: Callable[[Refused], bytes] | None = None
    """What a peer the admission refuses is told before it is closed (nothing: ``None``)."""
    hints: Mapping[str, str] = field(default_factory=dict)
    """Words added to a refusal line by limit (``"address"``: which option sets it)."""
    touch_on_data: bool = False
    """Every byte the peer sends is a sign of life (:meth:`~.admission.Ticket.touch`);
    otherwise the front touches the ticket itself (on a whole command, say)."""
    request_deadline: float | None = None
    late: Callable[[Gate], None] | None = None
    """Told of a connection closed for its request deadline (to log it), before it is."""

    def __call__(self) -> Gate:
        """A gate whose peer it reads from its transport (for asyncio's own servers, a
        Unix socket's; the :class:`~.listener.Listener` gives each gate the peer
        ``accept()`` told it)."""
        return Gate(self)

    @property
    def peer_named(self) -> str:
        return self.who or f"a {self.front}"


class Gate(asyncio.Protocol):
    """One connection at a :class:`Door`: admitted, then everything forwarded to what
    the door's ``open`` made for it (see the module notes)."""

    __slots__ = (
        "_timer",
        "address",
        "door",
        "host",
        "inner",
        "received",
        "ticket",
        "transport",
    )

    def __init__(self, door: Door, peer: object = None) -> None:
        self.door = door
        self.host, self.address = peer_names(peer) if peer is not None else ("", "")
        """The peer, read once: from ``accept()`` (``peer``), else from the transport."""
        self.ticket: Ticket | None = None
        self.inner: asyncio.Protocol | None = None
        self.transport: asyncio.Transport | None = None
        self.received = 0
        """Bytes the peer has sent (none at all: a browser's preconnect, say)."""
        self._timer: asyncio.TimerHandle | None = None

    # -- admission ------------------------------------------------------------------------
    def _admit(self, evict: Evict) -> Refused | None:
        door = self.door
        trouble = door.admission.trouble
        why = door.allows(self.host) if door.allows is not None else None
        if why is not None:
            held = trouble.allow(("not allowed", "gate"))
            if held is not None:
                log.warning("Refused %s from %s: %s%s", door.peer_named, self.address, why,
                            held_text(held, "more refused that were not allowed"))
            return Refused(why, "allowed")
        try:
            self.ticket = door.admission.admit(
                self.host, evict, front=door.front, deadlines=door.deadlines,
                address=self.address)
        except Refused as refused:
            held = trouble.allow(("refused", "gate", refused.limit))
            if held is not None:
                log.warning("Refused %s from %s: %s%s%s", door.peer_named, self.address,
                            refused.reason, door.hints.get(refused.limit, ""),
                            held_text(held, "more refused for the same reason"))
            return refused
        return None

    def admit_early(self, evict: Evict) -> Ticket | None:
        """The ticket of a connection still before its TLS handshake, ``evict`` being how
        the admission ends it meanwhile; ``None`` when it is refused (logged): the
        listener then closes its socket, nothing said (nothing can be before a
        handshake)."""
        self._admit(evict)
        return self.ticket

    # -- asyncio.Protocol -----------------------------------------------------------------
    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        if self.ticket is not None:  # admitted before a TLS handshake
            self.ticket.set_evict(lambda _why: transport.abort())
        else:
            if not self.address:  # a Unix socket's connection: no accept() told us
                self.host, self.address = peer_names(transport.get_extra_info("peername"))
            refused = self._admit(lambda _why: transport.abort())
            if refused is not None:
                told = (self.door.refusal(refused) if self.door.refusal is not None
                        and refused.limit != "allowed" else b"")
                if told:
                    transport.write(told)
                transport.close()
                return
        self.inner = self.door.open(self)
        self.inner.connection_made(transport)
        if self.door.request_deadline is not None:
            self.arm()

    def data_received(self, data: bytes) -> None:
        self.received += len(data)
        if self.inner is not None:
            if self.door.touch_on_data and self.ticket is not None:
                self.ticket.touch()
            self.inner.data_received(data)

    def eof_received(self) -> bool | None:
        return self.inner.eof_received() if self.inner is not None else None

    def pause_writing(self) -> None:
        if self.inner is not None:
            self.inner.pause_writing()

    def resume_writing(self) -> None:
        if self.inner is not None:
            self.inner.resume_writing()

    def connection_lost(self, exc: Exception | None) -> None:
        self.disarm()
        if self.ticket is not None:
            self.ticket.release()
        inner, self.inner = self.inner, None
        if inner is not None:
            inner.connection_lost(exc)
        self.transport = None

    # -- the request deadline ---------------------------------------------------------------
    def arm(self) -> None:
        """The next request must have fully arrived within the door's request deadline
        from now (nothing when the door has none)."""
        self.disarm()
        deadline = self.door.request_deadline
        if deadline is not None and self.transport is not None \
                and not self.transport.is_closing():
            self._timer = asyncio.get_running_loop().call_later(deadline, self._expire)

    def disarm(self) -> None:
        """The request is here: no deadline until :meth:`arm` again."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _expire(self) -> None:
        self._timer = None
        if self.door.late is not None:
            self.door.late(self)
        if self.transport is not None:
            self.transport.abort()


def gate_factory(
    admission: Admission,
    serve: Serve,
    *,
    front: str,
    deadlines: Deadlines = NO_DEADLINES,
    refusal: Callable[[str], bytes] | None = None,
    limit: int = 65_536,
    allows: Allows | None = None,
    who: str = "",
) -> Door:
    """The door of a stream front behind ``admission``: each admitted connection served
    by ``serve`` with asyncio's streams (reading at most ``limit`` bytes ahead);
    ``refusal`` says what a refused peer is told, given the reason."""
    return Door(
        admission, streams(serve, limit), front, who=who, deadlines=deadlines, allows=allows,
        refusal=None if refusal is None else (lambda refused: refusal(refused.reason)),
    )


def streams(serve: Serve, limit: int = 65_536) -> Open:
    """An ``open`` that serves each connection with asyncio's streams."""
    return lambda _gate: asyncio.StreamReaderProtocol(asyncio.StreamReader(limit=limit), serve)


def gate_of(transport: asyncio.BaseTransport | None) -> Gate | None:
    """The gate a connection came through (``None``: it came through none, or is gone)."""
    protocol = transport.get_protocol() if transport is not None else None
    return protocol if isinstance(protocol, Gate) else None


def ticket_of(writer: asyncio.StreamWriter) -> Ticket:
    """The admission ticket of a connection served by a stream front (its peer's
    ``host`` and ``address`` on it)."""
    gate = gate_of(writer.transport)
    if gate is None or gate.ticket is None:
        raise RuntimeError("a connection served without coming through a gate")
    return gate.ticket


__all__ = ["Allows", "Door", "Gate", "Open", "Serve", "gate_factory", "gate_of",
           "peer_names", "streams", "ticket_of"]
