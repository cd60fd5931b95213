"""The Antenna Genius front: a MOAS station served as one or more 4O3A Antenna Geniuses.

Every program that drives an Antenna Genius (AetherSDR, Log4YM, the Node-RED nodes,
POTACAT...) can read and drive the station's main radios through it, with the MOAS
engine's rules deciding (docs/antenna-genius.md).  One :class:`AgServer` serves the
station: its first device on ``port`` (``--ag-port`` / ``AGPort``), each further pair
of radios one more device on the next port.

What a client asks becomes one :class:`PortRequest` to the :class:`AgBackend` (the
real server's is :class:`moas_gui.engine_backend.AgEngineBackend`, which makes the
engine's operations of it and hands them to the server's one door): ``rxant``/``txant``
are the operator's press; ``band=`` is a frequency (the band's middle); ``auto=0``
holds the operator's choice, ``auto=1`` releases it.  The backend tries all of one
``port set`` first, so a refused command changes nothing.  The app tells the front
what changed (:meth:`AgServer.radios_changed`, :meth:`AgServer.reload`); the front
pushes ``S0|port ...`` to subscribers when a port's line changes and
``S0|antenna reload`` when a configuration opens.

Access goes through :class:`~.access.AgAccess` (one call at accept, one question for
the token, one for a code, checked off the loop: the reader of that connection waits
for the answer, nobody else does); the front has its own deadlines (:class:`AgTiming`).
An operator removed from the operators file has its sessions here ended
(:meth:`AgServer.end_operator`), as on every front.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from moas_gui.config import Config
from moas_gui.config.model import RadioRef
from moas_gui.edge.admission import Ticket, checking
from moas_gui.edge.gate import gate_factory, ticket_of
from moas_gui.edge.listener import Listener
from moas_gui.errors import RequestRefused
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.net.identity import Identity, serving

from . import codec
from .access import AgAccess, SimpleAccess
from .codec import AgCommand, AgMalformed, CommandReader, PortStatus
from .discovery import AgAnnouncement, Announcer
from .mapping import (
    BANDS,
    AgAntenna,
    Device,
    ag_antennas,
    ag_words,
    band_of,
    devices,
    serial_for,
)

log = logging.getLogger(__name__)

UNSUPPORTED_VERBS = frozenset({"stack", "group", "output", "flex", "conf", "antenna set",
                               "band set", "port reset", "sub group", "sub output",
                               "sub stack", "sub flex", "fw", "reboot"})
"""Commands of the real device this front does not do: answered with an error code."""

MAX_PENDING = 1 << 20
"""Bytes that may wait to be sent to one client (answers and pushes), as on the client
port: a client that stops reading is cut once more than this waits."""


@dataclass(frozen=True, slots=True)
class AgTiming:
    """The front's deadlines, in seconds."""

    first_command: float = 30.0
    """From the connection to its first line."""
    keepalive: float = 5.0
    """Silence allowed once ``keepalive enable`` was sent (a ``ping`` a second is expected)."""
    idle: float = 600.0
    """Silence allowed without keepalive."""
    discovery: float = 1.0
    """Between two discovery datagrams."""


class AgRadio(Protocol):
    """What the front reads of a radio (the engine's radio view is one)."""

    @property
    def khz(self) -> float | None: ...

    @property
    def tx(self) -> int | None: ...

    @property
    def rx(self) -> int | None: ...

    @property
    def transmitting(self) -> bool: ...

    @property
    def inhibited(self) -> bool: ...

    @property
    def held_by(self) -> str | None: ...


@dataclass(frozen=True, slots=True)
class PortRequest:
    """One ``port set`` for a radio, in the configuration's terms, done in this order:
    release the hold, tune to ``khz``, press ``tx`` then ``rx`` (antenna IDs; the same
    ID for both is one press for both), hold for ``hold_by``."""

    station: int
    radio: int
    release: bool = False
    khz: float | None = None
    tx: int | None = None
    rx: int | None = None
    hold_by: str | None = None


