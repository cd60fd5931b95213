"""The web port's defences below HTTP: every connection counted and timed, and
aiohttp's own log lines kept short and rare.

:func:`web_door` is the web port's :class:`~moas_gui.edge.gate.Door`, the one door of
every listener: each connection asks the client server's
:class:`~moas_gui.edge.admission.Admission` before aiohttp sees a byte (a connection over
a limit gets a ``503`` and is closed), gives its place back when it closes, and is
closed when its request has not fully arrived within
:data:`~.admission.REQUEST_DEADLINE` seconds of its opening or of the previous response:
a half-sent request (slowloris), a body sent a byte at a time, or a kept-alive
connection left idle (the web server's middleware stops the clock when a request is
there and starts it again after the response).  A WebSocket leaves this clock once
upgraded; the client protocol's own hello deadline and keepalive then apply to it
(:mod:`.web_socket`).

:class:`QuietAiohttp` is a filter on aiohttp's loggers: each kind of line (a
malformed request, say) goes out once a minute with a count of those held back,
as one Warning line without its traceback (the traceback stays at Debug).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from moas_gui.edge.gate import Door, Gate
from moas_gui.log_limit import LogLimiter, held_text

from .admission import REQUEST_DEADLINE
from .server import ClientServer

log = logging.getLogger(__name__)

AIOHTTP_LOGGERS = ("aiohttp.server", "aiohttp.web", "aiohttp.websocket", "aiohttp.access",
                   "aiohttp.internal")


def _refusal(text: str) -> bytes:
    body = (text + "\n").encode()
    return (b"HTTP/1.1 503 Service Unavailable\r\n"
            b"Content-Type: text/plain; charset=utf-8\r\n"
            b"Content-Length: " + str(len(body)).encode() + b"\r\n"
            b"Connection: close\r\n\r\n" + body)


def web_door(clients: ClientServer, make_inner: Callable[[], asyncio.Protocol],
             deadline: float = REQUEST_DEADLINE) -> Door:
    """The web port's door: its connections counted with the client port's, each handed
    to aiohttp's handler (``make_inner``, made only for a connection admitted: it costs)
    and timed (see the module notes); every byte a sign of life."""

    def late(gate: Gate) -> None:
        if gate.received == 0:
            # a browser opens a connection or two ahead in case it needs them (Chromium's
            # preconnect) and never uses them: nothing wrong, nothing for the Info log
            log.debug("Closed a web connection from %s: it sent nothing within %g s (a "
                      "browser's preconnect)", gate.address, deadline)
        else:
            clients.trouble_line(
                "web request deadline", logging.INFO,
                "Closed a web connection from %s: no complete request within %g s",
                gate.address, deadline)

    return clients.door("web connection", "a browser", lambda _gate: make_inner(), _refusal,
                        touch_on_data=True, request_deadline=deadline, late=late)


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


__all__ = ["AIOHTTP_LOGGERS", "QuietAiohttp", "web_door"]
