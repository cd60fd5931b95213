"""The client protocol over a WebSocket: another transport for the same connections.

A browser cannot open a TCP socket, so the browser client speaks the client
protocol over a WebSocket, and nothing else changes: each text message the page
sends is one protocol line (a message holding several lines is read as those
lines), answered by the same :func:`~.dispatch.answer` as a TCP line, and every
reply and event goes back as one text message holding one JSON object.  The
connection is a :class:`~.connection.Connection` attached to the
:class:`~.server.ClientServer`, so it is counted, logged, and sent events as a
TCP client is, with the same bad-line rule and the same errors, and the same
clocks: ``hello`` within the client server's ``hello_deadline`` and then a
message at least every ``keepalive`` seconds (an empty message will do; the
page sends one when it has had nothing to ask for a while).  WebSocket pings
and pongs keep the connection itself checked (every 20 s) but do not count as
messages.

:class:`WebSocketOutlet` is that connection's writer: :meth:`write` queues a
message and returns at once, a task sends the queue in order, and the bytes
not yet sent count towards the connection's ``max_pending`` (a page that stops
reading is cut off, and nobody waits for it).
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque

from aiohttp import WSMsgType, web

from moas_gui.edge.admission import Ticket

from .backend import ErrorCode
from .dispatch import answer
from .framing import MAX_LINE
from .messages import reply_error
from .server import ClientServer

log = logging.getLogger(__name__)

MAX_MESSAGE = 4 * MAX_LINE
"""Bigger messages close the WebSocket (1009); up to this size a line over
:data:`~.framing.MAX_LINE` gets the protocol's error reply, as on TCP."""


class WebSocketOutlet:
    """A :class:`~.connection.LineWriter` (and its transport) for one WebSocket."""

    def __init__(self, ws: web.WebSocketResponse) -> None:
        self._ws = ws
        self._queue: deque[str] = deque()
        self._queued = 0
        self._wake = asyncio.Event()
        self._closing = False
        self._aborted = False
        self._sender = asyncio.get_running_loop().create_task(self._send_all())

    @property
    def transport(self) -> WebSocketOutlet:
        return self

    # -- the transport side ------------------------------------------------------------
    def write(self, data: bytes) -> None:
        if self._closing:
            return
        text = data.decode("utf-8").rstrip("\n")
        self._queue.append(text)
        self._queued += len(text)
        self._wake.set()

    def is_closing(self) -> bool:
        return self._closing

    def get_write_buffer_size(self) -> int:
        underlying = self._ws.get_extra_info("transport")
        buffered = underlying.get_write_buffer_size() if underlying is not None else 0
        return self._queued + int(buffered)

    def abort(self) -> None:
        self._closing = self._aborted = True
        self._queue.clear()
        self._sender.cancel()
        underlying = self._ws.get_extra_info("transport")
        if underlying is not None:
            underlying.abort()

    # -- the writer side -----------------------------------------------------------------
    def close(self) -> None:
        """Closes after what is queued has been sent."""
        self._closing = True
        self._wake.set()

    async def aborted(self) -> None:
        """Waits for the sender's end after :meth:`abort` (whatever it ended with is
        retrieved, never raised)."""
        await asyncio.wait({self._sender})
        if not self._sender.cancelled():
            self._sender.exception()

    async def finished(self) -> None:
        """Waits for the sender to end (call after :meth:`close` or :meth:`abort`)."""
        self.close()
        try:
            await self._sender
        except asyncio.CancelledError:
            if not self._aborted:
                raise

    async def _send_all(self) -> None:
        ws = self._ws
        try:
            while True:
                while self._queue:
                    text = self._queue.popleft()
                    self._queued -= len(text)
                    await ws.send_str(text)
                if self._closing:
                    break
                self._wake.clear()
                await self._wake.wait()
        except (ConnectionError, RuntimeError) as e:
            log.debug("A browser client's WebSocket ended while sending: %s", e)
        finally:
            if not ws.closed and not self._aborted:
                await ws.close()


async def converse(clients: ClientServer, ws: web.WebSocketResponse, ticket: Ticket) -> None:
    """Serves one prepared WebSocket until it closes; ``ticket`` is its web connection's
    place in the admission (its peer on it), which its hello greets."""
    outlet = WebSocketOutlet(ws)
    address = ticket.address
    conn = clients.attach(outlet, ticket)
    if conn is None:
        clients.trouble_line(("over a limit", "websocket"), logging.WARNING,
                             "Refused a browser client from %s: %d clients are connected, the "
                             "most this server takes at once (moas-server --max-clients sets "
                             "it)", address, clients.client_limit)
        outlet.write(reply_error(None, ErrorCode.UNAVAILABLE,
                                 f"the server already serves {clients.client_limit} clients, "
                                 "its limit; try again when one has left"))
        await outlet.finished()
        return
    clients.connected_line("Browser client connected from %s", address)
    lost: str | None = None
    loop = asyncio.get_running_loop()
    hello_by = loop.time() + clients.hello_deadline
    try:
        while True:
            wait = clients.keepalive if conn.greeted else hello_by - loop.time()
            try:
                message = await ws.receive(timeout=max(wait, 0.001))
            except TimeoutError:
                conn.close(clients.timed_out(conn))
                break
            if message.type is WSMsgType.TEXT:
                data = message.data.encode("utf-8", "surrogatepass")
            elif message.type is WSMsgType.BINARY:
                data = bytes(message.data)
            else:
                if message.type is WSMsgType.ERROR:
                    lost = str(ws.exception() or "error")
                break
            greeted = conn.greeted
            for item in conn.splitter.feed(data + b"\n"):
                if conn.closed:  # ended meanwhile (its operator removed): nothing obeyed
                    break
                waiting = answer(clients.backend, conn, item)
                if waiting is not None:  # a token checked off the loop
                    await waiting
                if conn.closed:
                    break
            if conn.greeted and not greeted:
                conn.note("Browser client connected from %s", address)
            if conn.closed:
                break
            await asyncio.sleep(0)  # a page sending a flood must not starve the others
    finally:
        clients.detach(conn)
        clients.log_departure(conn, "Browser client", lost)
        try:
            async with asyncio.timeout(clients.close_grace):
                await outlet.finished()
        except TimeoutError:
            outlet.abort()
            await outlet.aborted()


__all__ = ["MAX_MESSAGE", "WebSocketOutlet", "converse"]
