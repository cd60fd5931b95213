"""The client protocol server: TCP, JSON lines, one asyncio loop, no Qt.

::

    server = ClientServer(backend, port=config.tcp_port, allow=config.client_allow)
    await server.start()
    ...                      # the app calls server.publish_radio(entry) etc. after changes
    await server.close()

Each connection is read line by line (:mod:`.framing`), and each line is
answered exactly once, in order (:mod:`.dispatch`, :mod:`.requests`); the
backend (:mod:`.backend`) does the work.  Events are written to every greeted client
the moment they are published (:mod:`.connection` explains why a client that
stops reading cannot hold anyone up).  Every connection comes through the
program's one door (:mod:`moas_gui.edge.gate`, :meth:`ClientServer.door`): peers
outside the allowed networks (:mod:`.access`) are closed at once, and those over a
limit told why.  Every call here runs on the loop's
thread; none of them waits.

Limits: at most ``max_clients`` connections at once (fewer when the process
may open few files: half its open-file limit), and at most ``per_address``
from one address; the browser client's web connections count against the same
two limits (:mod:`.admission`).  A connection beyond either is told so in one
error line and closed.  A connection must say ``hello`` within
``hello_deadline`` seconds, and a greeted one that stays silent for
``keepalive`` seconds is closed (clients with nothing to ask send a blank line
now and then: docs/client-protocol.md).  Each client's unread output is bounded
(``max_pending``), and so is the sum of all of them (``max_pending_total``):
when the sum is over, the clients with the most unread output are cut first.

Log lines (logger ``moas_gui.net``): hellos and the disconnects of greeted
clients at Info (a connection's opening at Debug); refused peers and clients
cut off for not reading at Warning; each bad line or refused request at Debug;
a backend failure at Error with its traceback.  Everything that a peer can
repeat at will -- refused peers, connections over a limit, connections closed
before or for want of a ``hello``, silent ones, the system running out of file
handles while accepting -- writes one line per minute and kind, saying how
many like it were left out (:attr:`ClientServer.trouble`, which the web server
shares).
"""

from __future__ import annotations

import asyncio
import logging
import ssl
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from moas_gui.edge.admission import (
    DEFAULT_BEFORE_HELLO,
    DEFAULT_PER_ADDRESS,
    Admission,
    Refused,
    Ticket,
)
from moas_gui.edge.gate import Allows, Door, Gate, Open, gate_of, streams
from moas_gui.edge.listener import Listener
from moas_gui.errors import HardwareError
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.net.secrets import SecretGuard
from moas_gui.operators import OperatorBook

from .access import allowed_networks, is_allowed
from .admission import HELLO_DEADLINE, KEEPALIVE
from .backend import ClientBackend, ErrorCode, LogLevel, RequestError
from .connection import (
    ClientInfo,
    Connection,
    LayoutKey,
    LineWriter,
    cut_slowest,
)
from .dispatch import MAX_BAD_LINES, answer
from .fd_limit import fitting_client_limit
from .identity import LOCAL_ADDRESSES, anonymous, is_local, token_needed
from .loop_faults import guard_loop_faults
from .memory import give_back_memory
from .messages import MessageEncodeError, event, reply_error

log = logging.getLogger(__name__)

DEFAULT_PORT = 12059
LOG_LEVELS: tuple[LogLevel, ...] = ("error", "info", "debug")
_READ_CHUNK = 16_384
"""Bytes read from a client at once (and what its reader holds before it stops
taking more from the socket): a few hundred requests."""
_FEED = 1024
"""Bytes of requests split into lines at once."""
_LINES_PER_TURN = 8
"""Requests of one client answered before the loop serves everything else once."""
_CROWD = 32
"""Clients at once after which their leaving gives memory back to the system."""
CHATTER_BURST = 120
"""Info lines a minute about the clients of one address (a hello and a goodbye are two,
a page's WebSocket three): far more than a station's computers reconnecting, or a
benchmark opening dozens of pages, ever write; beyond them, one a minute with a count
(a program connecting in a loop)."""
DEFAULT_MAX_CLIENTS = 200
"""Connections served at once unless ``--max-clients`` says otherwise."""
DEFAULT_MAX_PENDING_TOTAL = 32 << 20
"""Bytes of unread output, summed over every client, before the slowest are cut."""
_HINTS = {"address": " (moas-server --max-per-address sets it)",
          "total": " (moas-server --max-clients sets it)"}
