"""The browser client's web server: the page, and the client protocol over a WebSocket.

::

    web = WebServer(clients, host="0.0.0.0", port=config.web_port)
    await web.start()        # http://HOST:PORT/ is the page, ws://HOST:PORT/ws the protocol
    ...
    await web.close()

It serves four kinds of request, and nothing else:

* ``/`` and the page's own files (``moas_gui/resources/web``), read into memory
  at start: a name not in that fixed set is ``404``, so no path leads outside
  it and no directory is ever listed;
* ``/ws``, a WebSocket speaking the client protocol to the same
  :class:`~.server.ClientServer` as TCP clients (:mod:`.web_socket`);
* ``/report``, the contest report of the antenna journal as one read-only HTML page
  (``?hours=N``: the last N hours; ``?from=T&to=T``: ISO 8601 UTC).  Whoever may
  connect without a token sees it; anyone else shows an operator's token (any role:
  ``view`` suffices) as ``Authorization: Bearer TOKEN``, or gets ``401``.  The period
  is clamped to the journal's own time; one of more than a year is ``400`` naming the
  bounds; the report is made in a thread of its own, one at a time (a request while
  one is being made: ``503`` with ``Retry-After``);
* nothing else (``404``; methods other than GET and HEAD: ``405``).

Every connection is counted against the client server's limits, in all and per
address, and must deliver each complete request within a few seconds
(:mod:`.web_limits`).  Every request is checked first against the client
server's ``ClientAllow`` (refused with ``403``), then its Host header, and a
WebSocket's Origin (:mod:`.web_guard`); each refusal writes a Warning line, once
a minute per kind.  A WebSocket whose client sends an unmasked frame is failed
with a Close 1002, as RFC 6455 requires (:mod:`.web_frames`).  ``docs/web-client.md`` has the page's side.
"""

from __future__ import annotations

import asyncio
import contextlib
import html
import logging
import math
import sqlite3
import time
from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass
from importlib import resources
from typing import TYPE_CHECKING, Final

from aiohttp import WSCloseCode, web

from moas_gui.edge.admission import Ticket, checking
from moas_gui.edge.gate import gate_of
from moas_gui.edge.listener import Listener
from moas_gui.errors import HardwareError
from moas_gui.net.secrets import SecretVerdict

from .admission import REQUEST_DEADLINE
from .server import ClientServer
from .web_frames import frames_arrived_early, require_masking
from .web_guard import host_allowed, local_names, origin_complaint
from .web_limits import QuietAiohttp, web_door
from .web_socket import MAX_MESSAGE, converse

if TYPE_CHECKING:
    from moas_gui.antenna_log.records import JournalReader, Period

log = logging.getLogger(__name__)

JournalSource = Callable[[], "JournalReader | None"]
"""The antenna journal the server keeps now (None: turned off)."""

_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".css": "text/css; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".svg": "image/svg+xml",
    ".png": "image/png",
    ".json": "application/json",
}
_HEADERS = {
    "Content-Security-Policy": (
        "default-src 'self'; connect-src 'self'; img-src 'self' data:; "
        "style-src 'self'; script-src 'self'; frame-ancestors 'none'; base-uri 'none'; "
        "form-action 'none'"
    ),
    "X-Content-Type-Options": "nosniff",
    "X-Frame-Options": "DENY",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-cache",
}


@dataclass(frozen=True, slots=True)
class StaticFile:
    body: bytes
    content_type: str


def page_files() -> dict[str, StaticFile]:
    """The page's files by URL path, from the package's ``resources/web``."""
    root = resources.files("moas_gui") / "resources" / "web"
    files: dict[str, StaticFile] = {}
    for entry in root.iterdir():
        suffix = "." + entry.name.rsplit(".", 1)[-1] if "." in entry.name else ""
        if entry.is_file() and suffix in _TYPES:
            files["/" + entry.name] = StaticFile(entry.read_bytes(), _TYPES[suffix])
    if "/index.html" in files:
        files["/"] = files["/index.html"]
    return files


_REPORT_HEADERS = _HEADERS | {
    # one page with no script, its style and charts inline
    "Content-Security-Policy": (
        "default-src 'none'; style-src 'unsafe-inline'; img-src data:; "
        "frame-ancestors 'none'; base-uri 'none'; form-action 'none'"
    ),
}
MAX_REPORT_HOURS = 24 * 31
"""The most hours ``/report?hours=`` takes."""

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]

