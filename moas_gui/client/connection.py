"""An asyncio client of the moas-gui client protocol (no Qt).

:class:`ClientConnection` keeps one TCP connection to a server open for as
long as it runs: it connects, says ``hello``, keeps the server's snapshot
current from the change events, matches each reply to its request by ``id``,
and when the connection fails or drops it tries again after a growing pause
(:class:`Backoff`), for ever, until :meth:`ClientConnection.close`::

    start() -> CONNECTING --hello answered--> CONNECTED --lost--> RECONNECTING --+
                   |                              ^                              |
                   +--refused / timed out---------+------------ after back-off --+

Requests fail quickly rather than hang: with :class:`NotConnected` when there
is no connection, with :class:`RequestTimeout` when no reply comes in time,
with :class:`ConnectionLost` when the connection drops before the reply, and
with :class:`ServerError` (carrying the protocol's error ``code`` and the
server's sentence) when the server refuses.  A connection with nothing to ask
sends a blank line every ``keepalive`` seconds: the server closes a client
that stays silent for two minutes (docs/client-protocol.md).  Anything unusable the server
sends is reported to listeners as :class:`~moas_gui.client.events.ProblemSeen`
and logged (logger ``moas_gui.client``); the connection and the snapshot carry
on unharmed.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import logging
import socket
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal

from moas_gui import __version__
from moas_gui.errors import MoasError, ProtocolError
from moas_gui.retry import Backoff, keep_trying

from .codec import ClientCodec, Event, Garbled, Reply
from .events import (
    TOKEN_ASKED,
    TOKEN_REFUSED,
    ClientEvent,
    LayoutChanged,
    LinkChanged,
    LinkState,
    LogReceived,
    ProblemSeen,
    RadioChanged,
    RotatorChanged,
    StateReceived,
    SwitchChanged,
    TokenWanted,
)
from .model import (
    LayoutView,
    RadioKey,
    Snapshot,
    parse_layout,
    parse_radio,
    parse_rotator,
    parse_snapshot,
    parse_switch,
)

__all__ = [
    "Backoff",
    "ClientConnection",
    "ClientError",
    "ConnectionLost",
    "Listener",
    "NotConnected",
    "RequestTimeout",
    "Selection",
    "ServerError",
    "Target",
]

log = logging.getLogger(__name__)

Target = Literal["both", "tx", "rx"]
Listener = Callable[[ClientEvent], None]


class ClientError(MoasError):
    """A request that did not get a successful reply."""


class ServerError(ClientError):
    """The server refused a request: ``code`` is the protocol's error code."""

    def __init__(self, cmd: str, code: str, message: str) -> None:
        self.cmd = cmd
        self.code = code
        self.message = message
        super().__init__(f"{cmd}: {message} ({code})")


class NotConnected(ClientError):
    """There is no connection to send the request on."""


class ConnectionLost(ClientError):
    """The connection dropped before the reply came."""


class RequestTimeout(ClientError):
    """No reply came in time."""


@dataclass(frozen=True, slots=True)
class Selection:
    """The antennas of a radio after a ``select`` or ``relative`` request."""

    tx: int | None
    rx: int | None


