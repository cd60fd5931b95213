"""The phase table decides what a switch session may write (moas_gui/hw/moas2/phases.py).

A property walk: a session against the emulator model, driven by random events (ports
opened and lost, time passing, wanted states, the operator's Stop, Start and Reset,
reconciliations asked early or twice, key changes, another unit's id, a box found
inactive, a deaf box, questions).  Every write is watched with the phase it was made
in: nothing but a question (:data:`.questions.QUESTIONS`) goes out outside
:data:`.phases.WRITES_PLANS`.  A plan asked for out of turn (what a bug in the session
would do) is refused: :class:`.phases.WriteRefused` under ``strict``, a logged fault
and an ended session otherwise.

The walk is shown to catch what it guards against: with the table's check removed, a
plan asked for out of turn is written; with ``reconcile`` writing before it moves to
loading (the order before issue 41), the check refuses it, and without the check the
walk sees the write in survey.
"""

from __future__ import annotations

import logging
from dataclasses import replace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.commands import encode
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.messages import (
    Ping,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    StatusKind,
    StatusRequest,
    UnitId,
    UnitIdReply,
)
from moas_gui.hw.moas2.phases import WRITES_PLANS, Phase, PhaseEvent, WriteRefused
from moas_gui.hw.moas2.plan import Known
from moas_gui.hw.moas2.replies import encode_reply
from moas_gui.hw.moas2.session import (
    Action,
    Adopt,
    End,
    Log,
    SwitchSession,
    Write,
)
from moas_gui.hw.moas2.sync import DEFAULT_EVENTS
from moas_gui.hw.moas2.timing import LinkTiming

TIMING = LinkTiming()
A = StationAntennas(tx=1, tx_relays=frozenset({1, 2}), rx=1, rx_relays=frozenset({1, 2}))
B = StationAntennas(tx=3, tx_relays=frozenset({5}), rx=3, rx_relays=frozenset({5}))
STATE_A = SwitchState(stations=(A,) + (StationAntennas(),) * 5, conflicts=frozenset({(1, 1)}),
                      station0=frozenset({7}))
STATE_B = replace(STATE_A, stations=(B,) + (StationAntennas(),) * 5, station0=frozenset({8}))
STATES = (STATE_A, STATE_B, replace(STATE_A, active=False))

QUESTION_BYTES = frozenset({
    encode(Ping()), encode(UnitId()), encode(StatusRequest(StatusKind.BOX)),
    encode(StatusRequest(StatusKind.POLARITY)), encode(RelayStatusRequest())})
"""Everything a session may write outside loading and running: questions."""

EVENTS = ("open", "lost", "tick", "apply", "auto", "stop", "start", "reset", "reconcile",
          "key", "unkey", "foreign", "inactive", "deaf", "ask")
STEPS = st.lists(st.tuples(st.sampled_from(EVENTS), st.integers(0, 5)), max_size=50)
DELAYS = (0.02, 0.11, 0.6, 1.1, 3.5)


class Watched(SwitchSession):
    """A session that notes every write with the phase it was made in."""

    writes: list[tuple[Phase, bytes]]

    def _write(self, data: bytes, out: list[Action]) -> None:
        self.__dict__.setdefault("writes", []).append((self.phase, data))
        super()._write(data, out)


class Walk:
    """A session and the emulator model, with the driver's part played by hand."""

    def __init__(self, session_type: type[Watched], strict: bool = True) -> None:
        self.session = session_type(1, events=DEFAULT_EVENTS, timing=TIMING, strict=strict)
        self.model = EmulatorModel()
        self.now = 0.0
        self.deaf = False
        self.reconcile_due = False
        self.ended = 0

    def run(self, actions: list[Action]) -> None:
        pending = list(actions)
        while pending:
            action = pending.pop(0)
            if isinstance(action, Write):
                answer = self.model.feed(action.data, self.now)
                if answer and not self.deaf:
                    pending += self.session.feed(answer, self.now)
            elif isinstance(action, Adopt):
                self.reconcile_due = True  # the engine adopts: a later event reconciles
            elif isinstance(action, End):
                self.ended += 1

    def box_says(self, data: bytes) -> None:
        self.run(self.session.feed(data, self.now))

    def step(self, event: str, n: int) -> None:
        s = self.session
        if event == "open":
            self.run(s.opened(self.now))
        elif event == "lost":
            self.run(s.lost("pulled"))
        elif event == "tick":
            self.now += DELAYS[n % len(DELAYS)]
            answer = self.model.advance(self.now)
            if answer and not self.deaf:
                self.box_says(answer)
            self.run(s.tick(self.now))
        elif event in ("apply", "auto"):
            self.run(s.apply(STATES[n % len(STATES)], self.now, automatic=event == "auto"))
        elif event in ("stop", "start"):  # Stop and Start Switches: the wanted state
            self.run(s.apply(replace(s.desired, active=event == "start"), self.now))
        elif event == "reset":
            self.run(s.reset())
        elif event == "reconcile":
            self.reconcile_due = False
            self.run(s.reconcile(STATES[n % len(STATES)], self.now))
        elif event in ("key", "unkey"):
            answer = self.model.set_tr(1 + n, event == "key", self.now)
            if not self.deaf:
                self.box_says(answer)
        else:
            self.other(event, n)

    def other(self, event: str, n: int) -> None:
        if event == "foreign":
            self.box_says(encode_reply(UnitIdReply("100", 40 + n)))
        elif event == "inactive":
            self.box_says(encode_reply(Pong(False)))
        elif event == "deaf":
            self.deaf = not self.deaf
        elif event == "ask":
            self.run(self.session.ask(RelayStatusRequest(), RelayStatus, self.now)[1])

    def stray(self) -> None:
        """What a bug in the session would do: a plan asked for in whatever phase."""
        out: list[Action] = []
        self.session._send(Known(box_active=True, events=DEFAULT_EVENTS), STATE_B, out)
        self.run(out)


