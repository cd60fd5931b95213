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
(the engine's wanted state; Stop and Start Switches are wanted states too, inactive
and active again), :meth:`~SwitchSession.reconcile` (the engine's wanted state after
it adopted what a survey found), :meth:`~SwitchSession.reset` (the operator) and
:meth:`~SwitchSession.ask` (a question of the driver's own).  Each returns a list of
actions (:mod:`.actions`), for the driver to carry out in order.

The session is its phases and a few pure parts, each with one job:
:class:`.questions.Questions` (tickets, answers, timeouts, pings),
:class:`.reading.BoxReader` (key states, antennas in use, errors blamed),
:class:`.reading.UnitCheck` (is the box ours), :class:`.writer.PlanWriter` (what the
box holds, the plans through the safety rule, the relay dwell), :mod:`.survey` (what
a survey asks and says) and :class:`.actions.Voice` (the status, each outage said once).

A session's life (the phases' table is :mod:`.phases`):

1. **Confirm**: ask the unit id and a ping; a box that answers with another unit
   (or says another unit's id before that ping's answer) is not driven.
2. **Survey**: ask what the box holds and who transmits (ping, box status,
   inhibit polarity, relays), up to :data:`SURVEY_TRIES` times.  Until every
   answer is in, nothing is written that could move a relay.
3. **Reconcile** (:func:`.resync.reconcile` judges what the box holds): stations
   whose antennas on the box win over a stale saved state come back as one
   :class:`~.actions.Adopt`, after which the driver calls
   :meth:`~SwitchSession.reconcile` with the engine's wanted state; with nothing to
   adopt the session reconciles at once.  Reconciling moves to loading, then writes
   the plan: the difference from what the box is believed to hold or, when its
   contents are unsure, the whole state as values (:func:`.sync.absolute`), never a
   reset unless Stop Switches stands.
4. **Run**: a ping every ``ping_interval``; silence past ``answer_timeout`` ends the
   session (the driver retries); a box that says it is inactive when it should be
   active lost its state and is loaded again as values.

**What may be written**: questions (:data:`QUESTIONS`) in any open phase; a plan only
in a phase of :data:`.phases.WRITES_PLANS`, which :meth:`SwitchSession._may_write`
checks for every plan (:meth:`SwitchSession._send`, the one place a plan is written).
**The safety rule** is :func:`.plan.guard`, the one gate every plan goes through,
and every plan is chosen by :func:`.plan.choose_plan` beside it (the session only
says what it knows: what the box surely holds, what it is believed to hold, whether
the operator pressed Reset).  ``guard``'s whole scope is in :mod:`.plan`'s docstring.

The session says what to log as :class:`~.actions.Log` actions, which the driver
writes; it logs only its debug lines itself (a skipped malformed reply, a late answer
dropped, each message in words), lazily, so that they cost nothing on the busy path
while debug is off.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from ...engine.switchstate import STATIONS, SwitchState
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
    Voice,
    Write,
    describe,
)
from .decoder import SwitchDecoder
from .messages import (
    Command,
    ErrorReply,
    Malformed,
    Ping,
    Pong,
    StateOp,
    UnitId,
    UnitIdReply,
)
from .phases import (
    CONFIRMED,
    WRITES_PLANS,
    Phase,
    PhaseEvent,
    SessionNotes,
    WriteRefused,
    next_phase,
)
from .plan import Known, Verdict, guard
from .questions import QUESTIONS, Questions, Step, only_question
from .reading import NOTHING, BoxReader, UnitCheck, reset_found
from .resync import Slots, Survey, reconcile
from .survey import SURVEY, SURVEY_TRIES, answered, found, trouble
from .timing import REAL_TIMING, LinkTiming
from .writer import PlanWriter

log = logging.getLogger(__name__)

CONFIRM: dict[str, tuple[Command, type]] = {"unit": (UnitId(), UnitIdReply), "ping": (Ping(), Pong)}
LOAD_CHECK: dict[str, tuple[Command, type]] = {"ping": (Ping(), Pong)}


