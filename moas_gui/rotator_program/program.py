"""The MOAS Rotator program: TCP 13020 in front of any number of rotator drivers.

Decisions (see also docs/rotators-serial.md):

- One server connection at a time.  A new connection from the address of the
  one in control replaces it (the MOAS Server reconnects after a restart, and a
  half-dead old connection must not keep the new one out); one from another
  address is refused, told why, unless the program was started with
  ``--take-over``.  A connection replaced is told so in one line before it is
  closed.  Every connection passes the program's admission first (the
  project's one policy, :mod:`moas_gui.edge.admission`): a few at once, a
  fair share, and one that does not become the controlling one is closed.
- ``CONFIGURE`` opens serial devices only (``COM3``, ``/dev/ttyUSB0``, a
  pseudo-terminal, a link to one), and whatever else the user allowed
  (:mod:`.ports`: ``--allow``; the server that starts the program allows the
  ports of its ``.moas`` file); a ``socket://`` URL, ``loop://``, a file such
  as ``/etc/passwd`` is refused with one log line, and the rotator stays as it
  was.
- The program keeps no configuration of its own, but rotators stay
  configured and polled when the server goes away: a turn in progress runs
  to its end, nothing is stopped by a network hiccup, and ports stay open.
  A rotator's headings go only to a connection that has configured that
  rotator; a CONFIGURE that repeats the current set-up keeps the running
  driver and reports the last heading at once.
- A CONFIGURE that cannot be carried out (unknown model) leaves the rotator
  as it was; one that gives a port to another rotator number takes the port
  away from the rotator that had it.
- Every command that cannot be obeyed gives one log line saying which
  rotator and why; nothing else stops.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import socket

from moas_gui import __version__
from moas_gui.clock import LOOP_CLOCK, Clock
from moas_gui.edge.admission import Admission, Deadlines
from moas_gui.edge.gate import gate_factory, ticket_of
from moas_gui.edge.listener import Listener
from moas_gui.hw.rotators.controllers.base import ControllerError
from moas_gui.hw.rotators.controllers.models import find_model
from moas_gui.hw.rotators.moas_rotator_codec import (
    PORT,
    BadRotatorLine,
    CommandDecoder,
    Configure,
    Rotate,
    RotatorCommand,
    Stop,
    VersionRequest,
    encode_heading,
    encode_port_state,
    encode_version_reply,
)
from moas_gui.log_limit import held_text

from .driver import RETRY, ControllerDriver
from .ports import port_refusal
from .serial_link import Opener, PortError, open_serial, split_port

log = logging.getLogger(__name__)

WRITE_BUFFER_LIMIT = 1 << 20
"""Bytes queued for a server that does not read before it is disconnected."""

CONNECTIONS = 8
"""Connections at once (one controls; the others are told why not and closed)."""
PER_ADDRESS = 4
DEADLINES = Deadlines(hello=10.0)
"""A connection that does not become the controlling one is closed within 10 s."""


class RotatorProgram:
    """The program; see the module docstring."""

    def __init__(self, *, opener: Opener = open_serial, retry: float = RETRY,
                 clock: Clock = LOOP_CLOCK, version: str = __version__,
                 allow: tuple[str, ...] = (), take_over: bool = False) -> None:
        self.rotators: dict[int, ControllerDriver] = {}
        self._opener = opener
        self._retry = retry
        self._clock = clock
        self._version = version
        self._server: Listener | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._peer = ""
        self._announced: set[int] = set()
        self._port_reasons: dict[int, str | None] = {}
        """Why each rotator's controller cannot be reached (None: it can), as last told."""
        self._handlers: dict[asyncio.Task[None], asyncio.StreamWriter] = {}
        self.allow = tuple(allow)
        """Ports beyond serial devices that CONFIGURE may open (patterns, ``--allow``)."""
        self.take_over = take_over
        """Whether a connection from another address may replace the one in control."""
        self.admission = Admission(CONNECTIONS, PER_ADDRESS, before_hello=PER_ADDRESS,
                                   what="server connections")
        self._controller_host = ""

    # -- running ---------------------------------------------------------------------------

    async def start(self, host: str = "127.0.0.1", port: int = PORT) -> tuple[str, int]:
        """Listens on ``host``:``port`` (this computer only unless told otherwise);
        returns the address really bound."""
        # SO_REUSEADDR on POSIX only (a restart need not wait for TIME_WAIT); on Windows
        # that option would let two programs share the port (moas_gui.edge.listener).
        gate = gate_factory(self.admission, self._connection, front="server connection",
                            deadlines=DEADLINES)
        self._server = await Listener.open(gate, host, port, what="server connections",
                                           trouble=self.admission.trouble)
        address = self._server.sockets[0].getsockname()  # the listener's own sockets
        log.debug("listening on %s:%d", address[0], address[1])  # moas-rotator prints it
        return address[0], address[1]

    async def close(self) -> None:
        if self._server is not None:
            await self._server.close()
        self.admission.close()
        self._writer = None
        handlers = dict(self._handlers)
        for writer in handlers.values():
            writer.close()  # each handler then sees the end of its stream and returns
        if handlers:
            _, late = await asyncio.wait(handlers, timeout=2.0)
            for task in late:
                task.cancel()
        for driver in list(self.rotators.values()):
            await driver.close()
        self.rotators.clear()
        self._server = None

    @property
    def connected(self) -> bool:
        """True while a server is connected."""
        return self._writer is not None

    # -- the server connection -------------------------------------------------------------

    async def _connection(self, reader: asyncio.StreamReader,
                          writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        if task is not None:
            self._handlers[task] = writer
        ticket = ticket_of(writer)
        peer, host = ticket.address, ticket.host  # read once, when it was accepted
        old = self._writer
        if old is not None and not old.is_closing() and host != self._controller_host \
                and not self.take_over:
            self._refuse(writer, peer)
            if task is not None:
                self._handlers.pop(task, None)
            return
        ticket.greeted()  # in control: no deadline before it says anything
        _keep_alive(writer)
        self._writer, self._controller_host = writer, host
        if old is not None:
            log.info("server connection from %s replaces the one from %s", peer, self._peer)
            with contextlib.suppress(Exception):
                old.write(f"TAKEN OVER by the MOAS Server at {peer}\r".encode())
            old.close()
        else:
            log.info("server connected from %s", peer)
        self._peer = peer
        self._announced = set()
        commands = CommandDecoder()
        try:
            while True:
                try:
                    data = await reader.read(4096)
                except (ConnectionError, OSError):
                    break
                if not data or self._writer is not writer:
                    break
                for command in commands.feed(data):
                    await self._obey(command)
        finally:
            if self._writer is writer:
                self._writer = None
                log.info("server at %s disconnected; %d rotator(s) stay configured and polled",
                         peer, len(self.rotators))
            writer.close()
            if task is not None:
                self._handlers.pop(task, None)

    def _refuse(self, writer: asyncio.StreamWriter, peer: str) -> None:
        """A second server from another address: told why, and closed."""
        held = self.admission.trouble.allow("second server")
        if held is not None:
            log.warning("refused a server connection from %s: the MOAS Server at %s is in "
                        "control (moas-rotator --take-over lets a newcomer replace it)%s",
                        peer, self._peer, held_text(held, "more refused"))
        writer.write(f"BUSY: the MOAS Server at {self._peer} controls this program\r".encode())
        writer.close()

    def _send(self, data: bytes) -> None:
        writer = self._writer
        if writer is None or writer.is_closing():
            return
        if writer.transport.get_write_buffer_size() > WRITE_BUFFER_LIMIT:
            log.warning("server at %s reads nothing; disconnecting it", self._peer)
            self._writer = None
            writer.close()
            return
        writer.write(data)

    def _report(self, rotator: int, degrees: int) -> None:
        if rotator in self._announced:
            self._send(encode_heading(rotator, degrees))

    def _port_state(self, rotator: int, reason: str | None) -> None:
        """The controller's port went away (why) or is open again: the server shows the
        rotator offline or online (``OFFLINE``/``ONLINE``, lines of this project's)."""
        self._port_reasons[rotator] = reason
        if rotator in self._announced:
            self._send(encode_port_state(rotator, reason))

    # -- commands --------------------------------------------------------------------------

    async def _obey(self, command: RotatorCommand | BadRotatorLine) -> None:
        if isinstance(command, BadRotatorLine):
            where = f"rotator {command.rotator}: " if command.rotator is not None else ""
            log.warning("%sbad command from the server %r: %s", where, command.line,
                        command.reason)
        elif isinstance(command, VersionRequest):
            self._send(encode_version_reply(self._version))
        elif isinstance(command, Configure):
            await self._configure(command)
        elif isinstance(command, Rotate):
            self._rotate(command)
        elif isinstance(command, Stop):
            self._stop(command)

    async def _configure(self, command: Configure) -> None:
        rotator = command.rotator
        try:
            model = find_model(command.model)
        except ControllerError as error:
            current = self.rotators.get(rotator)
            kept = f"; it stays {current.label}" if current is not None else ""
            log.warning("rotator %d: CONFIGURE refused: %s%s", rotator, error, kept)
            return
        refusal = port_refusal(command.port, self.allow)
        if refusal is not None:
            current = self.rotators.get(rotator)
            kept = f"; it stays {current.label}" if current is not None else ""
            log.warning("rotator %d: CONFIGURE refused: %s%s", rotator, refusal, kept)
            return
        self._announced.add(rotator)
        current = self.rotators.get(rotator)
        if current is not None and current.same_setup(model, command.port, command.poll_ms):
            log.info("%s: configured again, unchanged", current.label)
            if current.heading is not None:
                self._send(encode_heading(rotator, current.heading))
            if self._port_reasons.get(rotator) is not None:
                self._send(encode_port_state(rotator, self._port_reasons[rotator]))
            return
        if current is not None:
            log.info("%s: replaced by a new configuration", current.label)
            del self.rotators[rotator]
            await current.close()
        device = split_port(command.port)[0]
        for other in list(self.rotators.values()):
            if split_port(other.port)[0] == device:
                log.warning("%s: gives its port up to rotator %d", other.label, rotator)
                del self.rotators[other.rotator]
                await other.close()
        driver = ControllerDriver(rotator, model, command.port, command.poll_ms, self._report,
                               port_state=self._port_state,
                               opener=self._opener, retry=self._retry, clock=self._clock)
        self.rotators[rotator] = driver
        log.info("%s: configured, %s", driver.label, _polling(driver))
        driver.start()

    def _rotate(self, command: Rotate) -> None:
        driver = self.rotators.get(command.rotator)
        if driver is None:
            log.warning("rotator %d: ROTATE %g refused: this rotator is not configured",
                        command.rotator, command.degrees)
            return
        try:
            driver.rotate(command.degrees)
        except (ControllerError, PortError) as error:
            log.warning("%s: ROTATE %g refused: %s", driver.label, command.degrees, error)

    def _stop(self, command: Stop) -> None:
        driver = self.rotators.get(command.rotator)
        if driver is None:
            log.warning("rotator %d: STOP refused: this rotator is not configured",
                        command.rotator)
            return
        try:
            driver.stop()
        except PortError as error:
            log.warning("%s: STOP not sent: %s", driver.label, error)


def _keep_alive(writer: asyncio.StreamWriter) -> None:
    """TCP keepalive on the controlling connection: a server gone without a word (its
    computer switched off) is found out by the system in time."""
    sock = writer.get_extra_info("socket")
    if sock is not None:
        with contextlib.suppress(OSError):
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)


def _polling(driver: ControllerDriver) -> str:
    info = driver.codec.info
    if not info.has_readback:
        return "no position readback (headings are estimated after each turn)"
    if info.unsolicited:
        return (f"reports by itself (poll time ignored; checked every "
                f"{driver.poll_interval:g} s)")
    return f"polled every {driver.poll_interval * 1000:g} ms"


__all__ = ["WRITE_BUFFER_LIMIT", "RotatorProgram"]