def outside_the_table(session: Watched) -> list[tuple[Phase, bytes]]:
    """Every write that is not a question, made outside :data:`WRITES_PLANS`."""
    return [(phase, data) for phase, data in session.__dict__.get("writes", [])
            if phase not in WRITES_PLANS and data not in QUESTION_BYTES]


def walk(session_type: type[Watched], steps: list[tuple[str, int]], *,
         strays: bool = False, strict: bool = True) -> Walk:
    played = Walk(session_type, strict=strict)
    played.run(played.session.opened(0.0))
    for event, n in steps:
        played.step(event, n)
        if strays and n == 0:
            played.stray()
        if played.reconcile_due and n % 2:
            played.step("reconcile", 0)
    return played


@given(STEPS)
def test_no_plan_is_written_outside_loading_and_running(steps: list[tuple[str, int]]) -> None:
    played = walk(Watched, steps)
    assert outside_the_table(played.session) == []
    assert played.session.faults == 0


@given(STEPS)
def test_a_plan_asked_for_out_of_turn_is_refused(steps: list[tuple[str, int]]) -> None:
    played = Walk(Watched)
    played.run(played.session.opened(0.0))
    for event, n in steps:
        played.step(event, n)
        phase, before = played.session.phase, played.session.faults
        if phase in WRITES_PLANS:
            played.stray()  # allowed there: through the safety rule like every plan
            continue
        with pytest.raises(WriteRefused, match=f"phase {phase.value}"):
            played.stray()
        assert played.session.faults == before + 1
    assert outside_the_table(played.session) == []


def test_out_of_turn_outside_tests_is_a_logged_fault_and_ends_the_session() -> None:
    played = Walk(Watched, strict=False)
    played.deaf = True
    played.run(played.session.opened(0.0))
    assert played.session.phase is Phase.CONFIRM
    out: list[Action] = []
    played.session._send(Known(box_active=True, events=DEFAULT_EVENTS), STATE_B, out)
    assert played.session.faults == 1
    assert [a for a in out if isinstance(a, Log) and a.level == logging.ERROR
            and "programming error" in a.text and "phase confirm" in a.text]
    assert [a for a in out if isinstance(a, End)], "the session ends; the driver opens anew"
    assert played.session.phase.value == "closed"
    assert not [a for a in out if isinstance(a, Write)]
    assert outside_the_table(played.session) == []


# ---------------------------------------------------------------- broken copies

class Unchecked(Watched):
    """The session with the table's check removed."""

    def _may_write(self, out: list[Action]) -> bool:
        return True


class WritesFirst(Watched):
    """``reconcile`` as it was before issue 41: the plan written while still in survey,
    the move to loading after."""

    def reconcile(self, desired: SwitchState, now: float) -> list[Action]:
        out: list[Action] = []
        r, self._notes.reconciliation = self._notes.reconciliation, None
        if r is None or self.phase is not Phase.SURVEY:
            return out
        self.desired = desired
        self._send(Known(box_active=not r.inactive, believed=r.believed,
                         events=DEFAULT_EVENTS), desired, out)
        self._move(PhaseEvent.SURVEYED)
        return out


class WritesFirstUnchecked(WritesFirst, Unchecked):
    pass


FIRST_STEPS = [("tick", 0)]
"""The confirmation and the survey answered at once: one tick reaches reconcile."""


def test_without_the_check_a_plan_out_of_turn_is_written() -> None:
    played = walk(Unchecked, [("deaf", 1), ("open", 0)], strays=True)
    assert [phase for phase, _ in outside_the_table(played.session)] == [Phase.CONFIRM]


def test_reconcile_writing_in_survey_is_refused_by_the_check() -> None:
    played = Walk(WritesFirst)
    with pytest.raises(WriteRefused, match="phase survey"):
        played.run(played.session.opened(0.0))


def test_reconcile_writing_in_survey_is_seen_by_the_walk_without_the_check() -> None:
    played = walk(WritesFirstUnchecked, FIRST_STEPS)
    found = outside_the_table(played.session)
    assert found and {phase for phase, _ in found} == {Phase.SURVEY}