STOP_GRACE: Final = 0.5
"""Seconds a stop gives the pages' WebSockets to close (a page answers at once), and
then aiohttp's request handlers to end."""

_TICKET: web.RequestKey[Ticket] = web.RequestKey("ticket", Ticket)
"""A request's connection's admission ticket (its peer on it), set by the guard."""


class WebServer:
    """Serves the browser client for one :class:`~.server.ClientServer`."""

    def __init__(self, clients: ClientServer, *, host: str | None = None, port: int,
                 request_deadline: float = REQUEST_DEADLINE,
                 journal: JournalSource | None = None) -> None:
        self.clients = clients
        self.journal = journal
        """Where ``/report`` reads the antenna journal (None: the journal is off)."""
        self.host = host
        self.port = port
        self.request_deadline = request_deadline
        self._files = page_files()
        self._names = local_names()
        self._runner: web.AppRunner | None = None
        self._pages: set[web.WebSocketResponse] = set()
        """The pages' open WebSockets, which a stop closes first."""
        self._listener: Listener | None = None
        self._quiet = QuietAiohttp(clients.trouble)
        self._closing = False

    async def start(self) -> int:
        """Starts listening; returns the port.  Raises
        :class:`~moas_gui.errors.HardwareError` saying which port when it cannot."""
        app = web.Application(middlewares=[self._guard], client_max_size=MAX_MESSAGE)
        app.router.add_get("/ws", self._websocket)
        app.router.add_get("/report", self._report)
        app.router.add_get("/{name:.*}", self._static)
        runner = web.AppRunner(app, access_log=None, handle_signals=False,
                               shutdown_timeout=STOP_GRACE,
                               keepalive_timeout=self.request_deadline, lingering_time=1.0)
        await runner.setup()
        assert runner.server is not None
        try:
            # not aiohttp's TCPSite: every connection goes through the guard first, and
            # the program's accept loop (which backs off when out of file handles)
            door = web_door(self.clients, runner.server, self.request_deadline)
            self._listener = await Listener.open(door,
                                                 self.host or None, self.port,
                                                 what="browsers", trouble=self.clients.trouble,
                                                 ssl=self.clients.tls,
                                                 handshake_deadline=self.request_deadline)
        except OSError as e:
            await runner.cleanup()
            raise HardwareError(
                f"cannot serve the browser client on TCP port {self.port}: "
                f"{e.strerror or e} (WebPort in the configuration, or --web-port, sets it)"
            ) from e
        self._runner = runner
        self._quiet.install()
        self.port = self._listener.port
        where = self.host if self.host not in (None, "") else "every interface"
        log.info("Serving the browser client on %s://%s:%d/ (%s)",
                 "https" if self.clients.tls is not None else "http",
                 _loopback(self.host), self.port, where)
        return self.port

    async def close(self) -> None:
        """Stops listening and closes every page's WebSocket."""
        self._closing = True  # a report being made stops before it is drawn
        if self._listener is not None:
            listener, self._listener = self._listener, None
            await listener.close()
        if self._pages:  # told "going away", each page answers and its handler ends:
            # aiohttp's shutdown then has no handler to wait out (a second, before)
            closing = [page.close(code=WSCloseCode.GOING_AWAY, message=b"server stopping")
                       for page in list(self._pages)]
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(STOP_GRACE):
                    await asyncio.gather(*closing, return_exceptions=True)
        if self._runner is not None:
            runner, self._runner = self._runner, None
            await runner.cleanup()
        self._quiet.remove()

    @web.middleware
    async def _guard(self, request: web.Request, handler: Handler) -> web.StreamResponse:
        gate = gate_of(request.transport)
        if gate is None or gate.ticket is None:  # the connection is gone already
            raise web.HTTPServiceUnavailable(text="The connection has closed.\n")
        gate.disarm()  # the request is here; the next one is timed after the response
        gate.ticket.greeted()  # a whole request: a browser, not a silent crowd
        try:
            return await self._checked(request, handler, gate.ticket)
        finally:
            gate.arm()

    async def _checked(self, request: web.Request, handler: Handler,
                       ticket: Ticket) -> web.StreamResponse:
        request[_TICKET] = ticket  # the peer, read once when it was accepted
        if not self.clients.allows(ticket.host):
            self.clients.trouble_line(
                "browser not allowed", logging.WARNING,
                "Refused a browser from %s: the address is not in the allowed networks "
                "(ClientAllow in the configuration decides)", ticket.address)
            raise web.HTTPForbidden(text="This address may not use the MOAS server "
                                         "(ClientAllow in its configuration decides).\n")
        # over TLS a rebound name cannot reach the page (the browser checks the certificate
        # against the name it asked for); a station reached by its public name serves it
        if self.clients.tls is None and not host_allowed(request.host, self._names):
            self.clients.trouble_line(
                "browser host", logging.WARNING,
                "Refused a browser request from %s for host %r: not a name of this computer",
                ticket.address, request.host[:80])
            raise web.HTTPMisdirectedRequest(text="Use this computer's address or name.\n")
        if request.method not in ("GET", "HEAD"):
            raise web.HTTPMethodNotAllowed(request.method, ["GET", "HEAD"])
        return await handler(request)

    async def _static(self, request: web.Request) -> web.StreamResponse:
        found = self._files.get(request.path)
        if found is None:
            raise web.HTTPNotFound(text="Not found.\n")
        return web.Response(body=found.body, content_type=found.content_type.split(";")[0],
                            charset="utf-8" if "charset" in found.content_type else None,
                            headers=_HEADERS)

    async def _websocket(self, request: web.Request) -> web.StreamResponse:
        ticket = request[_TICKET]
        address = ticket.address
        complaint = origin_complaint(request.headers.getall("Origin", []), request.host,
                                     "https" if self.clients.tls is not None else "http")
        if complaint is not None:
            self.clients.trouble_line(("websocket origin", complaint.split(" ", 2)[1]),
                                      logging.WARNING, "Refused a WebSocket from %s: %s",
                                      address, complaint)
            raise web.HTTPForbidden(text=f"Refused: {complaint}.\n")
        ws = web.WebSocketResponse(max_msg_size=MAX_MESSAGE, heartbeat=20.0)
        if not ws.can_prepare(request).ok:
            raise web.HTTPBadRequest(text="This address is for a WebSocket.\n")
        gate = gate_of(request.transport)
        handler = gate.inner if gate is not None else None
        if frames_arrived_early(handler):
            raise web.HTTPBadRequest(text="Frames were sent before the handshake's answer.\n")
        await ws.prepare(request)
        if not require_masking(handler, request.transport, lambda: self._unmasked(address)):
            self.clients.trouble_line("websocket masking", logging.ERROR,
                                      "This aiohttp's WebSocket reader cannot be checked for "
                                      "unmasked frames; WebSockets are refused")
            await ws.close(code=1011)
            return ws
        self._pages.add(ws)
        try:
            await converse(self.clients, ws, ticket)
        finally:
            self._pages.discard(ws)
        return ws

    async def _report(self, request: web.Request) -> web.StreamResponse:
        ticket = request[_TICKET]
        host = ticket.host
        shown = None
        if self.clients.needs_token(host):
            shown = await self._token_shown(request, host)
        if shown is not None and shown.busy:
            raise web.HTTPServiceUnavailable(text=f"{shown.refusal}.\n",
                                             headers={"Retry-After": "1"})
        if shown is not None and shown.wait > 0:  # too many wrong tokens: no check was made
            raise web.HTTPTooManyRequests(text=f"{shown.refusal}.\n",
                                          headers={"Retry-After": str(round(shown.wait + 0.5))})
        if shown is not None and not shown.ok:
            self.clients.trouble_line(
                "report token", logging.WARNING,
                "Refused the contest report to %s: it needs an operator's token",
                ticket.address)
            raise web.HTTPUnauthorized(
                text="The contest report needs an operator's token "
                     "(Authorization: Bearer TOKEN).\n",
                headers={"WWW-Authenticate": 'Bearer realm="moas-server"'})
        reader = self.journal() if self.journal is not None else None
        page = await self._report_page(reader, request.query)
        guard = self.clients.secrets
        if shown is not None and guard is not None and not guard.current(shown.operator):
            raise web.HTTPForbidden(text="The operator this token was for has been removed.\n")
        return web.Response(text=page, content_type="text/html", charset="utf-8",
                            headers=_REPORT_HEADERS)

    async def _token_shown(self, request: web.Request, host: str) -> SecretVerdict:
        """The operator the request's bearer token names, or why not: the server's one
        secret check (off the loop, budgeted per address and per operator)."""
        guard = self.clients.secrets
        scheme, _, token = request.headers.get("Authorization", "").partition(" ")
        if guard is None or scheme.lower() != "bearer" or not token.strip():
            return SecretVerdict(refusal="no token")
        with checking(request.get(_TICKET)):  # its place in the admission kept meanwhile
            return await guard.check_token(token.strip(), host)

    async def _report_page(self, reader: JournalReader | None,
                           query: Mapping[str, str]) -> str:
        from moas_gui.antenna_log.report import REPORTS, NothingRecorded, ReportBusy

        if reader is None:
            return _notice_page("The antenna journal is turned off: there is no report.")
        try:
            asked = _asked_period(query, time.time())
            # the journal is read and the charts drawn in the report's own thread, one
            # report at a time: the event loop only waits for the page
            return await REPORTS.run(lambda: _report_job(reader, asked,
                                                         lambda: self._closing))
        except ReportBusy as exc:
            raise web.HTTPServiceUnavailable(
                text=f"The contest report cannot be made now: {exc}; try again in a few "
                     "seconds.\n", headers={"Retry-After": "5"}) from None
        except NothingRecorded as exc:
            return _notice_page(html.escape(str(exc)))
        except ValueError as exc:
            raise web.HTTPBadRequest(text=f"{exc}\n") from None
        except (sqlite3.Error, OSError) as exc:
            self.clients.trouble_line("report journal", logging.ERROR,
                                      "The contest report could not read the antenna "
                                      "journal: %s", exc)
            raise web.HTTPServiceUnavailable(
                text=f"Could not read the antenna journal: {exc}\n") from None

    def _unmasked(self, address: str) -> None:
        self.clients.trouble_line("websocket unmasked", logging.WARNING,
                                  "Closed a WebSocket from %s: it sent an unmasked frame "
                                  "(RFC 6455 forbids it)", address)


