"""The switch session's pure parts, each on its own (moas_gui/hw/moas2/: keying.py,
questions.py, reading.py, listener.py), and what their split changed for the session:
a box status is read whole before the held-back station-0 relays may go out."""

from __future__ import annotations

import logging
from dataclasses import replace
from pathlib import Path

import pytest

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.actions import Answered, LinkStatus, Slots
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.keying import Keying
from moas_gui.hw.moas2.listener import SwitchListener, Told
from moas_gui.hw.moas2.messages import (
    BoxStatus,
    Ping,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    SetState,
    StateOp,
    TRState,
    UnitId,
    UnitIdReply,
)
from moas_gui.hw.moas2.questions import Questions
from moas_gui.hw.moas2.reading import UnitCheck
from moas_gui.hw.moas2.replies import encode_reply
from moas_gui.hw.moas2.session import Action, SwitchSession, Write
from moas_gui.hw.moas2.sync import DEFAULT_EVENTS, initialise
from moas_gui.hw.moas2.timing import LinkTiming

R, T, I = TRState.RECEIVE, TRState.TRANSMIT, TRState.INHIBITED


def test_keying_is_unknown_until_a_status_says_every_station() -> None:
    keying = Keying()
    assert keying.changed(1, True)
    assert keying.keyed() is None  # an event alone does not say the other five
    assert keying.status((R, R, I, R, R, R)) == [(n, False) for n in range(1, 7)]
    assert keying.keyed() == {3}  # shown inhibited by command: may be keyed behind it
    # an event for it: no news (it was shown not transmitting), but no longer unsure
    assert not keying.changed(3, False) and keying.keyed() == frozenset()
    keying.clear()
    assert keying.keyed() is None


def test_questions_take_nothing_but_questions() -> None:
    questions = Questions("switch 1", answer_timeout=3.0, ping_interval=1.0)
    with pytest.raises(TypeError, match="SetState is not a question"):
        questions.asked(SetState((StateOp.RESET,)), Pong, 0.0, None)  # type: ignore[arg-type]
    ticket, data = questions.asked(RelayStatusRequest(), RelayStatus, 0.0, None)
    assert data == b"|;"
    assert questions.expired(3.0) == [Answered(ticket, None)]  # given up
    # its late answer is dropped, never taken for the next question of its kind
    later, _ = questions.asked(RelayStatusRequest(), RelayStatus, 3.5, None)
    assert questions.took(RelayStatus(frozenset({1}))) == (None, [])
    assert questions.took(RelayStatus(frozenset({2}))) == (
        None, [Answered(later, RelayStatus(frozenset({2})))])


def test_the_ping_clock_ends_a_silent_session() -> None:
    questions = Questions("switch 1", answer_timeout=3.0, ping_interval=1.0)
    questions.clear(0.0)
    assert questions.ping_due(5.0) is None  # not running: no ping clock
    questions.next_ping = 1.0
    assert questions.ping_due(0.5) is None
    assert questions.ping_due(1.0) is True and questions.next_ping == 2.0
    assert questions.pinged(True) == b"';"
    assert questions.ping_due(3.5) is False  # nothing heard for longer than the timeout


def test_a_unit_check_without_echo_keeps_to_the_first_box() -> None:
    check = UnitCheck("switch 1", echo=None)
    assert check.judge(None, Pong(True), None) == (logging.WARNING,
                                                  "switch 1 does not answer; will retry")
    assert check.judge(UnitIdReply("100", 4), Pong(True), None) is None
    level, text = check.judge(UnitIdReply("100", 5), Pong(True), None) or (0, "")
    assert level == logging.ERROR and "before was unit 4" in text
    # another unit's id heard during the confirmation refuses it, whatever answered
    assert check.judge(UnitIdReply("100", 4), Pong(True), UnitIdReply("100", 9)) is not None


