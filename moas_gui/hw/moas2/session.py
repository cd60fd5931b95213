"""The switch session as a pure state machine: bytes and time in, actions out.

:class:`SwitchSession` holds every decision the switch link makes about one
MOAS II; :class:`~.link.SwitchLink` is the thin driver around it that opens
the port, carries out what the session returns and waits for the session's next
deadline.  The session never reads a clock, never touches a port and never
awaits: the driver hands it ``now`` with every call, so a test can play any
interleaving of bytes, silences and port losses against it.

Inputs: :meth:`~SwitchSession.opened` (a port is open), :meth:`~SwitchSession.feed`
(bytes from the box), :meth:`~SwitchSession.tick` (the deadline came),
:meth:`~SwitchSession.lost` (the port went away), :meth:`~SwitchSession.apply`
(the engine's wanted state), :meth:`~SwitchSession.reconcile` (the engine's wanted
state after it adopted what a survey found), :meth:`~SwitchSession.stop`,
:meth:`~SwitchSession.start`, :meth:`~SwitchSession.reset` (the operator) and
:meth:`~SwitchSession.ask` (a question of the driver's own).  Each returns a list of
actions, for the driver to carry out in order: :class:`Write`, :class:`Log`,
:class:`StatusChanged`, :class:`Transmit`, :class:`BoxError`, :class:`Adopt`,
:class:`Reconcile`, :class:`Answered` and :class:`End`.

A session's life (the phases' table is :mod:`.phases`):

1. **Confirm**: ask the unit id and a ping; a box that answers with another unit
   (or says another unit's id before that ping's answer) is not driven.
2. **Survey**: ask what the box holds and who transmits (ping, box status,
   inhibit polarity, relays), up to :data:`SURVEY_TRIES` times.  Until every
   answer is in, nothing is written that could move a relay.
3. **Reconcile** (:func:`.resync.reconcile` judges what the box holds): stations
   whose antennas on the box win over a stale saved state come back as
   :class:`Adopt` actions and a :class:`Reconcile`, after which the driver calls
   :meth:`~SwitchSession.reconcile` with the engine's wanted state; with nothing to
   adopt the session reconciles at once.  The plan is the difference from what the
   box is believed to hold or, when its contents are unsure, the whole state as
   values (:func:`.sync.absolute`), never a reset unless Stop Switches stands.
4. **Run**: a ping every ``ping_interval``; silence past ``answer_timeout`` ends the
   session (the driver retries); a box that says it is inactive when it should be
   active lost its state and is loaded again as values.

**The safety rule** is :func:`.plan.guard`, the one gate every plan goes through,
and every plan is chosen by :func:`.plan.choose_plan` beside it (the session only
says what it knows: what the box surely holds, what it is believed to hold, whether
the operator pressed Reset).  ``guard``'s whole scope: a reset (``*0``) goes out only
when the operator asked for it (Reset Switches, or Stop Switches: an inactive wanted
state), with a warning naming the stations transmitting then, or whose state was
unknown; and the station-0 relays (``!0X``, set by the box at once) are held back
while any station transmits or may, unless the operator changed them from relays
the box surely holds.  Everything else the session sends changes a station's relays
only through the box's own hot-switch rules (wait or interrupt mode) and the tables
the engine loads; the only other bytes it writes are questions (:data:`QUESTIONS`).

The session says what to log as :class:`Log` actions, which the driver writes; it
logs only its debug lines itself (a skipped malformed reply, a late answer dropped,
each message in words), lazily, so that they cost nothing on the busy path while
debug is off.
"""

from __future__ import annotations

import logging
import re
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, is_dataclass, replace
from enum import Enum
from typing import Any

from ...engine.switchstate import NO_ANTENNA, STATIONS, SwitchState
from .commands import encode, split
from .decoder import SwitchDecoder
from .diagnostics import Batch, blame
from .dwell import RelayDwell, interim, moves_relays
from .keying import Keying
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
    UnitId,
    UnitIdReply,
)
from .phases import (
    CONFIRMED,
    WRITES_PLANS,
    Phase,
    PhaseEvent,
    Standing,
    WriteRefused,
    next_phase,
)
from .plan import UNSURE_RELAYS, Known, Verdict, choose_plan, guard
from .resync import Reconciliation, Slots, Survey, reconcile
from .sync import stopped
from .timing import REAL_TIMING, LinkTiming

