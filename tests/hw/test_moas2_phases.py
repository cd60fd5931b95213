"""The switch session's phase table (moas_gui/hw/moas2/phases.py): every move the
session makes is one of the table's, the table is what docs/switch.md draws, and a
move it does not hold is refused."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.messages import Pong, UnitIdReply
from moas_gui.hw.moas2.phases import (
    TRANSITIONS,
    WRITES_PLANS,
    Phase,
    PhaseError,
    PhaseEvent,
    next_phase,
)
from moas_gui.hw.moas2.replies import encode_reply
from moas_gui.hw.moas2.session import Action, Adopt, SwitchSession, Write
from moas_gui.hw.moas2.sync import DEFAULT_EVENTS
from moas_gui.hw.moas2.timing import LinkTiming

DOCS = Path(__file__).resolve().parents[2] / "docs" / "switch.md"


class Watched(SwitchSession):
    """A session that notes every move it makes."""

    moves: list[tuple[Phase, PhaseEvent, Phase]]

    def _move(self, event: PhaseEvent) -> None:
        before = self.phase
        super()._move(event)
        self.__dict__.setdefault("moves", []).append((before, event, self.phase))


def drive(session: SwitchSession, model: EmulatorModel, actions: list[Action],
          now: float) -> bytes:
    wire = b""
    pending = list(actions)
    while pending:
        action = pending.pop(0)
        if isinstance(action, Write):
            wire += action.data
            answer = model.feed(action.data, now)
            if answer:
                pending += session.feed(answer, now)
        elif isinstance(action, Adopt):
            pending += session.reconcile(session.desired, now)
    return wire


def test_a_session_walks_the_table_from_closed_to_running_and_back() -> None:
    session = Watched(1, events=DEFAULT_EVENTS, timing=LinkTiming())
    model = EmulatorModel()
    drive(session, model, session.opened(0.0), 0.0)
    assert session.phase is Phase.RUNNING
    session.lost("pulled")
    assert [(a.value, e.value, b.value) for a, e, b in session.moves] == [
        ("closed", "opened", "confirm"), ("confirm", "confirmed", "survey"),
        ("survey", "surveyed", "loading"), ("loading", "loaded", "running"),
        ("running", "ended", "closed")]
    assert all(TRANSITIONS[(a, e)] is b for a, e, b in session.moves)


def test_an_unanswered_survey_is_asked_again_in_the_same_phase() -> None:
    session = Watched(1, events=DEFAULT_EVENTS, timing=LinkTiming())
    out = session.opened(0.0)
    out += session.feed(encode_reply(UnitIdReply("100", 0)) + encode_reply(Pong(True)), 0.1)
    assert session.phase is Phase.SURVEY
    session.tick(0.1 + LinkTiming().answer_timeout + 0.01)  # nothing answered
    assert (Phase.SURVEY, PhaseEvent.UNANSWERED, Phase.SURVEY) in session.moves


def test_a_move_the_table_does_not_hold_is_refused() -> None:
    with pytest.raises(PhaseError, match="no move from running on opened"):
        next_phase(Phase.RUNNING, PhaseEvent.OPENED)
    with pytest.raises(PhaseError):
        next_phase(Phase.CLOSED, PhaseEvent.ENDED)
    for phase in Phase:
        if phase is not Phase.CLOSED:
            assert next_phase(phase, PhaseEvent.ENDED) is Phase.CLOSED


def test_plans_are_written_only_after_the_survey() -> None:
    assert WRITES_PLANS == {Phase.LOADING, Phase.RUNNING}
    before = {b for (a, _e), b in TRANSITIONS.items() if a in (Phase.CLOSED, Phase.CONFIRM)}
    assert not before & WRITES_PLANS  # confirm and survey come first


def test_docs_draw_the_same_table() -> None:
    text = DOCS.read_text(encoding="utf-8")
    rows = set(re.findall(r"^ *\| (\w+) \| (\w+) \| (\w+) \|$", text, re.MULTILINE))
    wanted = {(a.value, e.value, b.value) for (a, e), b in TRANSITIONS.items()}
    assert rows >= wanted, sorted(wanted - rows)
