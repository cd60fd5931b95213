"""The web port's defences below HTTP: every connection counted and timed, and
aiohttp's own log lines kept short and rare.

:class:`GuardedConnection` stands between the socket and aiohttp's request
handler.  It asks the client server's :class:`~.admission.Admission` before
aiohttp sees a byte (a connection over a limit gets a ``503`` and is closed),
gives it back when the connection closes, and closes a connection whose request
has not fully arrived within :data:`~.admission.REQUEST_DEADLINE` seconds of its
opening or of the previous response: a half-sent request (slowloris), a body sent
a byte at a time, or a kept-alive connection left idle.  A WebSocket leaves this
clock once upgraded; the client protocol's own hello deadline and keepalive then
apply to it (:mod:`.web_socket`).

:class:`QuietAiohttp` is a filter on aiohttp's loggers: each kind of line (a
malformed request, say) goes out once a minute with a count of those held back,
as one Warning line without its traceback (the traceback stays at Debug).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from moas_gui.edge.admission import Refused, Ticket
from moas_gui.edge.listener import EarlyAdmitted
from moas_gui.log_limit import LogLimiter, held_text

from .admission import REQUEST_DEADLINE
from .connection import format_peer
from .server import ClientServer

log = logging.getLogger(__name__)

AIOHTTP_LOGGERS = ("aiohttp.server", "aiohttp.web", "aiohttp.websocket", "aiohttp.access",
                   "aiohttp.internal")


def _refusal(text: str) -> bytes:
    body = text.encode()
    return (b"HTTP/1.1 503 Service Unavailable\r\n"
            b"Content-Type: text/plain; charset=utf-8\r\n"
            b"Content-Length: " + str(len(body)).encode() + b"\r\n"
            b"Connection: close\r\n\r\n" + body)


class GuardedConnection(asyncio.Protocol, EarlyAdmitted):
    """One web connection: counted, timed, and otherwise handed to aiohttp's ``inner``.
    Over TLS its place is taken before the handshake (:meth:`admit_early`)."""

    def __init__(self, make_inner: Callable[[], asyncio.Protocol], clients: ClientServer,
                 deadline: float = REQUEST_DEADLINE) -> None:
        self._make_inner = make_inner
        """aiohttp's handler is made only for a connection admitted (it costs)."""
        self.inner: asyncio.Protocol = asyncio.Protocol()
        self.clients = clients
        self.deadline = deadline
        self.host = ""
        self.address = ""
        self.admitted = False
        self.ticket: Ticket | None = None
        """Its place in the client server's admission (a WebSocket's connection takes it
        over: a hello greets it)."""
        self.transport: asyncio.Transport | None = None
        self._timer: asyncio.TimerHandle | None = None
        self.received = 0
        """Bytes this connection sent: none at all is a browser's preconnect."""

    # -- the request clock ---------------------------------------------------------
    def arm(self) -> None:
        """The next request must have fully arrived within the deadline from now."""
        self.disarm()
        if self.transport is not None and not self.transport.is_closing():
            self._timer = asyncio.get_running_loop().call_later(self.deadline, self._expire)

    def disarm(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _expire(self) -> None:
        self._timer = None
        if self.received == 0:
            # a browser opens a connection or two ahead in case it needs them (Chromium's
            # preconnect) and never uses them: nothing wrong, nothing for the Info log
            log.debug("Closed a web connection from %s: it sent nothing within %g s (a "
                      "browser's preconnect)", self.address, self.deadline)
        else:
            self.clients.trouble_line(
                "web request deadline", logging.INFO,
                "Closed a web connection from %s: no complete request within %g s",
                self.address, self.deadline)
        if self.transport is not None:
            self.transport.abort()

    def _admit(self, peer: object, evict: Callable[[str], None]) -> Refused | None:
        self.host = str(peer[0]) if isinstance(peer, tuple) else str(peer)
        self.address = format_peer(peer)
        try:
            self.ticket = self.clients.admission.admit(
                self.host, evict, front="web connection", address=self.address)
        except Refused as refusal:
            self.clients.refused(self.address, refusal, "a browser")
            return refusal
        return None

    def admit_early(self, peer: object, evict: Callable[[str], None]) -> Ticket | None:
        self._admit(peer, evict)
        return self.ticket

    # -- asyncio.Protocol ------------------------------------------------------------
    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        if self.ticket is not None:  # admitted before its handshake
            self.ticket.set_evict(lambda _why: transport.abort())
        else:
            refusal = self._admit(transport.get_extra_info("peername"),
                                  lambda _why: transport.abort())
            if refusal is not None:
                transport.write(_refusal(self.clients.refusal_reply(refusal) + "\n"))
                transport.close()
                return
        self.admitted = True
        self.inner = self._make_inner()
        self.inner.connection_made(transport)
        self.arm()

    def data_received(self, data: bytes) -> None:
        self.received += len(data)
        if self.admitted:
            if self.ticket is not None:
                self.ticket.touch()
            self.inner.data_received(data)

    def eof_received(self) -> bool | None:
        return self.inner.eof_received() if self.admitted else None

    def pause_writing(self) -> None:
        if self.admitted:
            self.inner.pause_writing()

    def resume_writing(self) -> None:
        if self.admitted:
            self.inner.resume_writing()

    def connection_lost(self, exc: Exception | None) -> None:
        self.disarm()
        if self.admitted:
            self.admitted = False
            if self.ticket is not None:
                self.ticket.release()
            self.inner.connection_lost(exc)
        self.transport = None


class QuietAiohttp(logging.Filter):
    """Lets each kind of aiohttp log line through once a minute, short (see module notes)."""

    def __init__(self, limiter: LogLimiter | None = None) -> None:
        super().__init__()
        self.limiter = limiter or LogLimiter()

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        kind = ("aiohttp", record.name, str(record.msg)[:80], type(exc).__name__)
        held = self.limiter.allow(kind)
        if held is None:
            return False
        message = record.getMessage()
        if exc is not None and not logging.getLogger(record.name).isEnabledFor(logging.DEBUG):
            detail = " ".join(str(exc).split())
            detail = detail if len(detail) <= 160 else detail[:157] + "..."
            message = f"{message}: {type(exc).__name__}" + (f": {detail}" if detail else "")
            record.exc_info = None
            record.exc_text = None
            if record.levelno > logging.WARNING:  # the peer's fault, not the server's
                record.levelno, record.levelname = logging.WARNING, "WARNING"
        record.msg, record.args = message + held_text(held), None
        return True

    def install(self) -> None:
        for name in AIOHTTP_LOGGERS:
            logging.getLogger(name).addFilter(self)

    def remove(self) -> None:
        for name in AIOHTTP_LOGGERS:
            logging.getLogger(name).removeFilter(self)


__all__ = ["AIOHTTP_LOGGERS", "GuardedConnection", "QuietAiohttp"]