def _asked_period(query: Mapping[str, str], now: float) -> Period | None:
    """The period ``/report`` asks for: None for the whole journal; an end left out is
    infinite (the journal's first or last time, :func:`~moas_gui.antenna_log.report.bounded_period`).
    Raises ``ValueError`` saying what is wrong with the query."""
    from moas_gui.antenna_log.adif import parse_utc
    from moas_gui.antenna_log.records import Period
    from moas_gui.antenna_log.report import last_hours

    if "hours" in query:
        try:
            hours = float(query["hours"])
        except ValueError:
            hours = -1.0
        if not 0 < hours <= MAX_REPORT_HOURS:
            raise ValueError(f"hours={query['hours'][:40]}: give a number of hours from 1 to "
                             f"{MAX_REPORT_HOURS}")
        return last_hours(now, hours)
    if "from" in query or "to" in query:
        try:
            start = parse_utc(query["from"]) if "from" in query else -math.inf
            end = parse_utc(query["to"]) if "to" in query else math.inf
        except ValueError as exc:
            raise ValueError(f"from/to: {exc}") from None
        if start >= end:
            raise ValueError("from/to: from is not before to")
        return Period(start, end)
    return None


def _report_job(reader: JournalReader, asked: Period | None,
                closing: Callable[[], bool]) -> str:
    """The report page for ``asked`` (in the report's thread): the period bounded to the
    journal, read, drawn; not drawn once ``closing()`` (the server stops).  Raises what
    :func:`~moas_gui.antenna_log.report.bounded_period` raises."""
    from moas_gui.antenna_log.report import ReportBusy, bounded_period, contest_report
    from moas_gui.antenna_log.report_charts import report_html

    period = bounded_period(reader, asked, time.time())
    if period is None:
        return _notice_page("The antenna journal is empty: nothing has been recorded yet.")
    report = contest_report(reader, period)
    if closing():
        raise ReportBusy("the server is stopping")
    return report_html(report)


def _notice_page(text: str) -> str:
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<title>Contest report</title></head><body><h1>Contest report</h1>"
            f"<p id=\"notice\">{text}</p></body></html>\n")


def _loopback(host: str | None) -> str:
    return "127.0.0.1" if host in (None, "", "0.0.0.0", "::") else str(host)


async def start_web(clients: ClientServer, host: str | None, port: int,
                    journal: JournalSource | None = None) -> WebServer | None:
    """A started :class:`WebServer`, or ``None`` (and an Error log line) when it cannot listen."""
    server = WebServer(clients, host=host, port=port, journal=journal)
    try:
        await server.start()
    except HardwareError as e:
        log.error("Browser clients cannot connect: %s", e)
        return None
    return server


__all__ = ["StaticFile", "WebServer", "page_files", "start_web"]
