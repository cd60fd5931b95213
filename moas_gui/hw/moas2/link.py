"""The switch link: one object per MOAS II that makes the box hold what the
engine wants, and reports what the box says.

Its life, in plain words:

* ``connect()`` starts it.  It opens the port (or the built-in emulator for
  the port name ``"emulator"``) for itself alone, asks the unit id (``:;``)
  and a ping after it, and refuses a box that reported any unit but ``Echo``
  (without ``Echo``: the unit first found) before that ping was answered.
  Nothing is written that could move a relay before that (see
  :mod:`.questions` for how answers find their questions).  Then it resets
  and loads the box from the latest state (:func:`.sync.initialise`),
  checks the box answers, and asks the box status to learn who transmits.
  Given ``held`` (what a previous server told the box, from the saved
  state), the first connection asks the box's status first and, when the box
  still holds it (:func:`.sync.differs`), sends only the difference to the
  wanted state: no reset, so a restarted server changes nothing on the air.
* ``apply(state)`` writes the difference from the last state sent, at once
  (no timer in between), as the fewest bytes (:func:`.sync.difference`).
  Before the box is ready it only remembers the state.
* It pings once a second.  Three seconds without a well-formed message, or
  the port going away, make it ``unresponsive``; it then closes the port and
  tries again after 0.5 s, 1 s, 2 s ... up to 8 s (:class:`.timing.LinkTiming`;
  every wait is on the link's :class:`~moas_gui.clock.Clock`, which tests
  replace by a fake one), and on success checks, as
  after a restart, whether the box still holds what it was last told: then
  only the difference to the latest state goes out, else the box is loaded
  again.  A box that answers a ping "inactive"
  while it should be active was reset or lost power: it is loaded again.
* Each ping closes a batch of the commands written before it; a ``?`` error
  is blamed on the batch not yet answered, narrowed by the error letter,
  and logged naming the command.
* ``stop()`` resets the box and loads it without activating it (all relays
  off); ``start()`` activates it again; ``reset()`` reloads it; ``save_data``
  writes every status reply and the tables to a text file.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import re
import time
from collections import deque
from collections.abc import Callable
from dataclasses import fields, is_dataclass
from enum import Enum
from pathlib import Path
from typing import Any, TypeVar

from ...aio import cancel_and_wait
from ...clock import LOOP_CLOCK, Clock, timeout
from ...engine.switchstate import STATIONS, SwitchState
from ...files import write_text_atomic
from ...retry import Backoff, keep_trying
from .commands import encode, split
from .decoder import SwitchDecoder
from .diagnostics import Batch, blame, switch_data
from .emulator.box import EmulatedBox
from .emulator.model import EmulatorModel
from .errors import PortError
from .messages import (
    AntennaEvent,
    AntennaStatus,
    BoxStatus,
    Command,
    ErrorReply,
    Malformed,
    Ping,
    PolarityStatus,
    Pong,
    ReceiveEvent,
    RelayStatus,
    RelayStatusRequest,
    StateOp,
    StatusKind,
    StatusRequest,
    TransmitEvent,
    TRState,
    UnitId,
    UnitIdReply,
)
from .questions import Answer, Questions
from .replies import encode_reply
from .sync import DEFAULT_EVENTS, CommandPlan, difference, differs, initialise, stopped
from .timing import REAL_TIMING, LinkTiming
from .transport import EmulatorTransport, SerialTransport, Transport

log = logging.getLogger("moas_gui.hw.moas2.link")

EMULATOR_PORT = "emulator"
"""The port name that means "the built-in emulator"."""

_R = TypeVar("_R")


class LinkStatus(str, Enum):
    CONNECTING = "connecting"
    OK = "ok"
    UNRESPONSIVE = "unresponsive"
    STOPPED = "stopped"


class SwitchLink:
    """Owns one MOAS II switch."""

    def __init__(
        self,
        switch_id: int,
        port: str,
        echo: int | None = None,
        *,
        on_status: Callable[[LinkStatus], None] | None = None,
        on_tr: Callable[[int, bool], None] | None = None,
        on_error: Callable[[str], None] | None = None,
        indicate_tr: bool = True,
        timing: LinkTiming = REAL_TIMING,
        transport: Transport | None = None,
        held: SwitchState | None = None,
        clock: Clock = LOOP_CLOCK,
    ) -> None:
        self.switch_id = switch_id
        self.port = port
        self.echo = echo
        self.timing = timing
        self.clock = clock
        """What pings, answer timeouts and retries wait on (and the built-in emulator's
        timers run on)."""
        self._on_status = on_status
        self._on_tr = on_tr
        self._on_error = on_error
        self._events = DEFAULT_EVENTS if indicate_tr else (StateOp.ANTENNA_EVENTS_ON,)
        self.emulator: EmulatedBox | None = None
        if transport is None:
            if port == EMULATOR_PORT:
                self.emulator = EmulatedBox(EmulatorModel(unit_id=echo or 0), clock=clock)
                transport = EmulatorTransport(self.emulator)
            else:
                transport = SerialTransport(port)
        elif isinstance(transport, EmulatorTransport):
            self.emulator = transport.box
        self._transport = transport
        self._decoder = SwitchDecoder()
        self._desired = SwitchState()
        self._sent: SwitchState | None = None
        self._held = held
        """What the box was last told before this server started (a saved state): the
        first connection checks whether the box still holds it instead of resetting."""
        self._stopped = False
        self._status = LinkStatus.CONNECTING
        self._open = False
        self._lost: asyncio.Event | None = None
        self._task: asyncio.Task[None] | None = None
        self._questions = Questions()
        self._pings: deque[tuple[Batch, asyncio.Future[Any] | None]] = deque()
        self._session_no = 0
        """Counts sessions: what a port delivers for an ended one is dropped."""
        self._confirmed = False
        """The box of this session said it is our unit, and nothing said otherwise."""
        self._foreign: UnitIdReply | None = None
        """Another unit's id, heard in this session."""
        self._first_unit: int | None = None
        """Without Echo: the unit id of the first box this link drove."""
        self._batch = Batch(None)
        self._last_heard = 0.0
        self._last_problem = ""
        self._tr: dict[int, bool] = {}
        self.unit: UnitIdReply | None = None
        self.bytes_written = 0
        self.replies: dict[type, tuple[float, bytes]] = {}
        self.errors: deque[str] = deque(maxlen=50)

    # ------------------------------------------------------------------ public

    @property
    def status(self) -> LinkStatus:
        return self._status

    @property
    def ready(self) -> bool:
        """The box is initialised and every ``apply`` goes straight out."""
        return self._open and self._confirmed and self._sent is not None

    @property
    def sent(self) -> SwitchState | None:
        """What the box holds as far as the link knows (None while it is not ready)."""
        return self._sent if self.ready else None

    @property
    def where(self) -> str:
        return f"switch {self.switch_id} on {self._transport.description}"

    def connect(self) -> None:
        """Start talking to the switch (needs a running event loop)."""
        if self._task is None or self._task.done():
            self._lost = asyncio.Event()
            self._task = asyncio.get_running_loop().create_task(
                self._supervise(), name=f"switch {self.switch_id}"
            )

    async def close(self) -> None:
        """Stop talking to the switch; the box keeps its relays."""
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)
        self._close_port("closed")

    def apply(self, state: SwitchState) -> int:
        """Make the box hold ``state``; returns the bytes written now."""
        self._desired = state
        if not self.ready or self._sent is None:
            return 0
        target = self._effective(state)
        written = self._send(difference(self._sent, target, events=self._events))
        self._sent = target
        return written

    def stop(self) -> None:
        """Stop Switches: all relays off (reset, and load without activating)."""
        self._stopped = True
        self.apply(self._desired)
        if self.ready:
            self._set_status(LinkStatus.STOPPED)

    def start(self) -> None:
        """Start Switches: activate a stopped switch again."""
        self._stopped = False
        self.apply(self._desired)
        if self.ready:
            self._set_status(LinkStatus.OK)

    def reset(self) -> None:
        """Reset Switches: reset the box and load it again from the latest state."""
        if self.ready:
            log.info("%s: resetting and loading it again", self.where)
            self._load()

    async def ask_relays(self) -> frozenset[int] | None:
        """The relays the box says are closed (``|;``), or None without an answer."""
        reply = await self._ask(RelayStatusRequest(), RelayStatus) if self.ready else None
        return reply.relays if reply is not None else None

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
            f"status: {self._status.value}",
        ]
        state = self._sent if self._sent is not None else self._effective(self._desired)
        write_text_atomic(path, switch_data(header, answers, state, self.errors))
        return path

    # ------------------------------------------------------------------ supervision

    async def _supervise(self) -> None:
        retry = Backoff(first=self.timing.retry_first, factor=2.0, most=self.timing.retry_max)
        await keep_trying(self._attempt, retry, pause=self.clock.sleep)

    async def _attempt(self) -> bool:
        """One session and its end; True if the box became ready (the retries start over)."""
        reached = await self._session()
        self._close_port("session ended")
        self._set_status(LinkStatus.UNRESPONSIVE)
        return reached

    async def _session(self) -> bool:
        """One connection; True if the box became ready."""
        assert self._lost is not None
        self._session_no += 1
        session = self._session_no
        self._confirmed = False
        self._foreign = None
        try:
            self._lost.clear()
            self._decoder.reset()
            self._transport.open(
                lambda data: self._on_data(session, data),
                lambda reason: self._on_port_lost(session, reason),
            )
        except PortError as exc:
            self._problem(logging.WARNING, f"{self.where}: cannot open the port: {exc}; will retry")
            return False
        self._open = True
        self._pings.clear()
        self._batch = Batch(None)
        self._tr.clear()
        if not await self._confirm_unit():
            return False
        held, self._held = self._held, None
        if held is not None and await self._still_holds(held):
            # nothing on the air changes: only the difference to the wanted state goes out
            self._sent = held
            self.apply(self._desired)
        else:
            self._load()
        if await self._ask(Ping(), Pong) is None:
            self._problem(logging.WARNING, f"{self.where} stopped answering while loading")
            return False
        await self._ask(StatusRequest(StatusKind.BOX), BoxStatus)
        if not self._confirmed:  # another unit's id was heard meanwhile
            return False
        if self._last_problem:
            log.info("%s answers again", self.where)
        self._last_problem = ""
        self._set_status(LinkStatus.STOPPED if self._stopped else LinkStatus.OK)
        while True:
            with contextlib.suppress(TimeoutError):
                async with timeout(self.clock, self.timing.ping_interval):
                    await self._lost.wait()
            if self._lost.is_set():
                return True
            if self.clock.now() - self._last_heard > self.timing.answer_timeout:
                self._problem(
                    logging.WARNING,
                    f"{self.where} stopped answering (nothing for "
                    f"{self.timing.answer_timeout:.1f} s); will retry",
                )
                return True
            self._ping()

    async def _confirm_unit(self) -> bool:
        """Whether the box on the port now is ours: it answers the unit id and a ping
        after it, and says no other unit id before that ping's answer.  The box answers
        in order, so an answer that came late (to a question asked before, perhaps of
        the box the port led to then) is followed by this session's own before the
        ping's: a disagreement is seen, and the box is not driven."""
        unit = await self._ask(UnitId(), UnitIdReply)
        if unit is None or await self._ask(Ping(), Pong) is None:
            self._problem(logging.WARNING, f"{self.where} does not answer; will retry")
            return False
        self.unit = unit
        refusal = self._refusal(self._foreign or unit)
        if refusal:
            self._problem(logging.ERROR, refusal)
            return False
        self._confirmed = True
        if self.echo is None and self._first_unit is None:
            self._first_unit = unit.unit
        return True

    def _refusal(self, unit: UnitIdReply) -> str:
        """Why a box that says it is ``unit`` is not ours ("" when it is)."""
        if self.echo is not None and unit.unit != self.echo:
            return (
                f"{self.where} says it is unit {unit.unit}, but the configuration's Echo is "
                f"{self.echo}: not driving it (is it on the wrong port?)"
            )
        if self.echo is None and self._first_unit is not None and unit.unit != self._first_unit:
            return (
                f"{self.where} says it is unit {unit.unit}, but the box this port led to "
                f"before was unit {self._first_unit}: not driving it (is it on the wrong "
                f"port? give Echo in the configuration, or restart, to drive it)"
            )
        return ""

    async def _still_holds(self, held: SwitchState) -> bool:
        """Whether the box still holds ``held`` (what this link's saved state says it was
        told), judged by everything it can report: active, every station's antennas, the
        inhibit polarity, and closed relays that ``held`` can explain.  The tables and
        timings cannot be read back; they are the saved ones when the rest is."""
        if not held.active or self._stopped:
            return False  # a reset of a stopped box changes nothing on the air
        pong = await self._ask(Ping(), Pong)
        box = await self._ask(StatusRequest(StatusKind.BOX), BoxStatus)
        polarity = await self._ask(StatusRequest(StatusKind.POLARITY), PolarityStatus)
        relays = await self._ask(RelayStatusRequest(), RelayStatus)
        why = differs(held, pong, box, polarity, relays)
        if why:
            log.info("%s does not hold the saved state (%s): loading it", self.where, why)
            return False
        log.info("%s still holds the saved state: carrying on without a reset", self.where)
        return True

    def _load(self) -> None:
        target = self._effective(self._desired)
        self._send(initialise(target, events=self._events))
        self._sent = target

    def _effective(self, state: SwitchState) -> SwitchState:
        return stopped(state) if self._stopped else state

    def _forget_sent(self) -> None:
        """The port is gone: what the box was told becomes what the next connection
        checks it still holds (a cable pulled and plugged back must not reset a box,
        least of all under a transmitting station)."""
        if self._sent is not None:
            self._held = self._sent
        self._sent = None

    def _close_port(self, why: str) -> None:
        self._session_no += 1  # whatever the port still delivers belongs to no session
        self._end_session(why)
        self._transport.close()

    def _end_session(self, why: str) -> None:
        self._open = False
        self._confirmed = False
        self._forget_sent()
        self._questions.end(PortError(why))
        for _, future in self._pings:
            if future is not None and not future.done():
                future.set_exception(PortError(why))
        self._pings.clear()

    def _on_port_lost(self, session: int, reason: str) -> None:
        if session != self._session_no:
            return
        self._problem(logging.WARNING, f"{self.where}: the port went away: {reason}")
        self._end_session(reason)
        if self._lost is not None:
            self._lost.set()

    def _set_status(self, status: LinkStatus) -> None:
        if status is not self._status:
            self._status = status
            log.info("%s is %s", self.where, status.value)
            if self._on_status is not None:
                self._call(self._on_status, status)

    def _problem(self, level: int, text: str) -> None:
        """Log a problem once per outage: its first warning (and an error not said yet);
        what the retries meet after it goes to the debug log, "answers again" ends it."""
        quiet = text == self._last_problem or (
            level <= logging.WARNING and bool(self._last_problem))
        log.log(logging.DEBUG if quiet else level, "%s", text)
        self._last_problem = text

    # ------------------------------------------------------------------ writing

    def _send(self, plan: CommandPlan) -> int:
        if not self._confirmed:  # never reached: every caller waits for ``ready``
            log.error("%s: not sending to a box whose unit id is not confirmed", self.where)
            return 0
        for problem in plan.problems:
            log.error("switch %d: %s", self.switch_id, problem)
        parts = [encode(part) for command in plan.commands for part in split(command)]
        if not parts:
            return 0
        data = b"".join(parts)
        self._write(data)
        self._batch.commands += parts
        return len(data)

    def _write(self, data: bytes) -> None:
        try:
            self._transport.write(data)
        except PortError as exc:
            self._on_port_lost(self._session_no, str(exc))
            return
        self.bytes_written += len(data)

    def _ping(self, future: asyncio.Future[Any] | None = None) -> None:
        expect = self._sent.active if self.ready and self._sent is not None else None
        self._pings.append((Batch(expect, self._batch.commands), future))
        self._batch = Batch(None)
        self._write(b"';")

    async def _ask(self, command: Command, reply_type: type[_R]) -> _R | None:
        """Send ``command`` and wait for a message of ``reply_type``."""
        if not self._open:
            return None
        future: asyncio.Future[Any] = asyncio.get_running_loop().create_future()
        if isinstance(command, Ping):
            self._ping(future)
        else:
            forget_at = self.clock.now() + 2 * self.timing.answer_timeout
            self._questions.ask(reply_type, future, forget_at)
            self._write(encode(command))
        result: _R
        try:
            async with timeout(self.clock, self.timing.answer_timeout):
                result = await future
        except TimeoutError:
            if not future.done() or future.cancelled() or future.exception() is not None:
                future.cancel()  # the asker gave up: a late answer goes to nobody
                return None
            result = future.result()  # answered in the very turn the time ran out
        except PortError:
            return None
        return result

    # ------------------------------------------------------------------ reading

    def _on_data(self, session: int, data: bytes) -> None:
        if session != self._session_no or not self._open:
            log.debug("%s: dropped %r, which came after its session ended", self.where, data)
            return
        for message in self._decoder.feed(data):
            if isinstance(message, Malformed):
                log.debug("%s: skipped %r: %s", self.where, message.raw, message.reason)
                continue
            now = self.clock.now()
            self._last_heard = now
            if isinstance(message, UnitIdReply):
                self._unit_said(message)
            self._handle(message)
            if isinstance(message, Pong):
                continue  # answered in _pong
            answer = self._questions.answer(message, now)
            if answer is Answer.LATE:
                log.debug("%s: dropped a late answer (its asker gave up): %s", self.where,
                          describe(message))

    def _unit_said(self, reply: UnitIdReply) -> None:
        """Any unit id the box says counts, whichever question it answers: once another
        unit's id is heard, this session drives nothing more."""
        if not self._refusal(reply):
            return
        self._foreign = self._foreign or reply
        if self._confirmed:
            self._problem(logging.ERROR, self._refusal(reply))
            self._confirmed = False
            if self._lost is not None:
                self._lost.set()

    def _handle(self, message: object) -> None:
        if isinstance(message, BoxStatus | PolarityStatus | RelayStatus | UnitIdReply):
            self.replies[type(message)] = (time.time(), encode_reply(message))
        if isinstance(message, Pong):
            self._pong(message)
        elif isinstance(message, ErrorReply):
            self._error(message)
        elif isinstance(message, TransmitEvent | ReceiveEvent):
            self._tr_changed(message.station, isinstance(message, TransmitEvent))
        elif isinstance(message, BoxStatus):
            for number, letter in zip(STATIONS, message.tr, strict=False):
                self._tr_changed(number, letter is TRState.TRANSMIT)
        elif isinstance(message, AntennaEvent) and message.status in (
            AntennaStatus.TX_CONFLICT,
            AntennaStatus.RX_CONFLICT,
        ):
            kind = "transmit" if message.status is AntennaStatus.TX_CONFLICT else "receive"
            log.warning(
                "%s holds station %d's %s antenna (slot %d): it conflicts with another "
                "station's antenna", self.where, message.station, kind, message.antenna,
            )
        else:
            log.debug("%s: %s", self.where, describe(message))

    def _pong(self, pong: Pong) -> None:
        if not self._pings:
            log.debug("%s: dropped a pong no ping of this session asked for", self.where)
            return
        batch, future = self._pings.popleft()
        if future is not None:
            if future.done():
                log.debug("%s: dropped a late pong (its asker gave up)", self.where)
            else:
                future.set_result(pong)
        if batch.expect_active is not None and pong.active != batch.expect_active and self.ready:
            log.warning(
                "%s says it is %s, which it should not be: it was reset or lost power; "
                "loading it again", self.where, "active" if pong.active else "inactive",
            )
            for earlier, _ in self._pings:  # asked before the load: not to be judged
                earlier.expect_active = None
            self._load()

    def _error(self, reply: ErrorReply) -> None:
        commands = self._pings[0][0].commands if self._pings else self._batch.commands
        text = blame(self.where, reply, commands)
        log.error("%s", text)
        self.errors.append(text)
        if self._on_error is not None:
            self._call(self._on_error, text)

    def _tr_changed(self, station: int, transmitting: bool) -> None:
        if self._tr.get(station) is transmitting:
            return
        self._tr[station] = transmitting
        if self._on_tr is not None:
            self._call(self._on_tr, station, transmitting)

    def _call(self, callback: Callable[..., None], *args: object) -> None:
        """Call the server back; a failing callback is logged, the link carries on."""
        try:
            callback(*args)
        except Exception:  # whatever the caller's code raises, the link carries on
            log.exception("%s: the %s callback failed", self.where, callback)


def describe(message: object) -> str:
    """A message from the box in words for the debug log: ``antenna event: station 1,
    status TX fast (F), antenna 3`` rather than its Python form."""
    name = re.sub(r"(?<!^)(?=[A-Z])", " ", type(message).__name__).lower()
    if not is_dataclass(message):
        return name
    parts = []
    for item in fields(message):
        value = getattr(message, item.name)
        if isinstance(value, Enum):
            shown = f"{value.name.replace('_', ' ').lower()} ({value.value})"
        elif isinstance(value, frozenset | set | tuple | list):
            shown = ", ".join(str(v) for v in sorted(value, key=str)) or "none"
        else:
            shown = str(value)
        parts.append(f"{item.name.replace('_', ' ')} {shown}")
    return f"{name}: {', '.join(parts)}" if parts else name


__all__ = ["EMULATOR_PORT", "LinkStatus", "LinkTiming", "SwitchLink", "describe"]
