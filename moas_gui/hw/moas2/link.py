"""The switch link: the driver of one MOAS II's :class:`~.session.SwitchSession`.

Every decision about the box (confirming the unit, what it holds after a
restart, a replug or a stall, what to send and the safety rule it passes, which
:mod:`.plan` holds) is the session's, a pure state machine in :mod:`.session`.
The link does the I/O around it, with a few collaborators: a
:class:`~.transport.Transport` (the port, or the built-in emulator for the port
name ``"emulator"``: :func:`.transport.transport_for`), a
:class:`~moas_gui.clock.Clock` (tests replace it by a fake one), a
:class:`~.listener.SwitchListener` (what the server hears) and, with
``--record-serial``, a :class:`~.recording.SerialRecorder` (every call on the session
goes through :class:`~.calls.SessionCalls`, which stamps and records it).

* ``connect()`` starts a task that opens the port for this link alone, tells the
  session, and waits for the session's next deadline on the clock, calling ``tick``
  then.  Bytes from the port go to ``feed`` as they arrive.
* When the session ends (silence past ``answer_timeout``, the port going away,
  a box that does not answer, another unit), the link closes the port and tries
  again after 0.5 s, 1 s, 2 s ... up to 8 s (:class:`.timing.LinkTiming`).  The
  next session checks what the box holds before anything is written.
* The session's actions are carried out in order: bytes written, lines logged
  (the session decides what to say and how loud; the link writes it), the status,
  T/R and error calls on the listener, and an :class:`~.actions.Adopt`: the
  listener's ``adopt`` (the engine takes what the box holds for every station the
  survey adopts, in one call) returns the engine's wanted state then, and the
  session's ``reconcile`` gets it.
* ``apply(state)`` hands the engine's wanted state over and writes what the
  session says: the difference at once, except an automatic relay change that
  comes while the relay dwell runs (:mod:`.dwell`).  ``stop()`` and ``start()`` (an
  inactive wanted state, and active again) and ``reset()`` are the operator's;
  ``save_data`` writes every status reply and the tables to a file.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from ...aio import cancel_and_wait
from ...clock import LOOP_CLOCK, Clock, timeout
from ...engine.switchstate import SwitchState
from ...files import write_text_atomic
from ...retry import Backoff, keep_trying
from ...serial.settings import PortSettings
from .actions import (
    Action,
    Adopt,
    Answered,
    BoxError,
    End,
    LinkStatus,
    Log,
    StatusChanged,
    Transmit,
    Write,
    describe,
)
from .calls import SessionCalls
from .diagnostics import switch_data
from .errors import PortError
from .listener import SwitchListener, Told
from .messages import (
    BoxStatus,
    Command,
    Ping,
    PolarityStatus,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    StateOp,
    StatusKind,
    StatusRequest,
    UnitId,
    UnitIdReply,
)
from .recording import SerialRecorder
from .resync import Slots
from .session import SwitchSession
from .sync import DEFAULT_EVENTS
from .timing import REAL_TIMING, LinkTiming
from .transport import EMULATOR_PORT, SWITCH_PORT, EmulatorTransport, Transport, transport_for

if TYPE_CHECKING:  # the built-in emulator is loaded when a switch's port names it
    from .emulator.box import EmulatedBox

log = logging.getLogger(__name__)

_R = TypeVar("_R")


@dataclass(frozen=True, slots=True)
class LinkOptions:
    """How a link drives its box, from the configuration and the saved state."""

    timing: LinkTiming = REAL_TIMING
    indicate_tr: bool = True
    """Ask the box for its T and R events (the configuration's ``IndicateTR``)."""
    held: SwitchState | None = None
    """What the box was last told (the saved state): checked, not loaded blindly."""
    seen: Sequence[Slots] | None = None
    """Each station's antennas the box last reported in use (the saved state)."""
    port_settings: PortSettings = SWITCH_PORT

    @property
    def events(self) -> tuple[StateOp, ...]:
        return DEFAULT_EVENTS if self.indicate_tr else (StateOp.ANTENNA_EVENTS_ON,)


class SwitchLink:
    """Owns one MOAS II switch: the I/O around its :class:`SwitchSession`."""

    def __init__(
        self,
        switch_id: int,
        port: str,
        echo: int | None = None,
        *,
        listener: SwitchListener | None = None,
        options: LinkOptions = LinkOptions(),
        transport: Transport | None = None,
        clock: Clock = LOOP_CLOCK,
        recorder: SerialRecorder | None = None,
    ) -> None:
        self.switch_id = switch_id
        self.port = port
        self.echo = echo
        self.timing = options.timing
        self.clock = clock
        """What pings, answer timeouts and retries wait on (and the built-in emulator's
        timers run on)."""
        self._transport = transport or transport_for(port, echo, clock, options.port_settings)
        self.emulator: EmulatedBox | None = (
            self._transport.box if isinstance(self._transport, EmulatorTransport) else None)
        self.session = SwitchSession(switch_id, echo, events=options.events,
                                     timing=options.timing, held=options.held,
                                     seen=options.seen, where=self.where)
        if recorder is not None:
            recorder.session(switch_id, port=port, echo=echo, events=options.events,
                             timing=options.timing, held=options.held, seen=options.seen)
        self._calls = SessionCalls(self.session, clock.now, recorder)
        self._told = Told(listener or SwitchListener(), self.where)
        self._open = False
        self._ended: asyncio.Event | None = None
        self._wake: asyncio.Event | None = None
        self._waits_until = math.inf
        """The deadline the supervisor sleeps towards (inf: none, or it is not asleep)."""
        self._reached = False
        self._task: asyncio.Task[None] | None = None
        self._session_no = 0
        """Counts sessions: what a port delivers for an ended one is dropped."""
        self._answers: dict[int, asyncio.Future[Any]] = {}
        self.errors: deque[str] = deque(maxlen=50)

    # ------------------------------------------------------------------ public

    @property
    def status(self) -> LinkStatus:
        return self.session.status

    @property
    def ready(self) -> bool:
        """The box is reconciled and every ``apply`` goes straight out."""
        return self._open and self.session.ready

    @property
    def sent(self) -> SwitchState | None:
        """What the box holds as far as the link knows (None while it is not ready)."""
        return self.session.sent if self._open else None

    @property
    def holds(self) -> SwitchState | None:
        """What the box was last told, even during an outage (what a saved state keeps)."""
        return self.session.writer.holds

    @property
    def seen(self) -> tuple[Slots, ...] | None:
        """Each station's antennas the box last reported in use."""
        return self.session.reader.seen

    @property
    def bytes_written(self) -> int:
        return self.session.bytes_written

    @property
    def where(self) -> str:
        return f"switch {self.switch_id} on {self._transport.description}"

    def connect(self) -> None:
        """Start talking to the switch (needs a running event loop)."""
        if self._task is None or self._task.done():
            retry = Backoff(first=self.timing.retry_first, factor=2.0, most=self.timing.retry_max)
            self._task = asyncio.get_running_loop().create_task(
                keep_trying(self._attempt, retry, pause=self.clock.sleep),
                name=f"switch {self.switch_id}")

    async def close(self) -> None:
        """Stop talking to the switch; the box keeps its relays."""
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)
        self._close_port()

    def apply(self, state: SwitchState, *, automatic: bool = False) -> int:
        """Make the box hold ``state``; returns the bytes written now.  ``automatic``: a
        frequency decided it, and its relay changes keep the relay dwell (:mod:`.dwell`)."""
        before = self.session.bytes_written
        self._do(self._calls.apply(state, automatic))
        return self.session.bytes_written - before

    def stop(self) -> None:
        """Stop Switches: all relays off (reset, and load without activating): the wanted
        state, inactive, for a driver without an engine (the server's engine says it)."""
        self._do(self._calls.stop())

    def start(self) -> None:
        """Start Switches: activate a stopped switch again (the wanted state, active)."""
        self._do(self._calls.start())

    def reset(self) -> None:
        """Reset Switches: reset the box and load it again from the latest state."""
        self._do(self._calls.reset())

    async def ask_relays(self) -> frozenset[int] | None:
        """The relays the box says are closed (``|;``), or None without an answer."""
        reply = await self._ask(RelayStatusRequest(), RelayStatus) if self.ready else None
        return reply.relays if isinstance(reply, RelayStatus) else None

    async def save_data(self, path: str | Path) -> Path:
        """Write every status reply and the tables to ``path`` (text)."""
        path = Path(path)
        asked: list[tuple[Command, type[Any]]] = [
            (UnitId(), UnitIdReply),
            (StatusRequest(StatusKind.BOX), BoxStatus),
            (StatusRequest(StatusKind.POLARITY), PolarityStatus),
            (RelayStatusRequest(), RelayStatus),
            (Ping(), Pong),
        ]
        answers = []
        for command, reply_type in asked:
            reply = await self._ask(command, reply_type) if self.ready else None
            answers.append((command, reply))
        header = [
            f"MOAS II switch {self.switch_id}",
            f"port: {self.port} ({self._transport.description})",
            f"status: {self.status.value}",
        ]
        state = self.session.sent if self.session.sent is not None else self.session.desired
        write_text_atomic(path, switch_data(header, answers, state, self.errors))
        return path

    # ------------------------------------------------------------------ supervision

    async def _attempt(self) -> bool:
        """One session and its end; True if the box became ready (the retries start over).

        Whatever goes wrong in it that nobody foresaw is logged with its traceback and
        ends the session: the link keeps trying, so no single failure leaves a switch
        undriven for the rest of the contest."""
        try:
            return await self._session()
        except asyncio.CancelledError:
            raise
        except Exception:
            log.exception("%s: the session failed; will retry", self.where)
            with contextlib.suppress(Exception):
                self._close_port()
                self._do(self._calls.closed())
            return False

    async def _session(self) -> bool:
        """Open the port and run the session until it ends; True if the box became ready."""
        self._session_no += 1
        session = self._session_no
        self._ended = asyncio.Event()
        self._wake = asyncio.Event()
        self._waits_until = math.inf
        self._reached = False
        try:
            self._transport.open(
                lambda data: self._on_data(session, data),
                lambda reason: self._on_port_lost(session, reason),
            )
        except PortError as exc:
            self._do(self.session.voice.problem(
                logging.WARNING, f"{self.where}: cannot open the port: {exc}; will retry"))
            self._do(self._calls.closed())
            return False
        self._open = True
        try:
            self._do(self._calls.opened())
            while not self._ended.is_set():
                self._wake.clear()
                deadline = self.session.next_deadline()
                self._waits_until = math.inf if deadline is None else deadline
                wait = None if deadline is None else deadline - self.clock.now()
                if wait is not None and wait <= 0:  # due: however busy the port is
                    self._do(self._calls.tick())
                    await asyncio.sleep(0)
                    continue
                if wait is None:
                    await self._wake.wait()
                    continue
                with contextlib.suppress(TimeoutError):
                    async with timeout(self.clock, wait):
                        await self._wake.wait()
                if not self._wake.is_set() and not self._ended.is_set():
                    self._do(self._calls.tick())
        finally:
            self._close_port()
        self._do(self._calls.closed())
        return self._reached

    def _close_port(self) -> None:
        self._session_no += 1  # whatever the port still delivers belongs to no session
        if self._open:
            self._open = False
            self._do(self._calls.lost("closed"))
        self._transport.close()

    def _on_port_lost(self, session: int, reason: str) -> None:
        if session != self._session_no:
            return
        self._do(self.session.voice.problem(logging.WARNING,
                                            f"{self.where}: the port went away: {reason}"))
        self._do(self._calls.lost(reason))

    def _on_data(self, session: int, data: bytes) -> None:
        if session != self._session_no or not self._open:
            log.debug("%s: dropped %r, which came after its session ended", self.where, data)
            return
        self._do(self._calls.feed(data))

    # ------------------------------------------------------------------ actions

    def _do(self, actions: list[Action]) -> None:
        """Carry out the session's actions, in order."""
        listener = self._told.listener
        for action in actions:
            if isinstance(action, Write):
                self._write(action.data)
            elif isinstance(action, Log):
                log.log(action.level, "%s", action.text)
            elif isinstance(action, StatusChanged):
                log.info("%s is %s", self.where, action.status.value)
                self._told.call(listener.status, action.status)
            elif isinstance(action, Transmit):
                self._told.call(listener.transmitting, action.station, action.transmitting)
            elif isinstance(action, BoxError):
                log.error("%s", action.text)
                self.errors.append(action.text)
                self._told.call(listener.box_error, action.text)
            elif isinstance(action, Adopt):  # the engine takes them, then the box follows
                wanted = self._told.call(listener.adopt, action.stations, action.transmitting)
                desired = wanted if isinstance(wanted, SwitchState) else self.session.desired
                self._do(self._calls.reconcile(desired))
            elif isinstance(action, Answered):
                future = self._answers.pop(action.ticket, None)
                if future is not None and not future.done():
                    future.set_result(action.reply)
            elif isinstance(action, End):
                self._reached = self._reached or action.reached
                if self._ended is not None:
                    self._ended.set()
        self._told.seen(self.session.reader.seen)
        if self._wake is not None and self._wake_needed():
            self._wake.set()

    def _wake_needed(self) -> bool:
        """Whether the supervisor must wake to sleep towards another deadline: the session
        ended, or its next deadline is earlier than the one it sleeps towards.  (A later
        one needs no wake: the supervisor ticks at the earlier time, finds nothing due and
        sleeps on; so a band change and the box's answer to it cost no wake at all.)"""
        if self._ended is not None and self._ended.is_set():
            return True
        deadline = self.session.next_deadline()
        return deadline is not None and deadline < self._waits_until

    def _write(self, data: bytes) -> None:
        if not self._open:
            return
        self._calls.wrote(data)
        try:
            self._transport.write(data)
        except PortError as exc:
            self._on_port_lost(self._session_no, str(exc))

    async def _ask(self, command: Command, reply_type: type[_R]) -> _R | None:
        """Send ``command`` and wait for a message of ``reply_type``."""
        if not self._open:
            return None
        future: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
        ticket, actions = self._calls.ask(command, reply_type)
        self._answers[ticket] = future
        self._do(actions)
        try:
            result = await future
        finally:
            self._answers.pop(ticket, None)
        return result if isinstance(result, reply_type) else None


__all__ = [
    "EMULATOR_PORT",
    "LinkOptions",
    "LinkStatus",
    "LinkTiming",
    "SwitchLink",
    "SwitchListener",
    "describe",
]