class AgBackend(Protocol):
    """What the front needs from the server."""

    @property
    def running(self) -> bool:
        """A configuration runs."""
        ...

    def radio(self, station: int, radio: int) -> AgRadio | None:
        """The radio's state now; None when no configuration runs or it has no such radio."""
        ...

    def port_set(self, request: PortRequest) -> None:
        """Do all of ``request`` or nothing: raises :class:`RequestRefused` (its ``code``
        the client protocol's, ``message`` the reason) when anything of it is refused."""
        ...


@dataclass(eq=False)
class _Session:
    device: _Device
    writer: asyncio.StreamWriter
    ticket: Ticket
    """Its place in the admission, its peer on it (``host``, ``address``)."""
    authed: bool
    started: float
    last: float | None = None
    keepalive: bool = False
    ports: bool = False
    relay: bool = False
    operator: str | None = None
    identity: Identity | None = None
    """Who its commands act as (the roles' rules, :mod:`moas_gui.net.identity`)."""
    closing: bool = field(default=False)
    cut: Callable[[_Session, int], None] | None = None
    """Told when more than :attr:`max_pending` bytes wait for this client (it is then
    aborted): the server's one log line a minute about it."""
    max_pending: int = MAX_PENDING

    @property
    def host(self) -> str:
        return self.ticket.host

    @property
    def peer(self) -> str:
        return self.ticket.address

    def deadline(self, timing: AgTiming) -> float:
        if self.last is None:
            return self.started + timing.first_command
        return self.last + (timing.keepalive if self.keepalive else timing.idle)

    def send(self, data: bytes) -> None:
        """Queues ``data`` without waiting; a client with more than :attr:`max_pending`
        bytes waiting (it stopped reading) is aborted, its queue dropped."""
        transport = self.writer.transport
        if transport.is_closing():
            return
        transport.write(data)
        pending = transport.get_write_buffer_size()
        if pending > self.max_pending:
            self.closing = True
            transport.abort()
            if self.cut is not None:
                self.cut(self, pending)


class _Device:
    """One AG device: a listener and the two radios on its ports."""

    def __init__(self, owner: AgServer, device: Device, port: int) -> None:
        self.owner, self.device, self.port = owner, device, port
        self.server: Listener | None = None
        self.sessions: set[_Session] = set()
        self.pushed: dict[int, str] = {}

    @property
    def name(self) -> str:
        suffix = f"_{self.device.index + 1}" if self.device.index else ""
        return codec.name_text(f"{self.owner.name}{suffix}")

    @property
    def serial(self) -> str:
        return serial_for(self.owner.name, self.port)

    def info(self) -> str:
        return (f"v={codec.FIRMWARE} date=2026-01-01 btl=1.0 hw=2.0 serial={self.serial} "
                f"name={self.name} ports={len(self.device.radios)} "
                f"antennas={len(self.owner.antennas)} mode=master "
                f"uptime={int(time.monotonic() - self.owner.started)}")