class ClientConnection:
    """One client's connection to a moas-gui server; see the module notes."""

    def __init__(
        self,
        host: str,
        port: int,
        *,
        name: str = f"moas-client {__version__}",
        station: int | None = None,
        radio: int | None = None,
        want_log: bool = False,
        timeout: float = 5.0,
        connect_timeout: float = 3.0,
        backoff: Backoff | None = None,
        keepalive: float = 30.0,
        token: str | None = None,
        tls: bool = False,
        pin: str | None = None,
        trust: Callable[[str], bool] | None = None,
        local_host: str | None = None,
    ) -> None:
        self.host = host
        self.local_host = local_host
        """The local address to connect from (None: the system's choice)."""
        self.token = token
        """An operator's token, said in ``hello`` (docs/security.md); never logged."""
        self.tls = tls
        """Connect over TLS; the server's certificate is judged by its fingerprint."""
        self.pin = pin
        """The SHA-256 fingerprint the server must show (``moas-client --pin``)."""
        self.trust = trust
        """Without a pin: asked with the fingerprint seen (trust on first use); True to go
        on (the caller then keeps it as the pin).  None: any certificate is taken."""
        self.fingerprint: str | None = None
        """The fingerprint of the server's certificate on the last TLS connection."""
        self.port = port
        self.name = name
        self.station = station
        self.radio = radio
        self.want_log = want_log
        self.timeout = timeout
        self.connect_timeout = connect_timeout
        self.backoff = backoff or Backoff()
        self.keepalive = keepalive
        self._sent_at = 0.0
        """When the last bytes went to the server (the loop's clock)."""

        self.link = LinkState.CONNECTING
        self.snapshot: Snapshot | None = None
        """The server's state as last told, or None before the first ``state``."""
        self.layouts: dict[RadioKey, LayoutView] = {}
        """The last layout received for each radio."""
        self.server: Mapping[str, Any] = {}
        """The ``hello`` result: ``server``, ``version``, ``protocol``."""
        self.connects = 0
        """How many times a connection was made and greeted (1 after the first)."""

        self._listeners: list[Listener] = []
        self._codec = ClientCodec()
        self._writer: asyncio.StreamWriter | None = None
        self._pending: dict[int, tuple[str, asyncio.Future[Mapping[str, Any]]]] = {}
        self._closing = False
        self._wake = asyncio.Event()
        self._connected = asyncio.Event()
        self._task: asyncio.Task[None] | None = None

    @property
    def address(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}"

    # -- listeners ------------------------------------------------------------------------------
    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Calls ``listener`` with every event from now on; returns the way to stop."""
        self._listeners.append(listener)

        def unsubscribe() -> None:
            with contextlib.suppress(ValueError):
                self._listeners.remove(listener)

        return unsubscribe

    def _emit(self, event: ClientEvent) -> None:
        for listener in list(self._listeners):
            try:
                listener(event)
            except Exception:
                log.exception("A client listener failed on %s", type(event).__name__)

    # -- running --------------------------------------------------------------------------------
    def start(self) -> asyncio.Task[None]:
        """Runs the connection in a task of the current loop (once)."""
        if self._task is None:
            self._task = asyncio.ensure_future(self.run())
        return self._task

    async def run(self) -> None:
        """Connects, and reconnects after each loss, until :meth:`close`."""
        try:
            await keep_trying(self._attempt, self.backoff, pause=self._pause,
                              stopped=lambda: self._closing)
        finally:
            self._set_link(LinkState.CLOSED, "closed")

    async def _pause(self, delay: float) -> None:
        """Waits ``delay`` before the next attempt (cut short by :meth:`close`)."""
        self._set_link(LinkState.RECONNECTING,
                       f"{self._last_problem} \u2014 trying again in {delay:g} s"
                       f"{self._last_cause}")
        self._wake.clear()
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._wake.wait(), delay)

    async def wait_connected(self, timeout: float | None = None) -> None:
        """Returns once the server has answered ``hello`` (raises TimeoutError)."""
        await asyncio.wait_for(self._connected.wait(), timeout)

    def close(self) -> None:
        """Stops for good: drops the connection and fails waiting requests."""
        self._closing = True
        self._wake.set()
        if self._writer is not None:
            self._writer.close()
        if self._task is not None and not self._task.done():
            self._task.cancel()

    async def aclose(self) -> None:
        """:meth:`close`, then waits until the connection task has ended."""
        self.close()
        if self._task is not None:
            with contextlib.suppress(asyncio.CancelledError):
                await self._task

    _last_problem = "not connected"
    _last_cause = ""
    """Why the last attempt failed, in words, after the countdown (a narrow window cuts
    the end of the line, never the countdown)."""

    async def _attempt(self) -> bool:
        """One connection, from connect to loss; True when ``hello`` was answered."""
        try:
            reader, writer = await asyncio.wait_for(self._open(), self.connect_timeout)
        except TimeoutError:
            self._last_problem = f"Cannot reach the server at {self.address}"
            self._last_cause = f" (no answer within {self.connect_timeout:g} s)"
            return False
        except OSError as exc:
            self._last_problem = f"Cannot reach the server at {self.address}"
            self._last_cause = _why_not(exc)
            return False
        self._last_cause = ""
        refusal = self._judge_certificate(writer)
        if refusal is not None:
            self._last_problem = refusal
            log.warning("Not connecting to %s: %s", self.address, refusal)
            writer.close()
            return False
        self._codec = ClientCodec()
        self._writer = writer
        reading = asyncio.ensure_future(self._read(reader))
        greeted = False
        keeping: asyncio.Future[None] | None = None
        try:
            greeted = await self._greet()
            if greeted:
                keeping = asyncio.ensure_future(self._keep_alive(writer))
                await reading
        finally:
            self._writer = None
            if keeping is not None:
                keeping.cancel()
            reading.cancel()
            for task in (keeping, reading):  # both end before the connection is closed
                if task is not None:
                    with contextlib.suppress(asyncio.CancelledError, Exception):
                        await task
            writer.close()
            with contextlib.suppress(Exception):
                await writer.wait_closed()
            self._connected.clear()
            self._fail_pending(ConnectionLost(f"the connection to {self.address} was lost"))
        return greeted

    async def _open(self) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
        local = (self.local_host, 0) if self.local_host is not None else None
        if not self.tls:
            return await asyncio.open_connection(self.host, self.port, local_addr=local)
        from moas_gui.tls import client_context

        return await asyncio.open_connection(self.host, self.port, ssl=client_context(),
                                             server_hostname=self.host, local_addr=local)

    def use_token(self, token: str | None) -> None:
        """Says ``token`` (None: none) in the next ``hello``, which comes at once: a
        waiting attempt stops waiting, and a greeted connection is dropped so that the
        server judges the new token (a forgotten one no longer acts for its operator)."""
        self.token = token or None
        self._wake.set()
        if self._writer is not None and self._connected.is_set():
            self._writer.close()

    def _judge_certificate(self, writer: asyncio.StreamWriter) -> str | None:
        """Why the server's TLS certificate is not to be trusted, or None."""
        if not self.tls:
            return None
        from moas_gui.tls import TLSError, check_pin, peer_fingerprint

        ssl_object = writer.get_extra_info("ssl_object")
        try:
            seen = peer_fingerprint(ssl_object)
        except (TLSError, AttributeError, ValueError) as exc:
            return f"{self.address} showed no usable certificate: {exc}"
        self.fingerprint = seen
        if self.pin is not None:
            if not check_pin(seen, self.pin):
                return (f"the server's certificate fingerprint is {seen}, not the pinned "
                        f"{self.pin}: someone may be in between, or the server has a new "
                        "certificate (moas-server --fingerprint on it tells)")
            return None
        if self.trust is not None and not self.trust(seen):
            return f"the certificate of {self.address} (fingerprint {seen}) was not trusted"
        return None

    async def _keep_alive(self, writer: asyncio.StreamWriter) -> None:
        """Sends a blank line whenever nothing was sent for ``keepalive`` seconds."""
        loop = asyncio.get_running_loop()
        with contextlib.suppress(OSError):
            while not writer.is_closing():
                await asyncio.sleep(max(self._sent_at + self.keepalive - loop.time(), 0.05))
                if loop.time() - self._sent_at >= self.keepalive and not writer.is_closing():
                    writer.write(b"\n")
                    self._sent_at = loop.time()

    async def _greet(self) -> bool:
        args: dict[str, Any] = {"client": self.name}
        if self.station is not None:
            args["station"] = self.station
        if self.radio is not None:
            args["radio"] = self.radio
        if self.want_log:
            args["log"] = True
        sent = self.token  # the one this hello says (another may be given meanwhile)
        if sent:
            args["token"] = sent
        try:
            self.server = await self.request("hello", args)
        except ServerError as exc:
            if exc.code != "forbidden":  # hello is refused only for its token
                self._last_problem = f"{self.address} did not answer hello: {exc}"
                return False
            refused = bool(sent)
            self._last_problem = TOKEN_REFUSED if refused else TOKEN_ASKED
            log.info("%s refused this client's hello: %s", self.address, exc.message)
            self._emit(TokenWanted(refused, exc.message))
            return False
        except ClientError as exc:
            self._last_problem = f"{self.address} did not answer hello: {exc}"
            return False
        self.connects += 1
        version = self.server.get("version", "?")
        self._set_link(LinkState.CONNECTED,
                       f"{self.address} ({self.server.get('server', 'server')} {version})")
        self._connected.set()
        return True

    async def _read(self, reader: asyncio.StreamReader) -> None:
        try:
            while True:
                data = await reader.read(65536)
                if not data:
                    self._last_problem = f"{self.address} closed the connection"
                    return
                for item in self._codec.feed(data):
                    self._handle(item)
        except OSError as exc:
            self._last_problem = f"the connection to {self.address} failed: {_reason(exc)}"
        finally:
            self._fail_pending(ConnectionLost(f"the connection to {self.address} was lost"))

    def _set_link(self, state: LinkState, detail: str) -> None:
        if state == self.link and state != LinkState.RECONNECTING:
            return
        # a server that stays away is retried every few seconds: only the first
        # attempt goes to the info log, the rest to the debug log
        level = logging.DEBUG if state == self.link else logging.INFO
        self.link = state
        log.log(level, "Client link to %s: %s (%s)", self.address, state.value, detail)
        self._emit(LinkChanged(state, detail))

    # -- incoming -------------------------------------------------------------------------------
    def _handle(self, item: Reply | Event | Garbled) -> None:
        if isinstance(item, Garbled):
            self._problem(f"{self.address} sent {item.reason}")
        elif isinstance(item, Reply):
            self._handle_reply(item)
        else:
            try:
                self._handle_event(item)
            except ProtocolError as exc:
                self._problem(f"{self.address} sent a '{item.name}' event the client cannot "
                              f"use ({exc}); ignored")

    def _handle_reply(self, reply: Reply) -> None:
        waiting = self._pending.pop(reply.id, None) if isinstance(reply.id, int) else None
        if waiting is None:
            if reply.ok:
                self._problem(f"{self.address} sent a reply to request {reply.id!r}, "
                              "which nobody is waiting for")
            else:
                self._problem(f"{self.address} refused a line: {reply.message} ({reply.code})")
            return
        cmd, future = waiting
        if future.done():
            return
        if reply.ok:
            future.set_result(reply.result)
        else:
            future.set_exception(ServerError(cmd, reply.code, reply.message))

    def _handle_event(self, event: Event) -> None:
        body = event.body
        match event.name:
            case "state":
                self.snapshot = parse_snapshot(body, "state event")
                self._emit(StateReceived(self.snapshot))
            case "radio":
                radio = parse_radio(body, "radio event")
                if self.snapshot is not None:
                    self.snapshot = self.snapshot.with_radio(radio)
                self._emit(RadioChanged(radio))
            case "rotator":
                rotator = parse_rotator(body, "rotator event")
                if self.snapshot is not None:
                    self.snapshot = self.snapshot.with_rotator(rotator)
                self._emit(RotatorChanged(rotator))
            case "switch":
                switch = parse_switch(body, "switch event")
                if self.snapshot is not None:
                    self.snapshot = self.snapshot.with_switch(switch)
                self._emit(SwitchChanged(switch))
            case "layout":
                layout = parse_layout(body, "layout event")
                self.layouts[layout.key] = layout
                self._emit(LayoutChanged(layout))
            case "log":
                level, message = body.get("level"), body.get("message")
                if not isinstance(level, str) or not isinstance(message, str):
                    raise ProtocolError("'level' and 'message' must be strings")
                self._emit(LogReceived(level, message))
            case _:
                log.debug("Ignoring unknown event %r from %s", event.name, self.address)

    def _problem(self, message: str) -> None:
        log.warning("%s", message)
        self._emit(ProblemSeen(message))

    def _fail_pending(self, error: ClientError) -> None:
        pending, self._pending = self._pending, {}
        for _, future in pending.values():
            if not future.done():
                future.set_exception(error)

    # -- requests -------------------------------------------------------------------------------
    async def request(self, cmd: str, args: Mapping[str, Any] | None = None) -> Mapping[str, Any]:
        """Sends ``cmd`` and returns the ``result`` of its reply (see module notes for errors)."""
        writer = self._writer
        if writer is None or writer.is_closing():
            raise NotConnected(f"{cmd}: not connected to {self.address}")
        try:
            request_id, data = self._codec.encode(cmd, args)
        except (TypeError, ValueError) as exc:
            raise ClientError(f"{cmd}: the request cannot be written as JSON ({exc})") from None
        future: asyncio.Future[Mapping[str, Any]] = asyncio.get_running_loop().create_future()
        self._pending[request_id] = (cmd, future)
        try:
            writer.write(data)
            self._sent_at = asyncio.get_running_loop().time()
            await writer.drain()
            return await asyncio.wait_for(asyncio.shield(future), self.timeout)
        except TimeoutError:
            raise RequestTimeout(
                f"{cmd}: no reply from {self.address} within {self.timeout:g} s") from None
        except OSError as exc:
            raise ConnectionLost(f"{cmd}: the connection to {self.address} failed: "
                                 f"{_reason(exc)}") from None
        finally:
            self._pending.pop(request_id, None)
            if not future.done():
                future.cancel()

    async def state(self) -> Snapshot:
        snapshot = parse_snapshot(await self.request("state"), "state reply")
        self.snapshot = snapshot
        return snapshot

    async def frequency(self, station: int, radio: int, khz: float,
                        tx_khz: float | None = None) -> None:
        args: dict[str, Any] = {"station": station, "radio": radio, "khz": khz}
        if tx_khz is not None:
            args["tx_khz"] = tx_khz
        await self.request("frequency", args)

    async def active(self, station: int, radio: int) -> None:
        """The station's transmit focus is on ``radio`` (an SO2R logger's active radio)."""
        await self.request("active", {"station": station, "radio": radio})

    async def focus(self, station: int, radio: int) -> None:
        """The station's receive focus (the operator's keyboard) is on ``radio``."""
        await self.request("focus", {"station": station, "radio": radio})

    async def select(self, station: int, radio: int, antenna: int, target: Target = "both",
                     exclusive: bool = False) -> Selection:
        args: dict[str, Any] = {"station": station, "radio": radio, "antenna": antenna,
                                "target": target}
        if exclusive:
            args["exclusive"] = True
        return _selection("select", await self.request("select", args))

    async def release(self, station: int, radio: int) -> None:
        """Releases the hold on the radio's antennas (docs/client-protocol.md)."""
        await self.request("release", {"station": station, "radio": radio})

    async def function(self, station: int, radio: int, function: int) -> None:
        await self.request("function", {"station": station, "radio": radio,
                                        "function": function})

    async def relative(self, station: int, radio: int, *, step: int | None = None,
                       index: int | None = None) -> Selection:
        if (step is None) == (index is None):
            raise ValueError("relative needs exactly one of step and index")
        args: dict[str, Any] = {"station": station, "radio": radio}
        if step is not None:
            args["step"] = step
        else:
            args["index"] = index
        return _selection("relative", await self.request("relative", args))

    async def layout(self, station: int, radio: int, rows: int, columns: int) -> LayoutView:
        """The closest layout; the server then sends its changes as ``layout`` events."""
        result = await self.request("layout", {"station": station, "radio": radio,
                                               "rows": rows, "columns": columns})
        try:
            layout = parse_layout(result, "layout reply")
        except ProtocolError as exc:
            raise ClientError(f"layout: {exc}") from None
        self.layouts[layout.key] = layout
        return layout

    async def rotate(self, rotator: int, heading: float) -> None:
        await self.request("rotate", {"rotator": rotator, "heading": heading})

    async def stop(self, rotator: int) -> None:
        await self.request("stop", {"rotator": rotator})


def _selection(cmd: str, result: Mapping[str, Any]) -> Selection:
    tx, rx = result.get("tx"), result.get("rx")
    for name, value in (("tx", tx), ("rx", rx)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
            raise ClientError(f"{cmd}: the reply's '{name}' is {value!r}, not an antenna number")
    return Selection(tx, rx)


_UNREACHABLE = {
    errno.ECONNREFUSED: "nothing answers on that port: is the server running?",
    errno.EHOSTUNREACH: "no route to that computer",
    errno.ENETUNREACH: "no route to that network",
    errno.ETIMEDOUT: "no answer",
}


def _why_not(exc: OSError) -> str:
    """A connection failure in words an operator reads (no exception text), or nothing."""
    if isinstance(exc, socket.gaierror):
        return " (that name is not known)"
    said = _UNREACHABLE.get(exc.errno or 0)
    return f" ({said})" if said else ""


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__