def test_the_listener_is_told_what_is_seen_anew_and_a_failure_is_logged(
        caplog: pytest.LogCaptureFixture) -> None:
    heard: list[tuple[int, Slots]] = []

    class Listener(SwitchListener):
        def seen(self, station: int, slots: Slots) -> None:
            heard.append((station, slots))

        def status(self, status: LinkStatus) -> None:
            raise RuntimeError("server bug")

    told = Told(Listener(), "switch 1")
    told.seen(((1, 1, 63), (2, 2, 63)))
    told.seen(((1, 1, 63), (3, 3, 63)))
    assert heard == [(1, (1, 1, 63)), (2, (2, 2, 63)), (2, (3, 3, 63))]
    with caplog.at_level(logging.ERROR, "moas_gui.hw.moas2"):
        assert told.call(told.listener.status, LinkStatus.OK) is None
    assert any("callback failed" in r.getMessage() for r in caplog.records)


A = StationAntennas(tx=1, tx_relays=frozenset({1, 2}), rx=1, rx_relays=frozenset({1, 2}))
STATE = SwitchState(stations=(A,) + (StationAntennas(),) * 5)


def _run(session: SwitchSession, model: EmulatorModel, actions: list[Action]) -> bytes:
    wire = b""
    while actions:
        action = actions.pop(0)
        if isinstance(action, Write):
            wire += action.data
            if answer := model.feed(action.data, 0.0):
                actions += session.feed(answer, 0.0)
    return wire


def test_held_back_station_0_relays_wait_for_a_status_read_whole() -> None:
    """A box status that shows one station receiving and another inhibited by command
    (which may be keyed behind its inhibit) does not let the station-0 relays out."""
    model = EmulatorModel()
    model.feed(initialise(STATE).encode(), 0.0)
    model.feed(b"*1;", 0.0)
    model.set_tr(2, True, 0.0)
    session = SwitchSession(1, events=DEFAULT_EVENTS, timing=LinkTiming(), held=STATE,
                            strict=True)
    wanted = replace(STATE, station0=frozenset({61}))
    session.apply(wanted)
    wire = _run(session, model, session.opened(0.0))
    assert session.ready and b"!0X" not in wire  # held back: station 2 transmits
    status = BoxStatus((R, R, I, R, R, R), (1,) + (63,) * 5, (1,) + (63,) * 5, (63,) * 6)
    out = session.feed(encode_reply(status), 0.0)
    assert not any(isinstance(a, Write) and b"!0X" in a.data for a in out)
    assert session.keyed() == {3}
    # station 3's receive, once known, lets them out: nobody counts as keyed any more
    # (its state was "receive" all along, only its inhibit hid it)
    out = session.feed(encode_reply(replace(status, tr=(R,) * 6)), 0.0)
    assert session.keyed() == frozenset()
    assert any(isinstance(a, Write) and b"!0X" in a.data for a in out)


def test_a_session_asks_only_questions_of_its_own_accord() -> None:
    session = SwitchSession(1, events=DEFAULT_EVENTS, strict=True)
    ticket, out = session.ask(Ping(), Pong, 0.0)
    assert out == [Answered(ticket, None)]  # no port open: no answer, nothing written
    with pytest.raises(TypeError):
        session.ask(SetState((StateOp.ACTIVATE,)), Pong, 0.0)  # type: ignore[arg-type]
    session.opened(0.0)
    _, out = session.ask(UnitId(), UnitIdReply, 0.0)
    assert [a.data for a in out if isinstance(a, Write)] == [b":;"]


LAYER = Path(__file__).resolve().parents[2] / "moas_gui" / "hw" / "moas2"
RESET_BUILDERS = ("initialise(", "StateOp.RESET")
NOT_CHOOSERS = {"sync.py": "builds the reset-and-load", "diagnostics.py": "text only (Save "
                "Switch Data shows the load)", "__init__.py": "re-exports the codec"}


def reset_choosers(sources: dict[str, str]) -> list[str]:
    """The modules (by name) that reach a reset: call :func:`.sync.initialise` or name
    ``StateOp.RESET``, beside those that build it or only show it as text."""
    return sorted(name for name, text in sources.items()
                  if name not in NOT_CHOOSERS and any(b in text for b in RESET_BUILDERS))


def test_choose_plan_is_the_one_place_a_reset_is_chosen() -> None:
    sources = {p.name: p.read_text(encoding="utf-8") for p in LAYER.glob("*.py")}
    assert reset_choosers(sources) == ["plan.py"]
    # a session that picked a reset of its own would be named
    sources["session.py"] += "\ncommands = initialise(desired)\n"
    assert reset_choosers(sources) == ["plan.py", "session.py"]