class AgServer:
    """Every AG device of one station (see the module docstring)."""

    def __init__(self, backend: AgBackend, host: str, port: int, *,
                 radios: Sequence[RadioRef] | None = None, access: AgAccess | None = None,
                 name: str = "MOAS", timing: AgTiming | None = None,
                 discovery: tuple[str, int] | None = None,
                 max_pending: int = MAX_PENDING) -> None:
        self.backend = backend
        self.max_pending = max_pending
        self.host, self.port = host, port
        self.chosen = tuple(radios) if radios is not None else None
        self.access: AgAccess = access or SimpleAccess()
        self.name = name
        self.timing = timing or AgTiming()
        self.discovery_target = discovery
        self.trouble = LogLimiter()
        """One line a minute per kind of trouble an outside party can cause (a line that
        is no command, a refused ``port set``, a client that stops reading...), with the
        count of those left out."""
        self._refused = LogLimiter()
        """One line a minute about addresses refused for their wrong codes."""
        self.started = time.monotonic()
        self.antennas: tuple[AgAntenna, ...] = ()
        self.devices: list[_Device] = []
        self._tasks: set[asyncio.Task[None]] = set()
        self._announcer: Announcer | None = None
        self._deferred: set[tuple[int, int]] | None = None
        """While one ``port set`` runs its operations: the radios they changed, pushed
        once at its end (one line per port, not one per operation)."""

    # -- life ------------------------------------------------------------------------------
    def _layout(self, config: Config | None) -> tuple[Device, ...]:
        if config is None:
            return (Device(0, (None, None)),)
        self.antennas = ag_antennas(config)
        try:
            return devices(config, self.chosen)
        except ValueError as exc:
            log.error("Antenna Genius: %s; serving the first two main radios instead", exc)
            return devices(config)

    async def start(self, config: Config | None) -> list[int]:
        """Listen (a port per device); returns the ports.  Raises OSError when the first
        cannot be bound; a further one that cannot is logged and left out."""
        for device in self._layout(config):
            await self._open(device)
        self.access.watch_removals(self.end_operator)
        self._announce()
        return [d.port for d in self.devices]

    async def _open(self, device: Device) -> None:
        port = self.port + device.index if self.port or not self.devices else 0
        served = _Device(self, device, port)
        try:
            gate = gate_factory(self.access.admission,
                                lambda r, w: self._serve(served, r, w),
                                front="Antenna Genius connection",
                                who="an Antenna Genius connection")
            served.server = await Listener.open(gate, self.host or None, port,
                                                what="Antenna Genius connections",
                                                trouble=self.access.admission.trouble)
        except OSError as exc:
            if not self.devices:
                raise
            log.error("Antenna Genius device %d (%s) cannot listen on TCP port %d: %s",
                      device.index + 1, _radios_text(device), port, exc.strerror or exc)
            return
        served.port = served.server.port
        if not self.devices:
            self.port = served.port
        self.devices.append(served)
        log.info("Antenna Genius device %d (%s) on TCP port %d (%s)", device.index + 1,
                 _radios_text(device), served.port, self.host or "every interface")

    async def reload(self, config: Config) -> None:
        """A configuration opened: new antennas and radios; every client is told
        ``S0|antenna reload`` and subscribers get each port's line."""
        layout = self._layout(config)
        for served in self.devices[len(layout):]:
            await self._close_device(served)
        del self.devices[len(layout):]
        for served, device in zip(self.devices, layout, strict=False):
            served.device = device
            served.pushed.clear()
        for device in layout[len(self.devices):]:
            await self._open(device)
        for served in self.devices:
            for session in served.sessions:
                if session.authed:
                    session.send(codec.status("antenna reload"))
        self.radios_changed(None)
        self._announce()

    def _announce(self) -> None:
        if self._announcer is not None:
            self._announcer.close()
        self._announcer = Announcer(self.host, self.discovery_target, self._announcements,
                                    self.timing.discovery)
        self._announcer.start()

    def _announcements(self) -> list[AgAnnouncement]:
        return [AgAnnouncement(d.port, codec.FIRMWARE, d.serial, d.name, len(d.device.radios),
                             len(self.antennas), int(time.monotonic() - self.started))
                for d in self.devices]

    def end_operator(self, name: str) -> int:
        """Ends every session of operator ``name`` (removed); how many."""
        ended = 0
        for served in self.devices:
            for session in list(served.sessions):
                if session.operator is not None and session.operator.lower() == name.lower():
                    session.closing = True
                    session.writer.transport.abort()
                    ended += 1
        return ended

    async def close(self) -> None:
        self.access.watch_removals(None)
        if self._announcer is not None:
            self._announcer.close()
            self._announcer = None
        for served in self.devices:
            await self._close_device(served)
        self.devices.clear()
        tasks = list(self._tasks)
        if tasks:
            _, late = await asyncio.wait(tasks, timeout=1.0)
            for task in late:
                task.cancel()
            if late:
                await asyncio.wait(late)

    async def _close_device(self, served: _Device) -> None:
        if served.server is not None:
            listener, served.server = served.server, None
            await listener.close()
        for session in list(served.sessions):
            session.writer.close()

    # -- what changed ----------------------------------------------------------------------
    def radios_changed(self, refs: set[tuple[int, int]] | None) -> None:
        """Radios ``(station, radio)`` changed (None: any may have): subscribers get the
        lines of the ports whose line is not what they were last sent."""
        if self._deferred is not None:
            if refs is not None:
                self._deferred |= refs
                return
            self._deferred = None
        for served in self.devices:
            for port, ref in enumerate(served.device.radios, start=1):
                if ref is None or (refs is not None and (ref.station, ref.radio) not in refs):
                    continue
                text = self.port_status(served.device, port).text()
                if served.pushed.get(port) == text:
                    continue
                served.pushed[port] = text
                line = codec.status(text)
                for session in served.sessions:
                    if session.ports and session.authed:
                        session.send(line)

    def port_status(self, device: Device, port: int) -> PortStatus:
        """What ``port get`` says of ``port``: the engine's view of its radio."""
        ref = device.radio(port)
        view = None if ref is None else self.backend.radio(ref.station, ref.radio)
        if ref is None or view is None:
            return PortStatus(port)
        numbers = {a.id: a.number for a in self.antennas}
        return PortStatus(
            port, auto=view.held_by is None,
            source="AUTO" if view.held_by is None else "MANUAL",
            band=band_of(view.khz), rxant=numbers.get(view.rx, 0) if view.rx is not None else 0,
            txant=numbers.get(view.tx, 0) if view.tx is not None else 0,
            tx=view.transmitting, inhibit=view.inhibited,
            freq_mhz=None if view.khz is None else view.khz / 1000,
            nickname=f"S{ref.station}R{ref.radio}")

    # -- connections -----------------------------------------------------------------------
    async def _serve(self, served: _Device, reader: asyncio.StreamReader,
                     writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        assert task is not None
        ticket = ticket_of(writer)
        host = ticket.host
        loop = asyncio.get_running_loop()
        wait = self.access.waiting(host)
        if wait > 0:
            held = self._refused.allow("locked")
            if held is not None:
                log.warning("Antenna Genius: refused %s: too many wrong auth codes lately "
                            "(%.0f s to wait)%s", ticket.address, wait, held_text(held))
            writer.close()
            return
        refusal = self.access.allowed(host)
        if refusal is not None:
            self._trouble(logging.WARNING, "not allowed", "Antenna Genius: refused %s: %s",
                          ticket.address, refusal)
            writer.close()
            return
        self._tasks.add(task)
        needs = self.access.needs_token(host)
        session = _Session(served, writer, ticket, not needs, loop.time(),
                           cut=self._cut, max_pending=self.max_pending)
        session.identity = self.access.identity(host, session.peer, None)
        served.sessions.add(session)
        try:
            writer.write(codec.greeting(auth=needs))
            await self._read(session, reader)
        except (ConnectionError, OSError, asyncio.CancelledError):
            pass
        finally:
            served.sessions.discard(session)
            self._tasks.discard(task)
            writer.close()
            with contextlib.suppress(OSError, ConnectionError):
                await writer.wait_closed()

    async def _read(self, session: _Session, reader: asyncio.StreamReader) -> None:
        loop = asyncio.get_running_loop()
        lines = CommandReader()
        while not session.closing:
            left = session.deadline(self.timing) - loop.time()
            try:
                data = await asyncio.wait_for(reader.read(4096), max(left, 0.0))
            except TimeoutError:
                self._trouble(logging.INFO, ("silent", session.last is None),
                              "Antenna Genius: closed %s: %s", session.peer,
                              "no command came" if session.last is None else "it fell silent")
                return
            if not data:
                return
            session.last = loop.time()
            # a first command greets it: it is no crowd any more
            session.ticket.greeted()
            session.ticket.touch()
            for item in lines.feed(data):
                if session.closing:
                    break
                if isinstance(item, AgCommand) and _is_auth(item):  # checked off the loop
                    session.send(await self._auth(session, item))
                    continue
                if session.identity is None:
                    session.send(self.answer(session, item))
                    continue
                with serving(session.identity):  # an operator acts within its role
                    session.send(self.answer(session, item))
                if session.closing:
                    break
            await session.writer.drain()

    def _trouble(self, level: int, kind: object, message: str, *args: object) -> None:
        """A log line of a kind an outside party can cause: one a minute per kind, the
        next one saying how many were left out meanwhile."""
        held = self.trouble.allow(kind)
        if held is not None:
            log.log(level, message + "%s", *args, held_text(held, "more like it"))

    def _cut(self, session: _Session, pending: int) -> None:
        self._trouble(logging.WARNING, "stopped reading",
                      "Antenna Genius: disconnected %s: it stopped reading (%s bytes waiting "
                      "to be sent, over the %s-byte limit)", session.peer, f"{pending:,}",
                      f"{session.max_pending:,}")

    # -- commands --------------------------------------------------------------------------
    def answer(self, session: _Session, item: AgCommand | AgMalformed) -> bytes:
        """The bytes that answer one line."""
        if isinstance(item, AgMalformed):
            self._trouble(logging.INFO, "malformed", "Antenna Genius: %s sent %s",
                          session.peer, item.reason)
            return codec.reply(item.seq, codec.BAD_COMMAND, item.reason)
        verb = item.verb
        if _is_auth(item):  # the reader checks it (off the loop) before it gets here
            return codec.reply(item.seq, codec.NO_AUTH)
        if not session.authed:
            return codec.reply(item.seq, codec.NO_AUTH)
        handler = _HANDLERS.get(verb) or _HANDLERS.get(item.words[0] if item.words else "")
        if handler is not None:
            return handler(self, session, item)
        if verb in UNSUPPORTED_VERBS or (item.words and item.words[0] in UNSUPPORTED_VERBS):
            return codec.reply(item.seq, codec.UNSUPPORTED,
                               f"{verb} is not supported by this MOAS station")
        return codec.reply(item.seq, codec.BAD_COMMAND, f"unknown command {item.text[:40]}")

    async def _auth(self, session: _Session, item: AgCommand) -> bytes:
        """Every ``auth`` is checked (an open session's too), through the server's one
        secret check: budgeted per address and per operator (docs/security.md); wrong
        codes are logged there, one line a minute."""
        if session.authed and not self.access.needs_token(session.host):
            return codec.reply(item.seq)
        with checking(session.ticket):  # its place in the admission kept while it waits
            verdict = await self.access.check_code(item.args.get("code", ""), session.host)
        operator = verdict.name
        if operator is None or session.closing:
            if self.access.waiting(session.host) > 0:  # its address must wait: no more tries
                session.closing = True
            return codec.reply(item.seq, codec.NO_AUTH, verdict.refusal or "")
        session.authed, session.operator = True, operator
        session.identity = self.access.identity(session.host, session.peer, operator)
        log.info("Antenna Genius: %s authenticated as %s", session.peer, operator)
        self._operators_pool(session)
        return codec.reply(item.seq)

    def _operators_pool(self, session: _Session) -> None:
        """An operator's connection moves to the operators' own capacity, as on the client
        port: no crowd of other addresses can take its place from then on."""
        if session.identity is not None and session.identity.is_operator:
            session.ticket.operator()  # False when that capacity is full: the admission says so

    def _info(self, session: _Session, item: AgCommand) -> bytes:
        if item.words[1:2] != ("get",):
            return codec.reply(item.seq, codec.BAD_COMMAND, "info takes get")
        return codec.reply(item.seq, codec.OK, f"info {session.device.info()}")

    def _antenna_list(self, session: _Session, item: AgCommand) -> bytes:
        return codec.list_reply(item.seq, [a.text() for a in self.antennas])

    def _band_list(self, session: _Session, item: AgCommand) -> bytes:
        return codec.list_reply(item.seq, [b.text() for b in BANDS])

    def _port_number(self, session: _Session, item: AgCommand) -> int | bytes:
        text = item.words[2] if len(item.words) > 2 else ""
        if not text.isdigit() or not 1 <= int(text) <= len(session.device.device.radios):
            return codec.reply(item.seq, codec.BAD_ARGUMENT,
                               f"no port {text or '(none given)'}: ports are 1 and 2")
        return int(text)

    def _port_get(self, session: _Session, item: AgCommand) -> bytes:
        port = self._port_number(session, item)
        if isinstance(port, bytes):
            return port
        status = self.port_status(session.device.device, port)
        return codec.list_reply(item.seq, [status.text()])

    def _port_set(self, session: _Session, item: AgCommand) -> bytes:
        port = self._port_number(session, item)
        if isinstance(port, bytes):
            return port
        ref = session.device.device.radio(port)
        running = self.backend.running
        if ref is None or not running:
            return codec.reply(item.seq, codec.NOT_RUNNING,
                               f"port {port} has no radio" if running
                               else "no configuration is open")
        request = self._request(session, item, ref)
        if isinstance(request, str):
            return codec.reply(item.seq, codec.BAD_ARGUMENT, request)
        try:
            self._deferred = set()
            try:
                self.backend.port_set(request)
            finally:
                changed, self._deferred = self._deferred, None
                self.radios_changed(changed)
        except RequestRefused as exc:
            code = codec.NOT_RUNNING if exc.code == "not_running" else codec.REFUSED
            said = ag_words(exc.message, self.antennas, session.device.device)
            self._trouble(logging.INFO, "refused", "Antenna Genius: %s port set %d refused: %s",
                          session.peer, port, said)
            return codec.reply(item.seq, code, said)
        return codec.reply(item.seq)

    def _request(self, session: _Session, item: AgCommand,
                 ref: RadioRef) -> PortRequest | str:
        """The :class:`PortRequest` a ``port set``'s arguments ask for, or what is wrong."""
        args = item.args
        unknown = sorted(set(args) - {"auto", "source", "band", "rxant", "txant"})
        if unknown:
            return f"unknown argument {unknown[0]}"
        values: dict[str, int] = {}
        limits = {"auto": 1, "band": len(BANDS) - 1, "rxant": len(self.antennas),
                  "txant": len(self.antennas)}
        for key, top in limits.items():
            if key in args:
                text = args[key]
                if not text.isdigit() or not 0 <= int(text) <= top:
                    return f"{key}={text} is out of range (0-{top})"
                values[key] = int(text)
        # 0 is the AG's "none": no band, no antenna chosen for that side (a MOAS radio
        # keeps the antennas its engine gives it: docs/antenna-genius.md)
        band = values.get("band") or None
        if band is not None and not BANDS[band].high_khz:
            return f"band={band} is not a band of this station"
        ids = {a.number: a.id for a in self.antennas}
        who = session.operator or "an Antenna Genius client"
        return PortRequest(
            ref.station, ref.radio, release=values.get("auto") == 1,
            khz=None if band is None else BANDS[band].middle_khz,
            tx=ids.get(values.get("txant", 0)), rx=ids.get(values.get("rxant", 0)),
            hold_by=f"{who} at {session.host}" if values.get("auto") == 0 else None)

    def _sub(self, session: _Session, item: AgCommand) -> bytes:
        what = item.words[1] if len(item.words) > 1 else ""
        if what == "port":
            session.ports = True
        elif what == "relay":
            session.relay = True
        elif what != "antenna":
            return codec.reply(item.seq, codec.UNSUPPORTED, f"sub {what} is not supported")
        return codec.reply(item.seq)

    def _unsub(self, session: _Session, item: AgCommand) -> bytes:
        what = item.words[1] if len(item.words) > 1 else ""
        if what in ("", "port", "all"):
            session.ports = False
        if what in ("", "relay", "all"):
            session.relay = False
        return codec.reply(item.seq)

    def _keepalive(self, session: _Session, item: AgCommand) -> bytes:
        setting = item.words[1] if len(item.words) > 1 else ""
        if setting not in ("enable", "disable"):
            return codec.reply(item.seq, codec.BAD_ARGUMENT, "keepalive takes enable or disable")
        session.keepalive = setting == "enable"
        return codec.reply(item.seq)

    def _ping(self, session: _Session, item: AgCommand) -> bytes:
        return codec.reply(item.seq)


_Handler = Callable[[AgServer, _Session, AgCommand], bytes]
_HANDLERS: dict[str, _Handler] = {
    "info": AgServer._info,
    "info get": AgServer._info,
    "antenna list": AgServer._antenna_list,
    "band list": AgServer._band_list,
    "port get": AgServer._port_get,
    "port set": AgServer._port_set,
    "sub": AgServer._sub,
    "unsub": AgServer._unsub,
    "keepalive": AgServer._keepalive,
    "ping": AgServer._ping,
}


def _is_auth(item: AgCommand) -> bool:
    return item.verb == "auth" or item.words[:1] == ("auth",)


def _radios_text(device: Device) -> str:
    return ", ".join(f"port {p}: {r}" if r is not None else f"port {p}: no radio"
                     for p, r in enumerate(device.radios, start=1))


__all__ = ["UNSUPPORTED_VERBS", "AgBackend", "AgRadio", "AgServer", "AgTiming", "PortRequest"]
