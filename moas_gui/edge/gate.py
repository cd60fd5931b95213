"""A stream front's door: each connection admitted (:mod:`.admission`) before asyncio's
streams are made for it, and its ticket given back when it closes.

For a front that serves ``async def serve(reader, writer)`` the way
:func:`asyncio.start_server` does::

    listener = await Listener.open(
        gate_factory(admission, serve, front="rotctld connection",
                     deadlines=Deadlines(hello=30, idle=600), refusal=lambda why: b"..."),
        host, port, what="rotctld connections")

``serve`` finds its connection's ticket with :func:`ticket_of` (to call
:meth:`~.admission.Ticket.greeted` and :meth:`~.admission.Ticket.touch`).  A front may
turn addresses away altogether before the admission's limits (``allows``: the rotctld
ports under ``--require-token``).  A connection refused is told ``refusal(reason)`` (nothing when that is ``None``) and closed; one the
admission closes (a deadline, or another's fair share) is aborted.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable

from moas_gui.log_limit import held_text

from .admission import NO_DEADLINES, Admission, Deadlines, Evict, Refused, Ticket
from .listener import EarlyAdmitted

log = logging.getLogger(__name__)

Serve = Callable[[asyncio.StreamReader, asyncio.StreamWriter], Awaitable[None]]

Allows = Callable[[str], "str | None"]
"""Whether a front takes a peer at all, by its host: ``None`` if it does, else why not
(one sentence); asked before the admission's limits."""


def peer_host(transport: asyncio.BaseTransport) -> tuple[str, str]:
    """``(host, "host:port")`` of a transport's peer (``[host]:port`` for IPv6)."""
    peer = transport.get_extra_info("peername")
    if isinstance(peer, tuple) and len(peer) >= 2:
        host = str(peer[0])
        return host, (f"[{host}]:{peer[1]}" if ":" in host else f"{host}:{peer[1]}")
    return str(peer), str(peer)


class ForwardingGate(asyncio.Protocol):
    """What every gate shares: once a connection is admitted (:attr:`ticket`), asyncio's
    streams take it (:meth:`open_streams`) and everything is forwarded to them; the
    ticket is given back when the connection closes."""

    ticket: Ticket | None = None
    inner: asyncio.StreamReaderProtocol | None = None

    def open_streams(self, transport: asyncio.Transport, serve: Serve, limit: int) -> None:
        reader = asyncio.StreamReader(limit=limit)
        self.inner = asyncio.StreamReaderProtocol(reader, serve)
        self.inner.connection_made(transport)

    def data_received(self, data: bytes) -> None:
        if self.inner is not None:
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
        if self.ticket is not None:
            self.ticket.release()
        inner, self.inner = self.inner, None
        if inner is not None:
            inner.connection_lost(exc)


class StreamGate(ForwardingGate, EarlyAdmitted):
    """One connection of a stream front (see the module notes)."""

    def __init__(
        self,
        admission: Admission,
        serve: Serve,
        *,
        front: str,
        deadlines: Deadlines,
        refusal: Callable[[str], bytes] | None,
        limit: int,
        allows: Allows | None = None,
    ) -> None:
        self.admission = admission
        self.allows = allows
        self.serve = serve
        self.front = front
        self.deadlines = deadlines
        self.refusal = refusal
        self.limit = limit

    def _admit(self, host: str, address: str, evict: Evict) -> Refused | None:
        why = self.allows(host) if self.allows is not None else None
        if why is not None:
            held = self.admission.trouble.allow(("not allowed", self.front))
            if held is not None:
                log.warning("Refused a %s from %s: %s%s", self.front, address, why,
                            held_text(held, "more refused that were not allowed"))
            return Refused(why, "allowed")
        try:
            self.ticket = self.admission.admit(
                host, evict, front=self.front, deadlines=self.deadlines, address=address
            )
        except Refused as refused:
            held = self.admission.trouble.allow(("refused", self.front, refused.limit))
            if held is not None:
                log.warning(
                    "Refused a %s from %s: %s%s",
                    self.front,
                    address,
                    refused.reason,
                    held_text(held, "more refused for the same reason"),
                )
            return refused
        return None

    def admit_early(self, peer: object, evict: Evict) -> Ticket | None:
        if isinstance(peer, tuple) and len(peer) >= 2:
            host = str(peer[0])
            address = f"[{host}]:{peer[1]}" if ":" in host else f"{host}:{peer[1]}"
        else:
            host = address = str(peer)
        self._admit(host, address, evict)
        return self.ticket

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        if self.ticket is not None:  # admitted before a TLS handshake
            self.ticket.set_evict(lambda _why: transport.abort())
        else:
            host, address = peer_host(transport)
            refused = self._admit(host, address, lambda _why: transport.abort())
            if refused is not None:
                if self.refusal is not None:
                    transport.write(self.refusal(refused.reason))
                transport.close()
                return
        self.open_streams(transport, self.serve, self.limit)


def gate_factory(
    admission: Admission,
    serve: Serve,
    *,
    front: str,
    deadlines: Deadlines = NO_DEADLINES,
    refusal: Callable[[str], bytes] | None = None,
    limit: int = 65_536,
    allows: Allows | None = None,
) -> Callable[[], StreamGate]:
    """The protocol factory of a stream front behind ``admission``; ``allows``, when
    given, is asked first and refuses an address by saying why."""
    return lambda: StreamGate(
        admission, serve, front=front, deadlines=deadlines, refusal=refusal, limit=limit,
        allows=allows,
    )


def ticket_of(writer: asyncio.StreamWriter) -> Ticket | None:
    """The admission ticket of a connection served behind a :class:`StreamGate`."""
    protocol = writer.transport.get_protocol()
    return protocol.ticket if isinstance(protocol, StreamGate) else None


__all__ = ["Allows", "ForwardingGate", "Serve", "StreamGate", "gate_factory", "peer_host", "ticket_of"]