log = logging.getLogger(__name__)

SURVEY_TRIES = 3
"""How many times a session asks what the box holds before it gives up (and the
driver tries a new session later): a noisy line gets as many chances, and meanwhile
nothing is written that could move a relay."""


class LinkStatus(str, Enum):
    CONNECTING = "connecting"
    OK = "ok"
    UNRESPONSIVE = "unresponsive"
    STOPPED = "stopped"


# ---------------------------------------------------------------------------- actions

@dataclass(frozen=True, slots=True)
class Write:
    """Write these bytes to the port now."""

    data: bytes


@dataclass(frozen=True, slots=True)
class StatusChanged:
    """The link's status changed."""

    status: LinkStatus


@dataclass(frozen=True, slots=True)
class Transmit:
    """A station began (True) or ended (False) transmitting."""

    station: int
    transmitting: bool


@dataclass(frozen=True, slots=True)
class BoxError:
    """The box refused a command (the text names it)."""

    text: str


@dataclass(frozen=True, slots=True)
class Log:
    """A line for the log, at ``level`` (:mod:`logging`'s): the session decides what to
    say and how loud, the driver writes it."""

    level: int
    text: str


@dataclass(frozen=True, slots=True)
class Adopt:
    """What the box holds for ``station`` wins over the saved state: the engine should
    take these slots as that port's antennas.  Always followed by :class:`Reconcile`."""

    station: int
    slots: Slots
    transmitting: bool


@dataclass(frozen=True, slots=True)
class Reconcile:
    """The box was surveyed and some stations are to be adopted (the :class:`Adopt`
    actions before this one): once the engine took them, call
    :meth:`SwitchSession.reconcile` with the engine's wanted state.  A survey with
    nothing to adopt reconciles at once, with the wanted state the session has."""


@dataclass(frozen=True, slots=True)
class Answered:
    """The answer to the driver's question ``ticket`` (None: no answer)."""

    ticket: int
    reply: object | None


@dataclass(frozen=True, slots=True)
class End:
    """The session is over: close the port and try again later.  ``reached``: the box
    had become ready in it (the retries start over)."""

    reached: bool


Action = Write | Log | StatusChanged | Transmit | BoxError | Adopt | Reconcile | Answered | End


# ---------------------------------------------------------------------------- the rule

# ---------------------------------------------------------------------------- questions

@dataclass(slots=True)
class _Question:
    reply_type: type
    ticket: int
    expires: float
    """When the asker stops waiting."""
    gave_up: bool = False
    forget_at: float = 0.0


@dataclass(slots=True)
class _Step:
    """The questions the current phase waits for, by name, and their answers."""

    asked: dict[str, int] = field(default_factory=dict)
    answers: dict[str, Any] = field(default_factory=dict)

    def done(self) -> bool:
        return len(self.answers) == len(self.asked)


# ---------------------------------------------------------------------------- the session

QUESTIONS = (Ping, UnitId, StatusRequest, RelayStatusRequest)
"""What :meth:`SwitchSession.ask` may send: questions, which change nothing in the box."""