class SwitchSession:
    """Every decision about one MOAS II, with no I/O (see the module docstring)."""

    def __init__(self, switch_id: int, echo: int | None = None, *,
                 events: tuple[StateOp, ...], timing: LinkTiming = REAL_TIMING,
                 held: SwitchState | None = None, seen: Sequence[Slots] | None = None,
                 where: str = "", strict: bool = False) -> None:
        self.switch_id = switch_id
        self.echo = echo
        self.timing = timing
        self.where = where or f"switch {switch_id}"
        self._decoder = SwitchDecoder()
        self.desired = SwitchState()
        """The engine's wanted state, the one place "stopped" is read from (inactive)."""
        self.phase = Phase.CLOSED
        self._notes = SessionNotes()
        """What the session carries beside its phase (:class:`.phases.SessionNotes`)."""
        self.questions = Questions(self.where, timing.answer_timeout, timing.ping_interval)
        self.reader = BoxReader(self.where, seen)
        self.unit_check = UnitCheck(self.where, echo)
        self.writer = PlanWriter(self.where, events, timing.relay_dwell, held)
        self.voice = Voice()
        self.bytes_written = 0
        self.strict = strict  # a write the table refuses raises WriteRefused (the tests)
        self.faults = 0  # writes the table refused (programming errors, each ended its session)

    @property
    def ready(self) -> bool:
        """Every ``apply`` goes straight out: in :data:`.phases.WRITES_PLANS`, loaded."""
        return self.phase in WRITES_PLANS and self.writer.sent is not None

    @property
    def sent(self) -> SwitchState | None:
        """What the box holds as far as the session knows (None while not ready)."""
        return self.writer.sent if self.ready else None

    @property
    def status(self) -> LinkStatus:
        return self.voice.status

    def keyed(self) -> frozenset[int] | None:
        """Stations transmitting as the box last said; None until it said it for all."""
        return self.reader.keying.keyed()

    def next_deadline(self) -> float | None:
        """When :meth:`tick` must be called next (None: only input moves it)."""
        times = [self.questions.deadline(), self.writer.dwell.deadline() if self.ready else None]
        return min((t for t in times if t is not None), default=None)

    def opened(self, now: float) -> list[Action]:
        """A port is open to (maybe) the box: confirm it is ours."""
        self._decoder.reset()
        self.questions.clear(now)
        self.reader.keying.clear()
        self._notes = SessionNotes()
        if self.phase is not Phase.CLOSED:  # a driver that reopens without closing first
            self.writer.ended()
            self._move(PhaseEvent.ENDED)
        out: list[Action] = []
        self._ask_step(PhaseEvent.OPENED, CONFIRM, now, out)
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
            self.questions.last_heard = now
            self._message(message, out)
            if _ended(self):
                return out
        self._progress(now, out)
        return out

    def tick(self, now: float) -> list[Action]:
        """Time passed: questions time out, pings go out, silence ends the session."""
        out: list[Action] = []
        if self.phase is Phase.CLOSED:
            return out
        out += self.questions.expired(now)
        if self.ready and self.writer.dwell.due(now):
            self.writer.dwell.started(now)  # the latest wanted state lands, through guard
            self._send(self.writer.known(), self.desired, out)
        due = self.questions.ping_due(now)
        if due is False:
            out += self.voice.problem(logging.WARNING, f"{self.where} stopped answering "
                                      f"(nothing for {self.timing.answer_timeout:.1f} s); "
                                      "will retry")
            return out + self._end_session(reached=True)
        if due:
            self._write(self.questions.pinged(self.writer.expect()), out)
        self._progress(now, out)
        return out

    def apply(self, state: SwitchState, now: float | None = None, *,
              automatic: bool = False) -> list[Action]:
        """The engine wants the box to hold ``state`` (inactive: Stop Switches stands);
        ``automatic``: a frequency decided it, and its relay changes keep the dwell."""
        self.desired = state
        out: list[Action] = []
        if not self.ready:
            return out
        self._send(self.writer.known(), self.writer.now_target(state, now, automatic), out)
        if self.phase is Phase.RUNNING:  # loading ends with its own status (_progress)
            self._running_status(out)
        return out

    def reset(self) -> list[Action]:
        """Reset Switches: the operator resets the box and it is loaded again."""
        out: list[Action] = []
        if self.ready:
            out.append(Log(logging.INFO, f"{self.where}: resetting and loading it again"))
            self.writer.dwell.drop()  # the whole wanted state goes out now
            known = Known(box_active=True, sent=self.writer.sent, reset_asked=True,
                          events=self.writer.events)
            if self._send(known, self.desired, out):
                self.reader.surveyed([NOTHING for _ in STATIONS])
        return out

    def ask(self, command: Command, reply_type: type, now: float) -> tuple[int, list[Action]]:
        """Ask the box ``command``, a question only (:data:`.questions.QUESTIONS`: nothing
        that moves a relay); the answer comes as :class:`~.actions.Answered` with the
        ticket (None when the session is not open or no answer came in time)."""
        only_question(self.where, command)
        if self.phase is Phase.CLOSED:
            ticket = self.questions.ticket()
            return ticket, [Answered(ticket, None)]
        out: list[Action] = []
        ticket, data = self.questions.asked(command, reply_type, now, self.writer.expect())
        self._write(data, out)
        return ticket, out

    def reconcile(self, desired: SwitchState, now: float) -> list[Action]:
        """Bring a surveyed box to ``desired``, the engine's wanted state once it took the
        adopted stations (:class:`~.actions.Adopt`): move to loading, then send the plan
        for what the survey found (:meth:`_send`) and a ping to see it landed."""
        out: list[Action] = []
        r, self._notes.reconciliation = self._notes.reconciliation, None
        if r is None or self.phase is not Phase.SURVEY:
            return out
        self.desired = desired
        self._move(PhaseEvent.SURVEYED)  # loading: the phase in which the plan is written
        known = Known(box_active=not r.inactive, believed=r.believed, events=self.writer.events)
        if not self._send(known, self.desired, out):
            return out if _ended(self) else out + self._end_session()
        self.writer.held = None
        self._ask_step(None, LOAD_CHECK, now, out)
        return out

    def _progress(self, now: float, out: list[Action]) -> None:
        if not self.questions.step.done():
            return
        if self.phase is Phase.CONFIRM:
            self._confirm(now, out)
        elif self.phase is Phase.SURVEY and self._notes.reconciliation is None:
            self._surveyed(now, out)
        elif self.phase is Phase.LOADING:
            if self.questions.step.answers["ping"] is None:
                out += self.voice.problem(logging.WARNING,
                                          f"{self.where} stopped answering while loading")
                out += self._end_session()
                return
            out += self.voice.recovered(self.where)
            self._move(PhaseEvent.LOADED)
            self.questions.next_ping = now + self.timing.ping_interval
            self._running_status(out)

    def _confirm(self, now: float, out: list[Action]) -> None:
        answers = self.questions.step.answers
        refused = self.unit_check.judge(answers["unit"], answers["ping"], self._notes.foreign)
        if refused is not None:
            out += self.voice.problem(*refused)
            out += self._end_session()
            return
        self._notes.survey_tries = 1
        self._ask_step(PhaseEvent.CONFIRMED, SURVEY, now, out)

    def _surveyed(self, now: float, out: list[Action]) -> None:
        survey = answered(self.questions.step.answers)
        if survey == "unanswered" and self._notes.survey_tries < SURVEY_TRIES:
            out.append(Log(logging.INFO,
                           trouble(self.where, survey, self._notes.survey_tries)))
            self._notes.survey_tries += 1
            self._ask_step(PhaseEvent.UNANSWERED, SURVEY, now, out)
            return
        if not isinstance(survey, Survey):
            out += self.voice.problem(logging.WARNING,
                                      trouble(self.where, survey, SURVEY_TRIES))
            out += self._end_session()
            return
        r = reconcile(self.writer.held, self.reader.seen, survey)
        self._notes.reconciliation = r
        self.reader.surveyed([survey.slots(n) for n in STATIONS])
        out += found(self.where, self.writer.held, r)
        if not r.adopt:  # else the driver hands the engine's state after adopting
            out += self.reconcile(self.desired, now)

    def _ask_step(self, event: PhaseEvent | None, asked: dict[str, tuple[Command, type]],
                  now: float, out: list[Action]) -> None:
        """Move by ``event`` (if any), then ask the new step's questions."""
        if event is not None:
            self._move(event)
        step = self.questions.step = Step()
        for name, (command, reply_type) in asked.items():
            step.asked[name], data = self.questions.asked(command, reply_type, now,
                                                          self.writer.expect())
            self._write(data, out)

    def _running_status(self, out: list[Action]) -> None:
        """The one place a running session's status is chosen: Stop Switches stands
        (the wanted state, inactive) or not."""
        out += self.voice.set(LinkStatus.OK if self.desired.active else LinkStatus.STOPPED)

    def _send(self, known: Known, target: SwitchState, out: list[Action]) -> bool:
        """Every plan goes out here, only in a phase the table allows (:meth:`_may_write`),
        chosen and guarded by :meth:`.writer.PlanWriter.plan`.  False when refused."""
        if not self._may_write(out):
            return False
        parts = self.writer.plan(known, target, self.keyed(), out)
        if parts is None:
            return False
        if parts:
            self._write(b"".join(parts), out)
            self.questions.wrote(parts)
        return True

    def _may_write(self, out: list[Action]) -> bool:
        """The phase table's check on every plan: only in :data:`.phases.WRITES_PLANS`.
        Anything else is a bug in the session: refused, logged as a fault, and the session
        ends (the driver opens a new one); :class:`.phases.WriteRefused` when strict."""
        if self.phase in WRITES_PLANS:
            return True
        self.faults += 1
        text = WriteRefused.text(self.where, self.phase)
        if self.strict:
            raise WriteRefused(text)
        out.append(Log(logging.ERROR, text))
        if self.phase is not Phase.CLOSED:
            out += self._end_session()
        return False

    def _write(self, data: bytes, out: list[Action]) -> None:
        out.append(Write(data))
        self.bytes_written += len(data)

    def _message(self, message: object, out: list[Action]) -> None:
        if isinstance(message, UnitIdReply) and self.unit_check.refusal(message):
            # any unit id the box says counts, whichever question it answers
            self._notes.foreign = self._notes.foreign or message
            if self.phase in CONFIRMED:
                out += self.voice.problem(logging.ERROR, self.unit_check.refusal(message))
                out += self._end_session(reached=self.phase is Phase.RUNNING)
                return
        news = self.reader.read(message, self.questions.blamed(), out)
        if not isinstance(message, ErrorReply) and log.isEnabledFor(logging.DEBUG):
            log.debug("%s: %s", self.where, describe(message))  # words only when wanted
        batch, answers = self.questions.took(message)
        out += answers
        if news and self.writer.station0_waits and self.ready and self.keyed() == frozenset():
            # everyone receives: the station-0 relays held back go out now
            self._send(self.writer.known(), self.desired, out)
        if isinstance(message, Pong) and batch is not None and self.ready \
                and batch.expect_active not in (None, message.active):
            out.append(Log(logging.WARNING, reset_found(self.where, message.active)))
            self.questions.unjudge()  # asked before the load: not to be judged
            # what it holds is not known: active while it should be stopped, a reset
            # (Stop Switches stands); inactive, the whole state as values
            if self._send(Known(box_active=message.active, events=self.writer.events),
                          self.desired, out):
                self.reader.surveyed([NOTHING for _ in STATIONS])

    def _move(self, event: PhaseEvent) -> None:
        """The one place the phase changes: by the table of :mod:`.phases`."""
        self.phase = next_phase(self.phase, event)

    def _end_session(self, reached: bool = False) -> list[Action]:
        out = self.questions.dropped()
        self.writer.ended()
        if self.phase is not Phase.CLOSED:
            self._move(PhaseEvent.ENDED)
        out.append(End(reached))
        return out


def _ended(session: SwitchSession) -> bool:
    """The session ended (while it read what came in, or wrote)."""
    return session.phase is Phase.CLOSED


__all__ = [
    "QUESTIONS",
    "SURVEY_TRIES",
    "Action",
    "Adopt",
    "Answered",
    "BoxError",
    "End",
    "LinkStatus",
    "Log",
    "Phase",
    "StatusChanged",
    "SwitchSession",
    "Transmit",
    "Verdict",
    "Write",
    "describe",
    "guard",
]