"""What a refusal line adds, by the limit that refused."""


class ClientServer:
    """Serves the client protocol for one backend; implements :class:`~.backend.EventSink`.

    ``host`` ``None`` listens on every interface (access control decides who
    may stay); tests give ``"127.0.0.1"`` and port 0.  ``allow`` is the
    configuration's ``ClientAllow`` (``None``: loopback and private networks).
    ``max_pending`` bounds each client's outgoing queue in bytes and
    ``max_pending_total`` the sum of them all; ``max_clients`` bounds the
    connections served at once; ``max_layouts`` bounds the layouts one
    connection follows.  With ``host``
    ``None`` and port 0 each address family would get a port of its own: give
    a port, or a host, then.
    """

    close_grace = 2.0
    """Seconds a closing connection may take to send what is queued."""

    def __init__(
        self,
        backend: ClientBackend,
        *,
        host: str | None = None,
        port: int = DEFAULT_PORT,
        allow: Iterable[str] | None = None,
        max_pending: int = 1 << 20,
        max_pending_total: int = DEFAULT_MAX_PENDING_TOTAL,
        max_clients: int = DEFAULT_MAX_CLIENTS,
        max_layouts: int = 16,
        per_address: int = DEFAULT_PER_ADDRESS,
        before_hello: int = DEFAULT_BEFORE_HELLO,
        hello_deadline: float = HELLO_DEADLINE,
        keepalive: float = KEEPALIVE,
        require_token: bool = False,
        operators: OperatorBook | None = None,
        tls: ssl.SSLContext | None = None,
        secrets: SecretGuard | None = None,
    ) -> None:
        if max_clients < 1:
            raise ValueError(f"max_clients must be at least 1, not {max_clients}")
        if per_address < 1:
            raise ValueError(f"per_address must be at least 1, not {per_address}")
        self.backend = backend
        self.host = host
        self.port = port
        self._allowed = allowed_networks(allow)
        self.max_pending = max_pending
        self.max_pending_total = max_pending_total
        self.max_clients = max_clients
        self.client_limit = max_clients
        """The connections served at once: ``max_clients``, or fewer when the
        process may open few files (set by :meth:`start`)."""
        self.max_layouts = max_layouts
        self.admission = Admission(max_clients, per_address, before_hello=before_hello,
                                   trouble=LogLimiter(), what="client connections")
        """Open connections of both transports, in all and per address: the program's
        admission policy (:mod:`moas_gui.edge.admission`)."""
        self.hello_deadline = hello_deadline
        self.keepalive = keepalive
        self.require_token = require_token
        """Clients from ``ClientAllow`` networks need an operator's token too."""
        self.operators = operators
        """The station's operators (None: no token is ever valid)."""
        self.secrets = secrets if secrets is not None or operators is None \
            else SecretGuard(operators)
        """Where tokens are checked, off the loop and budgeted (the server's one guard,
        shared with the other fronts; a guard of its own when only a book is given)."""
        self._own_secrets = secrets is None and self.secrets is not None
        self.local_addresses: tuple[object, ...] = LOCAL_ADDRESSES
        """The addresses that are this computer (never need a token); a test driving a
        browser (which connects from ``127.0.0.1``) empties it to play a LAN peer."""
        self.fingerprint: str | None = None
        """The SHA-256 fingerprint of the certificate ``tls`` serves (set by who made it)."""
        self.tls = tls
        """Serve TLS with this context; then peers outside ``ClientAllow`` are admitted
        (and must give a token)."""
        self.chatter = LogLimiter(burst=CHATTER_BURST)
        """The Info lines about greeted clients, all addresses together."""
        self._unchecked = 0
        """Bytes queued since the sum of all clients' output was last checked."""
        self._crowd = 0
        """The most clients connected at once since memory was last given back."""
        self._trim: asyncio.Handle | None = None
        self._loop_faults = LogLimiter()
        self._restore_handler: Callable[[], None] | None = None
        self._server: Listener | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._connections: dict[Connection, None] = {}
        self._tasks: set[asyncio.Task[Any]] = set()
        self._layout_refresh: asyncio.Handle | None = None

    @property
    def trouble(self) -> LogLimiter:
        """One log line a minute per kind of trouble from outside, whatever the address:
        the admission's, which the gates of both ports and the web server share."""
        return self.admission.trouble

    @trouble.setter
    def trouble(self, limiter: LogLimiter) -> None:
        self.admission.trouble = limiter

    def door(self, front: str, who: str, open_: Open, refusal: Callable[[str], bytes], *,
             allows: Allows | None = None, touch_on_data: bool = False,
             request_deadline: float | None = None,
             late: Callable[[Gate], None] | None = None) -> Door:
        """The door of a port whose connections count in :attr:`admission` (the client
        port's, the web port's): refusal lines name the option that sets the limit, and
        a peer refused is told ``refusal(sentence)``."""
        return Door(self.admission, open_, front, who=who, allows=allows,
                    refusal=lambda refused: refusal(self.refusal_reply(refused)),
                    hints=_HINTS, touch_on_data=touch_on_data,
                    request_deadline=request_deadline, late=late)

    # ---- life -----------------------------------------------------------------------

    async def start(self) -> int:
        """Starts listening; returns the port (the system's choice when 0 was given).

        Raises :class:`~moas_gui.errors.HardwareError` saying which port when it
        cannot listen (the port is in use, say)."""
        self._loop = asyncio.get_running_loop()
        self.client_limit = fitting_client_limit(self.max_clients)
        self.admission.total = self.client_limit
        if self._restore_handler is None:
            self._restore_handler = guard_loop_faults(self._loop, self._loop_faults)
        try:
            # over TLS, the handshake gets the hello deadline's size (and is admitted first)
            door = self.door("client", "a client", streams(self._serve, _READ_CHUNK),
                             lambda why: reply_error(None, ErrorCode.UNAVAILABLE, why),
                             allows=self.refuses)
            self._server = await Listener.open(door, self.host, self.port,
                                               what="clients", trouble=self.trouble,
                                               ssl=self.tls,
                                               handshake_deadline=self.hello_deadline)
        except OSError as e:
            raise HardwareError(
                f"cannot accept clients on TCP port {self.port}: {e.strerror or e} "
                "(is another moas-server running? TCPPort in the configuration sets the port)"
            ) from e
        self.port = self._server.port
        if self.secrets is not None:  # a removed operator's sessions end, whoever removed it
            self.secrets.listen(self.end_operator)
        where = self.host if self.host is not None else "every interface"
        log.info("Accepting clients on TCP port %d (%s)%s", self.port, where,
                 " over TLS" if self.tls is not None else "")
        if not self.require_token:
            log.info("Clients from the allowed networks (ClientAllow) need no token: the LAN "
                     "is kept open (moas-server --require-token closes it)")
        return self.port

    async def close(self) -> None:
        """Stops listening and closes every connection."""
        if self._server is not None:
            await self._server.close()
            self._server = None
        self.admission.close()
        if self.secrets is not None:
            self.secrets.unlisten(self.end_operator)
            if self._own_secrets:
                self.secrets.close()
        for conn in tuple(self._connections):
            conn.close("the server is closing")
        if self._layout_refresh is not None:
            self._layout_refresh.cancel()
            self._layout_refresh = None
        if self._trim is not None:
            self._trim.cancel()
            self._trim = None
        tasks = tuple(self._tasks)
        if tasks:
            _done, pending = await asyncio.wait(tasks, timeout=self.close_grace + 1.0)
            for task in pending:
                task.cancel()
            await asyncio.gather(*pending, return_exceptions=True)
        if self._restore_handler is not None:
            self._restore_handler()
            self._restore_handler = None

    def set_allow(self, allow: Iterable[str] | None) -> None:
        """New ``ClientAllow`` (after a configuration is loaded); applies to new connections."""
        self._allowed = allowed_networks(allow)

    def allows(self, host: str) -> bool:
        """Whether a peer at ``host`` may connect: this computer, a ``ClientAllow``
        network, or -- over TLS -- anywhere (then with a token).  Other transports ask too."""
        return (self.tls is not None or is_local(host, self.local_addresses)
                or is_allowed(host, self._allowed))

    def refuses(self, host: str) -> str | None:
        """Why a peer at ``host`` may not connect at all (``None``: it may): the client
        port's door asks, before the admission's limits."""
        if self.allows(host):
            return None
        return ("the address is not in the allowed networks (ClientAllow in the "
                "configuration decides)")

    def needs_token(self, host: str) -> bool:
        """Whether a peer at ``host`` must show an operator's token to see anything (the
        same rule as a connection's identity: :func:`.identity.token_needed`)."""
        return token_needed(host, self._allowed, self.require_token, self.local_addresses)

    def identify(self, conn: Connection, host: str) -> None:
        """Gives a new connection its identity before hello (:mod:`.identity`)."""
        conn.identity = anonymous(host, conn.address, self._allowed, self.require_token,
                                  self.local_addresses)
        guard = self.secrets
        if guard is not None:  # dispatch keeps the connection's place while it waits
            conn.authenticate = lambda token: guard.check_token(token, host)

    def end_operator(self, name: str) -> int:
        """Closes every connection of the operator ``name`` (just removed); how many."""
        ended = 0
        for conn in tuple(self._connections):
            operator = conn.identity.operator
            if operator is not None and operator.name.lower() == name.lower():
                conn.abort(f'operator "{operator.name}" was removed')
                ended += 1
        return ended

    def attach(self, writer: LineWriter, ticket: Ticket) -> Connection | None:
        """A connection carried by another transport (the browser client's
        WebSocket, :mod:`.web`), with the same limits as a TCP one: its lines
        are answered by :func:`~.dispatch.answer` and it gets events as TCP
        clients do, until :meth:`detach`.  ``None`` when the server already
        serves as many clients as it takes (the caller says so and closes).  ``ticket``
        is the connection's place in :attr:`admission` (its peer on it): a ``hello``
        greets it."""
        if len(self._connections) >= self.client_limit:
            return None
        conn = self._connection(writer, ticket)
        self._connections[conn] = None
        self._crowd = max(self._crowd, len(self._connections))
        return conn

    def detach(self, conn: Connection) -> None:
        if self._connections.pop(conn, False) is None:
            self._after_departure()

    @property
    def client_count(self) -> int:
        return len(self._connections)

    @property
    def pending_total(self) -> int:
        """Bytes of output waiting to be read, summed over every client."""
        return sum(conn.pending for conn in self._connections)

    def _queued(self, size: int) -> None:
        """Called for every line queued; checks the sum now and then (often
        enough that it never gets far over :attr:`max_pending_total`)."""
        self._unchecked += size
        if self._unchecked >= max(1, self.max_pending_total // 16):
            self._unchecked = 0
            cut_slowest(self._connections, self.max_pending_total)

    def clients(self) -> tuple[ClientInfo, ...]:
        return tuple(conn.info() for conn in self._connections)

    # ---- events (EventSink) ---------------------------------------------------------

    def publish_state(self) -> None:
        try:
            snapshot = self.backend.snapshot()
            line = event("state", snapshot)
        except RequestError as e:
            log.debug("No state event for clients: %s", e.message)
            return
        except Exception:
            log.exception("Could not write the state event for clients")
            return
        self._broadcast(line)
        self.layouts_may_have_changed()

    def publish_radio(self, entry: Mapping[str, Any]) -> None:
        self._publish("radio", entry)

    def publish_rotator(self, entry: Mapping[str, Any]) -> None:
        self._publish("rotator", entry)

    def publish_switch(self, entry: Mapping[str, Any]) -> None:
        self._publish("switch", entry)

    @property
    def log_wanted(self) -> bool:
        """Whether any client asked for the log (``"log": true``): with none, a log
        record is not even formatted for clients (:class:`~.log_events.ClientLogHandler`)."""
        return any(conn.greeted and conn.wants_log for conn in self._connections)

    def publish_log(self, level: LogLevel, message: str) -> None:
        if level not in LOG_LEVELS:
            raise ValueError(f"log level {level!r} is not one of {', '.join(LOG_LEVELS)}")
        if not self.log_wanted:
            return
        try:
            line = event("log", {"level": level, "message": str(message)})
        except MessageEncodeError:
            log.exception("Could not write a log event for clients")
            return
        for conn in tuple(self._connections):
            if conn.greeted and conn.wants_log:
                conn.send(line)

    def layouts_may_have_changed(self) -> None:
        """Re-checks every followed layout soon (once per loop turn, however
        often this is called) and sends those that changed."""
        if self._layout_refresh is None and self._loop is not None and not self._loop.is_closed():
            self._layout_refresh = self._loop.call_soon(self._refresh_layouts)

    def _publish(self, name: str, entry: Mapping[str, Any]) -> None:
        if not self._connections:
            return
        try:
            line = event(name, entry)
        except MessageEncodeError:
            log.exception("Could not write a %s event for clients", name)
            return
        self._broadcast(line)

    def _broadcast(self, line: bytes) -> None:
        for conn in tuple(self._connections):
            if conn.greeted:
                conn.send(line)

    def _refresh_layouts(self) -> None:
        self._layout_refresh = None
        fresh: dict[LayoutKey, tuple[Any, bytes] | None] = {}
        for conn in tuple(self._connections):
            for key, last in tuple(conn.layouts.items()):
                if key not in fresh:
                    fresh[key] = self._ask_layout(key)
                now = fresh[key]
                if now is not None and now[0] != last and not conn.closed:
                    conn.layouts[key] = now[0]
                    conn.send(now[1])

    def _ask_layout(self, key: LayoutKey) -> tuple[Any, bytes] | None:
        try:
            layout = self.backend.layout(*key)
            return layout, event("layout", layout)
        except RequestError as e:
            log.debug("Layout %s not sent to clients: %s", key, e.message)
        except Exception:
            log.exception("Could not refresh layout %s for clients", key)
        return None

    # ---- connections ----------------------------------------------------------------

    def _take_ticket(self, conn: Connection, ticket: Ticket) -> None:
        """``conn`` keeps its admission ticket: touched by every line, greeted by its
        hello; should the admission close it, it is told why first."""
        conn.ticket = ticket

        def evict(why: str) -> None:
            conn.reply_error(None, ErrorCode.UNAVAILABLE, why)
            conn.close(why)

        ticket.set_evict(evict)
        # a token that names an operator moves the connection to the operators' own pool
        conn.identified = lambda identity: None if not identity.is_operator \
            else self._promote(conn, ticket)

    def _promote(self, conn: Connection, ticket: Ticket) -> None:
        if not ticket.operator():
            self.trouble_line("operators' pool full", logging.WARNING,
                              "%s: the operators' own connections are all in use; %s stays "
                              "with the others", conn.address, conn.identity.name)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        if task is not None:
            self._tasks.add(task)
        try:
            await self._converse(reader, writer)
        finally:
            if task is not None:
                self._tasks.discard(task)

    def refusal_reply(self, refusal: Refused) -> str:
        """The sentence a refused client is told."""
        if refusal.limit == "address":
            return (f"this address already holds {self.admission.per_address} connections, "
                    "the most one address may; close one and try again")
        if refusal.limit == "hello":
            return (f"this address already has {self.admission.before_hello} connections "
                    "that have not said hello; try again when they have")
        return (f"the server already serves {self.client_limit} clients, its limit; "
                "try again when one has left")

    def connected_line(self, message: str, *args: object) -> None:
        """A Debug line about a connection opening, within the clients' share of the log
        (a crowd connecting as fast as it can writes no more than the share)."""
        held = self.chatter.allow("connected")
        if held is not None:
            log.debug(message + "%s", *args, held_text(held, "more connections opened"))

    def trouble_line(self, kind: object, level: int, message: str, *args: object) -> None:
        """Logs ``message`` unless a line of ``kind`` went out in the last minute; the
        next one that does says how many were left out."""
        held = self.trouble.allow(kind)
        if held is not None:
            log.log(level, message + "%s", *args, held_text(held))

    def _connection(self, writer: LineWriter, ticket: Ticket) -> Connection:
        """A new connection of either transport, its peer the one its ticket carries."""
        conn = Connection(writer, ticket.address, max_pending=self.max_pending,
                          max_layouts=self.max_layouts, on_queued=self._queued)
        # one share of the log for all addresses: a crowd of addresses writes no more
        conn.chatter = lambda: self.chatter.allow("clients")
        self._take_ticket(conn, ticket)
        self.identify(conn, ticket.host)
        return conn

    async def _converse(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        gate = gate_of(writer.transport)
        if gate is None or gate.ticket is None:  # gone before it was served
            writer.close()
            return
        conn = self._connection(writer, gate.ticket)
        self._connections[conn] = None
        self._crowd = max(self._crowd, len(self._connections))
        self.connected_line("Client connected from %s", conn.address)
        lost: str | None = None
        loop = asyncio.get_running_loop()
        hello_by = loop.time() + self.hello_deadline
        try:
            while not conn.closed:
                wait = self.keepalive if conn.greeted else hello_by - loop.time()
                try:
                    async with asyncio.timeout(max(wait, 0.0)):
                        data = await reader.read(_READ_CHUNK)
                except TimeoutError:
                    conn.close(self.timed_out(conn))
                    break
                if not data:
                    break
                if conn.ticket is not None:
                    conn.ticket.touch()
                await self._answer(conn, data)
        except (ConnectionError, OSError) as e:
            lost = str(e) or type(e).__name__
        finally:
            del self._connections[conn]
            self.log_departure(conn, "Client", lost)
            self._after_departure()
            if not conn.closed:
                writer.close()
            await self._closed(writer)

    async def _answer(self, conn: Connection, data: bytes) -> None:
        """Answers the lines in ``data``, a few at a time: a client sending a flood
        must not starve the others or the switches (nor hold many lines at once)."""
        answered = 0
        for start in range(0, len(data), _FEED):
            for item in conn.splitter.feed(data[start : start + _FEED]):
                waiting = answer(self.backend, conn, item)
                if waiting is not None:  # a token checked off the loop; the next line waits
                    await waiting
                if conn.closed:
                    return
                answered += 1
                if answered % _LINES_PER_TURN == 0:
                    await asyncio.sleep(0)
        await asyncio.sleep(0)

    def _after_departure(self) -> None:
        """Once most of a crowd of clients has gone, gives their memory back (soon,
        once for however many leave in the same moment)."""
        if self._crowd >= _CROWD and len(self._connections) <= self._crowd // 2:
            self._crowd = len(self._connections)
            if self._trim is None and self._loop is not None:
                self._trim = self._loop.call_later(0.5, self._give_back)

    def _give_back(self) -> None:
        self._trim = None
        if give_back_memory():
            log.debug("Gave freed memory back to the system (%d clients now)",
                      len(self._connections))

    async def _closed(self, writer: asyncio.StreamWriter) -> None:
        """Waits for what is queued to be sent, but not for a peer that never reads."""
        try:
            async with asyncio.timeout(self.close_grace):
                await writer.wait_closed()
        except TimeoutError:
            writer.transport.abort()
        except Exception:  # noqa: BLE001 - the connection is gone either way
            log.debug("Closing a client connection: the transport reported an error")


    def timed_out(self, conn: Connection) -> str:
        """Why ``conn`` is closed for its silence."""
        if conn.greeted:
            return f"silent for {self.keepalive:g} s (clients send a blank line when idle)"
        return f"no hello within {self.hello_deadline:g} s"

    def log_departure(self, conn: Connection, what: str, lost: str | None) -> None:
        """Logs a connection's end: always for a greeted client (at Info), once a
        minute per way of ending for one that never said hello."""
        if conn.close_reason is not None:
            how = f"disconnected by the server: {conn.close_reason}"
        elif lost is not None:
            how = f"connection lost: {lost}"
        else:
            how = "disconnected"
        if conn.greeted:
            conn.note("%s %s %s", what, _who(conn), how)
        else:
            kind = ("left before hello", what, (conn.close_reason or lost or "")[:24])
            never = "" if "hello" in how else " (it never said hello)"
            self.trouble_line(kind, logging.INFO, "%s %s %s%s", what, _who(conn), how, never)


def _who(conn: Connection) -> str:
    return f'"{conn.name}" at {conn.address}' if conn.name else f"at {conn.address}"


__all__ = [
    "DEFAULT_MAX_CLIENTS",
    "DEFAULT_MAX_PENDING_TOTAL",
    "DEFAULT_PORT",
    "LOG_LEVELS",
    "MAX_BAD_LINES",
    "ClientServer",
]