class SwitchSession:
    """Every decision about one MOAS II, with no I/O (see the module docstring)."""

    def __init__(
        self,
        switch_id: int,
        echo: int | None = None,
        *,
        events: tuple[StateOp, ...],
        timing: LinkTiming = REAL_TIMING,
        held: SwitchState | None = None,
        seen: Sequence[Slots] | None = None,
        where: str = "",
        strict: bool = False,
    ) -> None:
        self.switch_id = switch_id
        self.echo = echo
        self.timing = timing
        self.where = where or f"switch {switch_id}"
        self._events = events
        self._decoder = SwitchDecoder()
        self.desired = SwitchState()
        self._sent: SwitchState | None = None
        self._held = held
        """What the box was last told (a saved state, or an earlier session's): a new
        session checks what the box holds against it instead of loading it blindly."""
        self._seen: list[Slots] | None = [tuple(s) for s in seen] if seen else None  # type: ignore[misc]
        self.status = LinkStatus.CONNECTING
        self.phase = Phase.CLOSED
        self._step = _Step()
        self._survey_tries = 0
        self._questions: deque[_Question] = deque()
        self._pings: deque[tuple[Batch, int | None]] = deque()
        self._batch = Batch(None)
        self._tickets = 0
        self._last_heard = 0.0
        self._next_ping: float | None = None
        self._standing = Standing()
        """What the session carries beside its phase (:class:`.phases.Standing`)."""
        self._first_unit: int | None = None
        self._keying = Keying()
        self._last_problem = ""
        self._dwell = RelayDwell(timing.relay_dwell)
        """Automatic relay changes wait for the running dwell's end (:mod:`.dwell`)."""
        self.unit: UnitIdReply | None = None
        self.bytes_written = 0
        self.refusals: list[str] = []
        """Every plan the safety rule refused (for tests and Save Switch Data)."""
        self.strict = strict
        """A write outside the phase table raises :class:`.phases.WriteRefused` (tests)
        rather than only being refused, logged as a fault and ending the session."""
        self.faults = 0
        """Writes refused because the phase table does not allow them (programming
        errors; each ended its session)."""

    # ------------------------------------------------------------------ what it knows

    @property
    def ready(self) -> bool:
        """The box is reconciled and every ``apply`` goes straight out."""
        return self.phase in WRITES_PLANS and self._sent is not None

    @property
    def sent(self) -> SwitchState | None:
        """What the box holds as far as the session knows (None while not ready)."""
        return self._sent if self.ready else None

    @property
    def holds(self) -> SwitchState | None:
        """What the box was last told, ready or not: what a saved state should keep, so
        that a restart during an outage still checks the box rather than loading it."""
        return self._sent if self._sent is not None else self._held

    @property
    def seen(self) -> tuple[Slots, ...] | None:
        """Each station's antennas the box last reported in use (events and status)."""
        return tuple(self._seen) if self._seen is not None else None

    def keyed(self) -> frozenset[int] | None:
        """Stations transmitting as the box last said; None until it said it for all."""
        return self._keying.keyed()

    def next_deadline(self) -> float | None:
        """When :meth:`tick` must be called next (None: only input moves it)."""
        times = [q.expires for q in self._questions if not q.gave_up]
        if self.ready and (landing := self._dwell.deadline()) is not None:
            times.append(landing)
        times += [q.forget_at for q in self._questions if q.gave_up]
        if self.phase is Phase.RUNNING and self._next_ping is not None:
            times.append(self._next_ping)
        return min(times) if times else None

    # ------------------------------------------------------------------ inputs

    def opened(self, now: float) -> list[Action]:
        """A port is open to (maybe) the box: confirm it is ours."""
        self._reset_session()
        if self.phase is not Phase.CLOSED:  # a driver that reopens without closing first
            self._move(PhaseEvent.ENDED)
        self._move(PhaseEvent.OPENED)
        self._last_heard = now
        out: list[Action] = []
        self._step = _Step()
        self._step.asked["unit"] = self._question(UnitId(), UnitIdReply, now, out)
        self._step.asked["ping"] = self._ping_question(now, out)
        return out

    def lost(self, reason: str) -> list[Action]:
        """The port went away (or the driver closed it)."""
        if self.phase is Phase.CLOSED:
            return []
        return self._end_session(reached=self.phase is Phase.RUNNING)

    def feed(self, data: bytes, now: float) -> list[Action]:
        """Bytes from the box."""
        out: list[Action] = []
        if self.phase is Phase.CLOSED:
            log.debug("%s: dropped %r, which came after its session ended", self.where, data)
            return out
        for message in self._decoder.feed(data):
            if isinstance(message, Malformed):
                log.debug("%s: skipped %r: %s", self.where, message.raw, message.reason)
                continue
            self._last_heard = now
            self._message(message, now, out)
            if self._ended():
                return out
        self._progress(now, out)
        return out

    def tick(self, now: float) -> list[Action]:
        """Time passed: questions time out, pings go out, silence ends the session."""
        out: list[Action] = []
        if self.phase is Phase.CLOSED:
            return out
        for q in list(self._questions):
            if q.gave_up and q.forget_at <= now:
                self._questions.remove(q)  # the box may never have heard it
            elif not q.gave_up and q.expires <= now:
                q.gave_up = True
                q.forget_at = q.expires + self.timing.answer_timeout
                self._answer(q.ticket, None, out)
        if self.ready and self._dwell.due(now):
            self._dwell.started(now)  # the latest wanted state lands, through guard
            self._send_state(self.desired, out)
        if self.phase is Phase.RUNNING and self._next_ping is not None \
                and now >= self._next_ping:
            if now - self._last_heard > self.timing.answer_timeout:
                out += self.problem(logging.WARNING, f"{self.where} stopped answering "
                                    f"(nothing for {self.timing.answer_timeout:.1f} s); "
                                    f"will retry")
                out += self._end_session(reached=True)
                return out
            self._ping(now, out)
            self._next_ping = now + self.timing.ping_interval
        self._progress(now, out)
        return out

    @property
    def stopped(self) -> bool:
        """Stop Switches is in force: the wanted state says so (``active`` False).  In the
        server the engine owns it; :meth:`stop` and :meth:`start` set it for a driver
        without one."""
        return not self.desired.active

    def apply(self, state: SwitchState, now: float | None = None, *,
              automatic: bool = False) -> list[Action]:
        """The engine wants the box to hold ``state``; ``automatic`` when a frequency
        (a logger's, a client's) decided it, whose relay changes keep the dwell
        (:mod:`.dwell`): then, while a dwell runs, what moves relays waits for its end
        and only what makes the box stricter goes out now."""
        self.desired = state
        out: list[Action] = []
        if not (self.ready and self._sent is not None):
            return out
        self._apply(state, now, automatic, out)
        if self.phase is Phase.RUNNING:  # loading ends with its own status (_loaded)
            self._set_status(LinkStatus.STOPPED if self.stopped else LinkStatus.OK, out)
        return out

    def _apply(self, target: SwitchState, now: float | None, automatic: bool,
               out: list[Action]) -> None:
        sent = self._sent
        assert sent is not None  # apply() checked it
        if automatic and self._dwell.holds(now):
            # the latest lands at the dwell's end; until then the relays stay, the waiting
            # stations stay inhibited (also when this state happens to need no relay
            # change: no inhibit goes on and off with every packet of a flood)
            self._dwell.waiting = True
            self._send_state(interim(sent, target), out)
            return
        if moves_relays(sent, target):
            self._dwell.started(now)
        elif not automatic:
            self._dwell.waiting = False  # a press sends everything: nothing waits
        self._send_state(target, out)

    def stop(self) -> list[Action]:
        """Stop Switches: all relays off (a reset, and a load without activation): the
        wanted state, inactive (what the engine's own state says after its Stop)."""
        return self.apply(stopped(self.desired))

    def start(self) -> list[Action]:
        """Start Switches: activate a stopped switch again (the wanted state, active)."""
        return self.apply(replace(self.desired, active=True))

    def reset(self) -> list[Action]:
        """Reset Switches: the operator resets the box and it is loaded again."""
        out: list[Action] = []
        if self.ready:
            out.append(Log(logging.INFO, f"{self.where}: resetting and loading it again"))
            self._dwell.drop()  # the whole wanted state goes out now
            known = Known(box_active=True, sent=self._sent, reset_asked=True,
                          events=self._events)
            if self._send(known, self.desired, out):
                self._seen = [(NO_ANTENNA,) * 3 for _ in STATIONS]
        return out

    def ask(self, command: Command, reply_type: type, now: float) -> tuple[int, list[Action]]:
        """Ask the box ``command``; the answer comes as :class:`Answered` with the ticket
        (None when the session is not open or no answer came in time).

        Only questions are asked this way (a ping, the unit id, the status and relay
        reports), which move no relay: anything that could goes through :func:`guard`."""
        if not isinstance(command, QUESTIONS):
            raise TypeError(f"{self.where}: {type(command).__name__} is not a question; "
                             "commands that move relays go through the safety rule")
        out: list[Action] = []
        if self.phase is Phase.CLOSED:
            self._tickets += 1
            out.append(Answered(self._tickets, None))
            return self._tickets, out
        if isinstance(command, Ping):
            return self._ping_question(now, out), out
        return self._question(command, reply_type, now, out), out

    def reconcile(self, desired: SwitchState, now: float) -> list[Action]:
        """Bring a surveyed box to ``desired``, the engine's wanted state once it took the
        adopted stations (see :class:`Reconcile`): the plan :func:`.plan.choose_plan`
        picks from what the survey found, through :func:`.plan.guard`, then a ping to
        see it landed.  Returns the actions, for the driver to carry out in order (none
        when no survey waits for it)."""
        out: list[Action] = []
        r, self._standing.reconciliation = self._standing.reconciliation, None
        if r is None or self.phase is not Phase.SURVEY:
            return out
        self.desired = desired
        self._move(PhaseEvent.SURVEYED)  # loading: the phase in which the plan is written
        self._step = _Step()
        known = Known(box_active=not r.inactive, believed=r.believed, events=self._events)
        if not self._send(known, self.desired, out):
            if not self._ended():
                out += self._end_session()
            return out
        self._held = None
        self._step.asked["ping"] = self._ping_question(now, out)
        return out

    # ------------------------------------------------------------------ phases

    def _progress(self, now: float, out: list[Action]) -> None:
        step = self._step
        if self.phase is Phase.CONFIRM and step.done():
            self._confirm(now, out)
        elif self.phase is Phase.SURVEY and step.done():
            self._surveyed(now, out)
        elif self.phase is Phase.LOADING and step.done():
            self._loaded(now, out)

    def _confirm(self, now: float, out: list[Action]) -> None:
        unit, pong = self._step.answers["unit"], self._step.answers["ping"]
        if unit is None or pong is None:
            out += self.problem(logging.WARNING, f"{self.where} does not answer; will retry")
            out += self._end_session()
            return
        self.unit = unit
        refusal = self._refusal(self._standing.foreign or unit)
        if refusal:
            out += self.problem(logging.ERROR, refusal)
            out += self._end_session()
            return
        if self.echo is None and self._first_unit is None:
            self._first_unit = unit.unit
        self._survey_tries = 0
        self._ask_survey(now, out, PhaseEvent.CONFIRMED)

    def _ask_survey(self, now: float, out: list[Action], event: PhaseEvent) -> None:
        self._move(event)
        self._survey_tries += 1
        self._step = _Step()
        self._step.asked["ping"] = self._ping_question(now, out)
        self._step.asked["box"] = self._question(StatusRequest(StatusKind.BOX), BoxStatus,
                                                 now, out)
        self._step.asked["polarity"] = self._question(
            StatusRequest(StatusKind.POLARITY), PolarityStatus, now, out)
        self._step.asked["relays"] = self._question(RelayStatusRequest(), RelayStatus, now, out)

    def _surveyed(self, now: float, out: list[Action]) -> None:
        a = self._step.answers
        if any(a[name] is None for name in ("ping", "box", "polarity", "relays")):
            if self._survey_tries < SURVEY_TRIES:
                out.append(Log(logging.INFO, f"{self.where} did not answer every status "
                               "request; asking again (nothing is sent until it does)"))
                self._ask_survey(now, out, PhaseEvent.UNANSWERED)
                return
            out += self.problem(logging.WARNING, f"{self.where} did not answer every status "
                          f"request ({SURVEY_TRIES} tries): not driving it until it does; "
                          f"will retry")
            out += self._end_session()
            return
        box: BoxStatus = a["box"]
        if min(len(box.tx), len(box.rx), len(box.alt)) < len(STATIONS):
            out += self.problem(logging.WARNING, f"{self.where} sent an incomplete box status; "
                          f"will retry")
            out += self._end_session()
            return
        survey = Survey(a["ping"], box, a["polarity"], a["relays"])
        r = reconcile(self._held, self._seen, survey)
        self._standing.reconciliation = r
        self._seen = [survey.slots(n) for n in STATIONS]
        out += self._survey_actions(r)
        if r.adopt:
            out.append(Reconcile())  # the driver hands the engine's state after adopting
        else:
            out += self.reconcile(self.desired, now)

    def _survey_actions(self, r: Reconciliation) -> list[Action]:
        """What a survey found, as lines for the log and stations for the engine."""
        if self._held is None:
            said = f"{self.where}: {r.why}: loading it (no reset)"
        elif r.why:
            said = (f"{self.where} does not hold the saved state ({r.why}): " +
                    ("loading it again (no reset)" if r.believed is None
                     else "sending what differs"))
        else:
            said = (f"{self.where} still holds the saved state: carrying on without a "
                    f"reset{self._waiting_text(r)}")
        out: list[Action] = [Log(logging.INFO, said)]
        for n, slots in sorted(r.adopt.items()):
            on_air = n in r.keyed
            out.append(Log(logging.WARNING, (
                f"{self.where} station {n} "
                f"{'is transmitting on' if on_air else 'holds'} antennas "
                f"{'/'.join(str(s) for s in slots)} (transmit, receive, alternate slots), "
                f"not the saved {'/'.join(str(s) for s in self._held_slots(n))}: keeping "
                "what the box holds")))
            out.append(Adopt(n, slots, on_air))
        return out

    def _waiting_text(self, r: Reconciliation) -> str:
        if not r.waiting:
            return ""
        names = ", ".join(str(n) for n in sorted(r.waiting))
        return f" (station {names} transmitting: its change waits for receive)"

    def _held_slots(self, n: int) -> Slots:
        if self._held is None:
            return (NO_ANTENNA,) * 3
        s = self._held.station(n)
        return (s.tx, s.rx, s.alt)

    def _loaded(self, now: float, out: list[Action]) -> None:
        if self._step.answers["ping"] is None:
            out += self.problem(logging.WARNING, f"{self.where} stopped answering while loading")
            out += self._end_session()
            return
        if self._last_problem:
            out.append(Log(logging.INFO, f"{self.where} answers again"))
        self._last_problem = ""
        self._move(PhaseEvent.LOADED)
        self._next_ping = now + self.timing.ping_interval
        self._set_status(LinkStatus.STOPPED if self.stopped else LinkStatus.OK, out)

    # ------------------------------------------------------------------ writing

    def _send_state(self, target: SwitchState, out: list[Action]) -> None:
        """A running session: take the box from what it surely holds to ``target``."""
        assert self._sent is not None
        self._send(Known(box_active=self._sent.active, sent=self._sent, events=self._events),
                   target, out)

    def _send(self, known: Known, target: SwitchState, out: list[Action]) -> bool:
        """Every plan goes out here: chosen by :func:`.plan.choose_plan`, passed through
        :func:`.plan.guard`; then the box is taken to hold ``target`` (less what the
        rule held back).  False when the rule refused the plan, or when the phase table
        does not let the session write one now (:meth:`_may_write`)."""
        if not self._may_write(out):
            return False
        verdict = guard(choose_plan(known, target), self.keyed(), self.where)
        if verdict.refused:
            out.append(Log(logging.ERROR, verdict.refused))
            self.refusals.append(verdict.refused)
            return False
        plan = verdict.plan
        self._standing.station0_waits = verdict.held_back
        if verdict.held_back:
            out.append(Log(logging.INFO, f"{self.where}: its always-on (station 0) relays wait "
                           "until no station transmits"))
        if verdict.warning:
            out.append(Log(logging.WARNING, verdict.warning))
        for problem in plan.problems:
            out.append(Log(logging.ERROR, f"switch {self.switch_id}: {problem}"))
        parts = [encode(part) for command in plan.commands for part in split(command)]
        if parts:
            data = b"".join(parts)
            self._write(data, out)
            self._batch.commands += parts
        self._sent = self._told(target)
        return True

    def _told(self, target: SwitchState) -> SwitchState:
        """What the box was told of ``target``: all of it, or all but the station-0 relays
        the safety rule held back (marked unsure, so they go out later)."""
        return replace(target, station0=UNSURE_RELAYS) if self._standing.station0_waits \
            else target

    def _may_write(self, out: list[Action]) -> bool:
        """The phase table's check on every plan: only in :data:`.phases.WRITES_PLANS`.
        Anything else is a bug in the session: refused, logged as a fault, and the session
        ends (the driver opens a new one); :class:`.phases.WriteRefused` when strict."""
        if self.phase in WRITES_PLANS:
            return True
        self.faults += 1
        text = (f"{self.where}: a programming error: a plan was to be written in phase "
                f"{self.phase.value}, where the phase table allows none; refused, and the "
                "session ends")
        if self.strict:
            raise WriteRefused(text)
        out.append(Log(logging.ERROR, text))
        if not self._ended():
            out += self._end_session()
        return False

    def _write(self, data: bytes, out: list[Action]) -> None:
        out.append(Write(data))
        self.bytes_written += len(data)

    def _ping(self, now: float, out: list[Action], ticket: int | None = None) -> None:
        expect = self._sent.active if self.ready and self._sent is not None else None
        self._pings.append((Batch(expect, self._batch.commands), ticket))
        self._batch = Batch(None)
        self._write(b"';", out)

    def _ping_question(self, now: float, out: list[Action]) -> int:
        self._tickets += 1
        ticket = self._tickets
        self._questions.append(_Question(Pong, ticket, now + self.timing.answer_timeout))
        self._ping(now, out, ticket)
        return ticket

    def _question(self, command: Command, reply_type: type, now: float,
                  out: list[Action]) -> int:
        self._tickets += 1
        ticket = self._tickets
        self._questions.append(_Question(reply_type, ticket, now + self.timing.answer_timeout))
        self._write(encode(command), out)
        return ticket

    def _answer(self, ticket: int, reply: object | None, out: list[Action]) -> None:
        for name, asked in self._step.asked.items():
            if asked == ticket:
                self._step.answers[name] = reply
                return
        out.append(Answered(ticket, reply))

    # ------------------------------------------------------------------ reading

    def _message(self, message: object, now: float, out: list[Action]) -> None:
        if isinstance(message, UnitIdReply):
            self._unit_said(message, out)
            if self._ended():
                return
        self._handle(message, out)
        if isinstance(message, Pong):
            return  # answered in _pong, by the order of the pings
        for q in self._questions:
            if isinstance(message, q.reply_type):
                self._questions.remove(q)
                if q.gave_up:
                    log.debug("%s: dropped a late answer (its asker gave up): %s",
                              self.where, message)
                else:
                    self._answer(q.ticket, message, out)
                return

    def _unit_said(self, reply: UnitIdReply, out: list[Action]) -> None:
        """Any unit id the box says counts, whichever question it answers: once another
        unit's id is heard, this session drives nothing more."""
        if not self._refusal(reply):
            return
        self._standing.foreign = self._standing.foreign or reply
        if self.phase in CONFIRMED:
            out += self.problem(logging.ERROR, self._refusal(reply))
            out += self._end_session(reached=self.phase is Phase.RUNNING)

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

    def _handle(self, message: object, out: list[Action]) -> None:
        if isinstance(message, Pong):
            self._pong(message, out)
        elif isinstance(message, ErrorReply):
            commands = self._pings[0][0].commands if self._pings else self._batch.commands
            out.append(BoxError(blame(self.where, message, commands)))  # the driver logs it
        elif isinstance(message, TransmitEvent | ReceiveEvent):
            self._tr_changed(message.station, isinstance(message, TransmitEvent), out)
        elif isinstance(message, BoxStatus):
            news = self._keying.status(message.tr)
            out += [Transmit(n, on) for n, on in news]
            if news:
                self._station0_lands(out)
        elif isinstance(message, AntennaEvent):
            self._antenna_event(message, out)
        if not isinstance(message, ErrorReply) and log.isEnabledFor(logging.DEBUG):
            log.debug("%s: %s", self.where, describe(message))  # words only when wanted

    def _antenna_event(self, event: AntennaEvent, out: list[Action]) -> None:
        status = event.status
        if status in (AntennaStatus.TX_CONFLICT, AntennaStatus.RX_CONFLICT):
            kind = "transmit" if status is AntennaStatus.TX_CONFLICT else "receive"
            out.append(Log(logging.WARNING, (
                f"{self.where} holds station {event.station}'s {kind} antenna (slot "
                f"{event.antenna}): it conflicts with another station's antenna")))
            return
        if self._seen is None or event.station not in STATIONS:
            return
        tx, rx, alt = self._seen[event.station - 1]
        if status in (AntennaStatus.TX_FAST, AntennaStatus.TX_SLOW):
            tx = event.antenna
        elif status in (AntennaStatus.RX_FAST, AntennaStatus.RX_SLOW):
            rx = event.antenna
        else:
            alt = event.antenna
        self._seen[event.station - 1] = (tx, rx, alt)

    def _pong(self, pong: Pong, out: list[Action]) -> None:
        if not self._pings:
            log.debug("%s: dropped a pong no ping of this session asked for", self.where)
            return
        batch, ticket = self._pings.popleft()
        if ticket is not None:
            for q in self._questions:
                if q.ticket == ticket:
                    self._questions.remove(q)
                    if not q.gave_up:
                        self._answer(ticket, pong, out)
                    break
            else:
                log.debug("%s: dropped a late pong (its asker gave up)", self.where)
        if batch.expect_active is not None and pong.active != batch.expect_active \
                and self.ready and self._sent is not None:
            out.append(Log(logging.WARNING, (
                f"{self.where} says it is {'active' if pong.active else 'inactive'}, which "
                "it should not be: it was reset or lost power; loading it again")))
            for earlier, _ in self._pings:  # asked before the load: not to be judged
                earlier.expect_active = None
            # what it holds is not known: active while it should be stopped, a reset
            # (Stop Switches stands); inactive, the whole state as values
            if self._send(Known(box_active=pong.active, events=self._events), self.desired,
                          out):
                self._seen = [(NO_ANTENNA,) * 3 for _ in STATIONS]

    def _tr_changed(self, station: int, transmitting: bool, out: list[Action]) -> None:
        if self._keying.changed(station, transmitting):
            out.append(Transmit(station, transmitting))
            self._station0_lands(out)

    def _station0_lands(self, out: list[Action]) -> None:
        """Everyone receives: the station-0 relays held back go out now."""
        if self._standing.station0_waits and self.ready and self.keyed() == frozenset():
            self._send_state(self.desired, out)

    # ------------------------------------------------------------------ endings

    def _ended(self) -> bool:
        """The session ended (while it read what came in)."""
        return self.phase is Phase.CLOSED

    def _move(self, event: PhaseEvent) -> None:
        """The one place the phase changes: by the table of :mod:`.phases`."""
        self.phase = next_phase(self.phase, event)

    def _reset_session(self) -> None:
        self._decoder.reset()
        self._questions.clear()
        self._pings.clear()
        self._batch = Batch(None)
        self._keying.clear()
        self._standing = Standing()
        self._next_ping = None

    def _end_session(self, reached: bool = False) -> list[Action]:
        out: list[Action] = []
        for q in self._questions:
            if not q.gave_up:
                self._answer(q.ticket, None, out)
        self._questions.clear()
        if self._sent is not None:
            self._held = self._sent  # a cable pulled and plugged back must not reset a box
        self._sent = None
        self._dwell.drop()  # the next session plans from the latest wanted state
        if self.phase is not Phase.CLOSED:
            self._move(PhaseEvent.ENDED)
        self._pings.clear()
        self._step = _Step()
        out.append(End(reached))
        return out

    def _set_status(self, status: LinkStatus, out: list[Action]) -> None:
        if status is not self.status:
            self.status = status
            out.append(StatusChanged(status))

    def closed(self) -> list[Action]:
        """The driver closed the port after an :class:`End` (or to stop): unresponsive."""
        out: list[Action] = []
        self._set_status(LinkStatus.UNRESPONSIVE, out)
        return out

    def problem(self, level: int, text: str) -> list[Action]:
        """A problem, said once per outage: its first warning (and an error not said yet)
        at its level; what the retries meet after it at debug level; "answers again" ends
        the outage.  The driver passes what it meets (a port that cannot be opened) here
        too, and logs the :class:`Log` returned."""
        quiet = text == self._last_problem or (
            level <= logging.WARNING and bool(self._last_problem))
        self._last_problem = text
        return [Log(logging.DEBUG if quiet else level, text)]



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


__all__ = [
    "SURVEY_TRIES",
    "Action",
    "Adopt",
    "Answered",
    "BoxError",
    "End",
    "LinkStatus",
    "Log",
    "Phase",
    "Reconcile",
    "StatusChanged",
    "SwitchSession",
    "Transmit",
    "Verdict",
    "Write",
    "describe",
    "guard",
]
