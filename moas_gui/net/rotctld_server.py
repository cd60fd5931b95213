"""A rotctld-compatible listener per rotator (config key ``RotctldPort``).

Any program that can drive Hamlib's ``rotctld`` (``rotctl -m 2 -r
HOST:PORT``, loggers, satellite trackers) can read and turn that rotator.
Served: ``p``/``\\get_pos``, ``P``/``\\set_pos``, ``S``/``\\stop``,
``K``/``\\park`` (to the rotator's ``ParkHeading``), ``M``/``\\move``
(clockwise or counterclockwise, up to 179 degrees, never past the end of
travel), ``R``/``\\reset`` (stops the rotator), ``_``/``\\get_info``,
``1``/``\\dump_caps``, ``\\dump_state``, ``q``, in default and extended
(``+``) form.  Other rotctld commands answer ``RPRT -4`` (not implemented);
text that is no rotctld command gets no answer, exactly as from rotctld, and
a log line.

Errors say what happened, in Hamlib's numbers: the server cannot reach the
rotator (offline, heading not known yet): ``-6`` (I/O error); the rotator's
controller did not answer in time: ``-5``; the controller refused: ``-9``;
bad arguments: ``-1``; no ``ParkHeading``, or a move in elevation: ``-11``
(feature not available).

Listeners bind 127.0.0.1 unless told otherwise (``--rotctld-allow``: where the client
port listens): only programs on the server's computer can use them.  Whoever reaches
a listener may use it (rotctld's protocol has no token) unless it is given the peers
it takes (:func:`rotctld_peers`: with ``--require-token``, this computer alone and
whatever ``--rotctld-allow`` lists); any other is closed at once, one Warning line a
minute.  All of them share one admission (the program's policy,
:mod:`moas_gui.edge.admission`): at most :data:`ROTCTLD_TOTAL` connections at once,
:data:`ROTCTLD_PER_ADDRESS` from one address, a fair share when full; a connection
must send its first command within :data:`ROTCTLD_DEADLINES` ``hello`` seconds (it
then counts as greeted) and is closed after ``idle`` seconds without one.  Log lines
about bad input go out once a minute a kind, whoever sends it, with the count of
those left out.  A station whose logging computers should turn
rotators binds the server's address on the station network (or 0.0.0.0
behind the station's firewall); rotctld has no authentication.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Awaitable, Iterable
from typing import Protocol

from moas_gui.config.model import Rotator
from moas_gui.edge.admission import Admission, Deadlines
from moas_gui.edge.gate import Allows, gate_factory, ticket_of
from moas_gui.edge.listener import Listener
from moas_gui.hw.rotators.base import RotatorError, RotatorView, describe
from moas_gui.hw.rotators.headings import Travel, normalize
from moas_gui.log_limit import held_text

from .access import IPNetwork, is_allowed
from .identity import is_local
from .rotctld_codec import (
    CLOCKWISE,
    COUNTERCLOCKWISE,
    EINVAL,
    EIO,
    ENAVAIL,
    ENIMPL,
    ERJCTED,
    ETIMEOUT,
    AzimuthScale,
    RequestParser,
    RotctldRequest,
    answer,
    azimuth_for,
    dump_caps,
    dump_state,
    move_target,
    parse_direction,
    parse_number,
    scale_for,
)

log = logging.getLogger(__name__)

ROTCTLD_TOTAL = 64
"""rotctld connections at once, all listeners together: far more than the loggers and
trackers of a station."""
ROTCTLD_PER_ADDRESS = 16
ROTCTLD_DEADLINES = Deadlines(hello=30.0, idle=600.0)
"""A first command within 30 s; then at most 10 minutes without one."""


def rotctld_admission() -> Admission:
    """The admission every rotctld listener of a server shares."""
    return Admission(ROTCTLD_TOTAL, ROTCTLD_PER_ADDRESS, what="rotctld connections")


def rotctld_peers(require_token: bool, allow: tuple[IPNetwork, ...] | None) -> Allows | None:
    """Who the rotctld ports take: anyone who reaches them (``None``) on an open LAN
    with no ``--rotctld-allow``; else this computer and the ``allow`` networks only
    (``--require-token`` closes every port, and rotctld's protocol has no token)."""
    if not require_token and allow is None:
        return None
    networks = allow or ()
    why = ("the rotctld ports take only this computer"
           + (" and --rotctld-allow's addresses" if networks else
              " (--require-token; moas-server --rotctld-allow lists others)"))

    def allows(host: str) -> str | None:
        return None if is_local(host) or is_allowed(host, networks) else why

    return allows


SERVED = frozenset({"get_pos", "set_pos", "stop", "park", "move", "reset", "get_info",
                    "dump_caps", "dump_state", "quit"})


class RotatorService(Protocol):
    """What a listener needs from the rotator manager."""

    def view(self, rotator_id: int) -> RotatorView: ...

    async def rotate(self, rotator_id: object, heading: object) -> None: ...

    async def stop(self, rotator_id: object) -> None: ...

    def travel_position(self, rotator_id: int) -> float | None: ...


class RotctldServer:
    def __init__(self, service: RotatorService, rotator: Rotator, host: str, port: int,
                 admission: Admission | None = None,
                 deadlines: Deadlines = ROTCTLD_DEADLINES, allows: Allows | None = None) -> None:
        self.service, self.rotator = service, rotator
        self.allows = allows
        """Who may connect (:func:`rotctld_peers`); ``None``: whoever reaches the port."""
        self.host, self.port = host, port
        self.admission = admission if admission is not None else rotctld_admission()
        self.deadlines = deadlines
        try:
            travel = Travel(rotator.ccw_limit, rotator.rotation, rotator.has_stop)
        except ValueError:
            travel = Travel()
        self.travel = travel
        self.scale: AzimuthScale = scale_for(travel)
        self._server: Listener | None = None
        self._sessions: set[asyncio.Task[None]] = set()
        self._writers: set[asyncio.StreamWriter] = set()

    @property
    def where(self) -> str:
        return f"rotctld listener for {describe(self.rotator)} on {self.host}:{self.port}"

    async def start(self) -> int:
        """Listen; returns the port.  Raises ``OSError`` when it cannot bind."""
        gate = gate_factory(self.admission, self._serve, front="rotctld connection",
                            deadlines=self.deadlines, allows=self.allows)
        self._server = await Listener.open(gate, self.host, self.port,
                                           what="rotctld connections",
                                           trouble=self.admission.trouble)
        self.port = self._server.port
        log.info("%s: listening", self.where)
        return self.port

    async def close(self) -> None:
        if self._server is not None:
            await self._server.close()
            self._server = None
        self.admission.close()
        for writer in list(self._writers):
            writer.close()
        sessions = list(self._sessions)
        if sessions:
            _, late = await asyncio.wait(sessions, timeout=1.0)
            for task in late:
                task.cancel()
            if late:
                await asyncio.wait(late)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        assert task is not None
        self._sessions.add(task)
        self._writers.add(writer)
        ticket = ticket_of(writer)
        peer = ticket.address  # read once, when it was accepted
        parser = RequestParser()
        try:
            while data := await reader.read(4096):
                for request in parser.feed(data):
                    if request.name == "quit":
                        return
                    if request.known:
                        ticket.greeted()  # a rotctld command: it has said what it is
                        ticket.touch()
                    reply = await self._handle(request, peer)
                    if reply:
                        writer.write(reply)
                if parser.overflowed:
                    self._trouble("overflow", logging.WARNING,
                                  "%s: %s sent over 4096 bytes without a command; dropped",
                                  self.where, peer)
                    parser.overflowed = False
                await writer.drain()
        except (ConnectionError, OSError):
            pass
        except asyncio.CancelledError:
            pass  # closing: end this session quietly (the task must not end cancelled)
        finally:
            self._sessions.discard(task)
            self._writers.discard(writer)
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()

    async def _handle(self, request: RotctldRequest, peer: str) -> bytes:
        if not request.known:
            self._trouble("unknown", logging.WARNING,
                          "%s: %s sent %r, which is not a rotctld command; no answer (as rotctld)",
                          self.where, peer, request.name[:40])
            return b""
        if request.name not in SERVED:
            self._trouble(("not served", request.name), logging.INFO,
                          "%s: %s asked for %s, which this listener does not do", self.where,
                          peer, request.name)
            return answer(request, code=ENIMPL)
        if request.name == "dump_state":
            return dump_state(request, self.scale)
        if request.name == "dump_caps":
            return dump_caps(request, self._info, self.scale,
                             can_park=self.rotator.park_heading is not None)
        if request.name == "get_info":
            return answer(request, (("Info", self._info),))
        if request.name == "get_pos":
            view = self.service.view(self.rotator.id)
            if not view.online or view.heading is None:
                return answer(request, code=EIO)
            azimuth = azimuth_for(self.scale, view.heading)
            return answer(request, (("Azimuth", f"{azimuth:.2f}"), ("Elevation", "0.00")))
        if request.name == "set_pos":
            return await self._set_pos(request, peer)
        if request.name == "park":
            return await self._park(request)
        if request.name == "move":
            return await self._move(request, peer)
        return await self._call(request, self.service.stop(self.rotator.id))  # stop, reset

    def _trouble(self, kind: object, level: int, message: str, *args: object) -> None:
        """A line about bad or refused input: once a minute a kind, whoever sends it."""
        held = self.admission.trouble.allow(("rotctld", kind))
        if held is not None:
            log.log(level, message + "%s", *args, held_text(held))

    @property
    def _info(self) -> str:
        return f"MOAS {self.rotator.label}"[:48]

    async def _park(self, request: RotctldRequest) -> bytes:
        heading = self.rotator.park_heading
        if heading is None:
            self._trouble("no park", logging.INFO, "%s: park asked for, but %s has no "
                          "ParkHeading", self.where, describe(self.rotator))
            return answer(request, code=ENAVAIL)
        return await self._call(request, self.service.rotate(self.rotator.id, float(heading)))

    async def _move(self, request: RotctldRequest, peer: str) -> bytes:
        direction = parse_direction(request.args[0])
        if direction is None or parse_number(request.args[1]) is None:
            self._trouble("bad move", logging.WARNING, "%s: %s sent move with %r: not a "
                          "direction and a speed", self.where, peer, " ".join(request.args)[:80])
            return answer(request, code=EINVAL)
        if direction not in (CLOCKWISE, COUNTERCLOCKWISE):
            self._trouble("elevation", logging.INFO, "%s: %s asked to move in elevation; this "
                          "rotator turns in azimuth only", self.where, peer)
            return answer(request, code=ENAVAIL)
        view = self.service.view(self.rotator.id)
        if not view.online or view.heading is None:
            return answer(request, code=EIO)
        target = move_target(self.travel, view.heading,
                             self.service.travel_position(self.rotator.id),
                             clockwise=direction == CLOCKWISE)
        return await self._call(request, self.service.rotate(self.rotator.id, target))

    async def _set_pos(self, request: RotctldRequest, peer: str) -> bytes:
        azimuth = parse_number(request.args[0])
        elevation = parse_number(request.args[1])
        if azimuth is None or elevation is None:
            self._trouble("bad set_pos", logging.WARNING, "%s: %s sent set_pos with %r: not "
                          "two numbers", self.where, peer, " ".join(request.args)[:80])
            return answer(request, code=EINVAL)
        return await self._call(request, self.service.rotate(self.rotator.id, normalize(azimuth)))

    async def _call(self, request: RotctldRequest, action: Awaitable[None]) -> bytes:
        try:
            await action
        except RotatorError as exc:
            self._trouble(("refused", request.name), logging.INFO, "%s: %s refused: %s",
                          self.where, request.name, exc.message)
            return answer(request, code=self._code_for(exc))
        return answer(request)

    def _code_for(self, error: RotatorError) -> int:
        """Hamlib's number for what went wrong (see the module notes)."""
        if error.code == "bad_request":
            return EINVAL
        if isinstance(error.__cause__, TimeoutError):
            return ETIMEOUT
        if not self.service.view(self.rotator.id).online:
            return EIO
        return ERJCTED


async def start_rotctld_servers(
    service: RotatorService, rotators: Iterable[Rotator], host: str,
    allows: Allows | None = None,
) -> list[RotctldServer]:
    """A listener for every rotator with a ``RotctldPort``, taking the peers ``allows``
    takes (:func:`rotctld_peers`); a port that cannot be opened is logged and skipped."""
    servers: list[RotctldServer] = []
    shared = rotctld_admission()
    for rotator in rotators:
        if rotator.rotctld_port is None:
            continue
        server = RotctldServer(service, rotator, host, rotator.rotctld_port, shared,
                               allows=allows)
        try:
            await server.start()
        except OSError as exc:
            log.error("%s: cannot listen: %s", server.where, exc)
            continue
        servers.append(server)
    return servers


__all__ = [
    "ROTCTLD_DEADLINES",
    "ROTCTLD_PER_ADDRESS",
    "ROTCTLD_TOTAL",
    "RotatorService",
    "RotctldServer",
    "rotctld_admission",
    "rotctld_peers",
    "start_rotctld_servers",
]
