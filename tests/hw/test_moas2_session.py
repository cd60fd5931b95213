"""The switch session as a pure state machine: bytes and times in, actions out.

No port, no loop, no clock: each test plays the box's side by hand (or through the
project's emulator model) and reads the actions.  The safety rule (:func:`guard`) is
checked on its own and on every path that loads a box.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from itertools import pairwise

import pytest

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.messages import (
    AntennaKind,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    SetAntenna,
    SetState,
    StateOp,
    UnitIdReply,
)
from moas_gui.hw.moas2.plan import ChosenPlan, Known, choose_plan
from moas_gui.hw.moas2.replies import encode_reply
from moas_gui.hw.moas2.session import (
    SURVEY_TRIES,
    Action,
    Adopt,
    End,
    LinkStatus,
    Log,
    Phase,
    SwitchSession,
    Write,
    guard,
)
from moas_gui.hw.moas2.sync import DEFAULT_EVENTS, absolute, initialise, stopped
from moas_gui.hw.moas2.timing import LinkTiming

TIMING = LinkTiming()
A = StationAntennas(tx=1, tx_relays=frozenset({1, 2}), rx=1, rx_relays=frozenset({1, 2}))
B = StationAntennas(tx=3, tx_relays=frozenset({5}), rx=3, rx_relays=frozenset({5}))
STATE_A = SwitchState(stations=(A,) + (StationAntennas(),) * 5, conflicts=frozenset({(1, 1)}))
STATE_B = replace(STATE_A, stations=(B,) + (StationAntennas(),) * 5)


def written(actions: list[Action]) -> bytes:
    return b"".join(a.data for a in actions if isinstance(a, Write))


class Played:
    """A session against the emulator model, driven by hand: what the session writes
    goes to the model, what the model answers goes back, until nothing moves."""

    def __init__(self, session: SwitchSession, model: EmulatorModel) -> None:
        self.session, self.model = session, model
        self.now = 0.0
        self.wire = bytearray()
        self.actions: list[Action] = []
        self.after_adopting: SwitchState | None = None
        """What the engine wants once it took the adopted stations (None: what the
        session was last given): handed to ``reconcile`` as a driver does."""

    def run(self, actions: list[Action]) -> None:
        pending = list(actions)
        while pending:
            action = pending.pop(0)
            self.actions.append(action)
            if isinstance(action, Write):
                self.wire += action.data
                answer = self.model.feed(action.data, self.now)
                if answer:
                    pending += self.session.feed(answer, self.now)
            elif isinstance(action, Adopt):
                desired = self.after_adopting or self.session.desired
                pending += self.session.reconcile(desired, self.now)

    def key(self, station: int, on: bool) -> None:
        self.run(self.session.feed(self.model.set_tr(station, on, self.now), self.now))


def connected(model: EmulatorModel, desired: SwitchState = STATE_A, **kw: object) -> Played:
    session = SwitchSession(1, events=DEFAULT_EVENTS, timing=TIMING, strict=True,
                            **kw)  # type: ignore[arg-type]
    played = Played(session, model)
    played.run(session.apply(desired))
    played.run(session.opened(played.now))
    return played


def loaded_box(state: SwitchState) -> EmulatorModel:
    model = EmulatorModel()
    model.feed(initialise(state).encode(), 0.0)
    return model


# ---------------------------------------------------------------------------- the rule

def test_the_guard_refuses_every_reset_the_session_asks_for_itself() -> None:
    # a reset that neither Reset Switches nor Stop Switches (an inactive target) asked
    # for, from any state the session may know or believe
    reset = initialise(STATE_A)
    for known in (Known(box_active=True), Known(box_active=False),
                  Known(box_active=True, believed=STATE_A),
                  Known(box_active=True, sent=STATE_B)):
        for keyed in (None, frozenset(), frozenset({2})):
            verdict = guard(ChosenPlan(reset, STATE_A, known), keyed, "switch 1")
            assert verdict.plan.commands == () and "not resetting it" in verdict.refused


def test_the_guard_lets_the_operator_reset_and_names_who_transmits() -> None:
    reset = initialise(STATE_A)
    pressed = ChosenPlan(reset, STATE_A, Known(box_active=True, reset_asked=True))
    assert guard(pressed, frozenset(), "switch 1").warning == ""
    verdict = guard(pressed, frozenset({2, 5}), "switch 1")
    assert verdict.plan == reset and "stations 2, 5 transmitting" in verdict.warning
    verdict = guard(pressed, None, "switch 1")
    assert "not known yet" in verdict.warning
    # Stop Switches: the target is inactive, which only the operator asks for
    stop = choose_plan(Known(box_active=True, sent=STATE_A), replace(STATE_A, active=False))
    assert b"*0;" in stop.commands.encode()
    verdict = guard(stop, frozenset({3}), "switch 1")
    assert verdict.plan == stop.commands and "station 3 transmitting" in verdict.warning


def test_the_plan_chooser_never_resets_unless_the_operator_asked() -> None:
    active = replace(STATE_A, active=True)
    for known in (Known(box_active=True), Known(box_active=False),
                  Known(box_active=True, believed=STATE_B),
                  Known(box_active=True, sent=STATE_B)):
        plan = choose_plan(known, active)
        assert b"*0;" not in plan.commands.encode(), known
        assert guard(plan, frozenset({1}), "x").refused == ""
    assert b"*0;" in choose_plan(Known(box_active=True, reset_asked=True),
                                 active).commands.encode()


def test_the_guard_holds_back_station_0_unless_the_operator_changed_it() -> None:
    wanted = replace(STATE_A, station0=frozenset({61}))
    # the session's own plans (a reconnection, a box found reset): held back while keyed
    for known in (Known(box_active=True), Known(box_active=True, believed=STATE_A),
                  Known(box_active=True, sent=replace(STATE_A, station0=frozenset({-1})))):
        plan = choose_plan(known, wanted)
        assert b"!0X" in plan.commands.encode()
        for keyed in (None, frozenset({2})):
            verdict = guard(plan, keyed, "x")
            assert verdict.held_back and b"!0X" not in verdict.plan.encode()
        assert not guard(plan, frozenset(), "x").held_back
    # the engine changed them on a box that surely held the old ones: they go out
    plan = choose_plan(Known(box_active=True, sent=STATE_A), wanted)
    assert b"!0X" in guard(plan, frozenset({2}), "x").plan.encode()


def test_a_load_as_values_holds_no_reset_and_no_plan_the_session_sends_does() -> None:
    assert b"*0;" not in absolute(STATE_A, box_active=True).encode()
    assert b"*0;" not in absolute(STATE_A, box_active=False).encode()
    played = connected(EmulatorModel())  # a box fresh from power-on
    assert played.session.phase is Phase.RUNNING
    assert b"*0;" not in played.wire and b"*1;" in played.wire
    assert played.model.view().relays == {1, 2}


# ---------------------------------------------------------------------------- nothing before

def test_nothing_that_moves_a_relay_is_written_before_the_box_said_who_transmits() -> None:
    session = SwitchSession(1, events=DEFAULT_EVENTS, timing=TIMING, held=STATE_A)
    session.apply(STATE_B)
    out = session.opened(0.0)
    out += session.feed(encode_reply(UnitIdReply("100", 0)) + encode_reply(Pong(True)), 0.1)
    assert written(out) == b":;';';\"B;\"I;|;"  # questions only
    assert session.keyed() is None  # not known: counts as transmitting


def test_a_box_that_never_answers_its_status_is_asked_again_then_left_alone() -> None:
    session = SwitchSession(1, events=DEFAULT_EVENTS, timing=TIMING, held=STATE_A)
    session.apply(STATE_B)
    out = session.opened(0.0)
    out += session.feed(encode_reply(UnitIdReply("100", 0)) + encode_reply(Pong(True)), 0.1)
    now = 0.1
    for _ in range(SURVEY_TRIES):
        now += TIMING.answer_timeout
        out += session.tick(now)
    assert out[-1] == End(False)
    assert written(out).count(b'"B;') == SURVEY_TRIES
    assert all(part in (b":", b"'", b'"B', b'"I', b"|", b"")
               for part in written(out).split(b";")), written(out)
    assert session.writer.holds == STATE_A  # still what the next session checks against


# ---------------------------------------------------------------------------- reconciling

def test_a_box_that_holds_the_saved_state_gets_only_the_difference() -> None:
    played = connected(loaded_box(STATE_A), held=STATE_A, desired=STATE_B)
    load = bytes(played.wire).split(b"|;", 1)[1]
    # every station's antenna commands again (the box cannot report the relays behind an
    # antenna), together, and nothing else: no table, no reset
    assert load.startswith(b"*r;!1B35;") and load.endswith(b"*R;';")
    assert b"%" not in load and b"*0;" not in load
    played.model.advance(1.0)  # past the slow transition's inhibit
    assert played.model.view().relays == {5}


def test_a_keyed_stations_held_change_is_consistent_and_applies_at_receive() -> None:
    model = loaded_box(STATE_A)
    model.feed(b"*1;", 0.0)
    model.set_tr(1, True, 0.0)
    model.feed(b"!1B35;", 0.1)  # sent by the server that then died: held (wait mode)
    assert model.view().relays == {1, 2}
    played = connected(model, held=STATE_B, seen=[(1, 1, 63)] + [(63, 63, 63)] * 5,
                       desired=STATE_B)
    assert [a for a in played.actions if isinstance(a, Adopt)] == []
    assert b"*0;" not in played.wire and b"%0;" not in played.wire
    assert played.model.view().relays == {1, 2}  # transmitting: untouched
    played.key(1, False)
    played.now = 1.0
    played.run(played.session.feed(played.model.advance(1.0), 1.0))
    assert played.model.view().relays == {5}


def test_a_keyed_station_showing_what_the_state_file_never_knew_is_adopted() -> None:
    model = loaded_box(STATE_B)  # the box moved on to B; the file says A (not saved)
    model.feed(b"*1;", 0.0)
    model.set_tr(1, True, 0.0)
    played = connected(model, held=STATE_A, seen=[(1, 1, 63)] + [(63, 63, 63)] * 5,
                       desired=STATE_A)
    adopted = [a for a in played.actions if isinstance(a, Adopt)]
    assert adopted == [Adopt({1: (3, 3, 63)}, frozenset({1}))]
    assert b"*0;" not in played.wire
    assert played.model.view().relays == {5}


def test_reconciliation_is_data_the_driver_carries_out_in_order() -> None:
    # the survey ends with the lines to log and one Adopt with the stations to adopt; the
    # plan is chosen for the state the driver hands over then (the engine's, once it
    # took station 1's antennas): no apply has to come back in between
    model = loaded_box(STATE_B)
    model.feed(b"*1;", 0.0)
    model.set_tr(1, True, 0.0)
    session = SwitchSession(1, events=DEFAULT_EVENTS, timing=TIMING, held=STATE_A,
                            seen=[(1, 1, 63)] + [(63, 63, 63)] * 5)
    session.apply(STATE_A)
    played = Played(session, model)
    played.after_adopting = STATE_B
    played.run(session.opened(0.0))
    kinds = [type(a).__name__ for a in played.actions if not isinstance(a, Write)]
    at = kinds.index("Adopt")
    assert kinds.count("Adopt") == 1 and "Log" in kinds[:at]
    assert not any(isinstance(a, Write) and b"*0;" in a.data for a in played.actions)
    assert session.desired == STATE_B and session.sent == STATE_B
    assert played.model.view().relays == {5}
    played.key(1, False)
    played.run(session.feed(played.model.advance(1.0), 1.0))
    assert played.model.view().relays == {5}  # nothing stale was left to land at receive
    # a survey with nothing to adopt reconciles at once, with no Adopt to carry out
    again = connected(loaded_box(STATE_A), held=STATE_A, desired=STATE_A)
    assert not any(isinstance(a, Adopt) for a in again.actions)
    assert again.session.phase is Phase.RUNNING


def test_a_box_that_lost_power_is_loaded_as_values_even_under_a_keyed_station() -> None:
    model = EmulatorModel()
    model.set_tr(2, True, 0.0)
    played = connected(model, held=STATE_A)
    assert b"*0;" not in played.wire and b"*1;" in played.wire
    assert played.session.status is LinkStatus.OK


def test_stop_switches_is_the_operators_reset_and_says_who_was_keyed() -> None:
    model = loaded_box(STATE_A)
    model.feed(b"*1;", 0.0)
    played = connected(model, held=STATE_A)
    played.key(2, True)
    played.run(played.session.apply(stopped(played.session.desired)))  # Stop Switches
    assert b"*0;" in played.wire
    # the session says it as a warning for its driver to log (no log call of its own)
    assert any(isinstance(a, Log) and a.level == logging.WARNING
               and "station 2 transmitting" in a.text for a in played.actions)


def test_station_0_relays_wait_while_a_station_transmits_on_a_reconnection() -> None:
    # the box sets station 0's relays at once, with no hot-switch rule: an automatic
    # plan keeps them back while anyone transmits, and sends them when all receive
    model = loaded_box(STATE_A)
    model.feed(b"*1;", 0.0)
    model.set_tr(2, True, 0.0)
    wanted = replace(STATE_A, station0=frozenset({61}))
    played = connected(model, held=STATE_A, desired=wanted)
    assert b"!0X" not in played.wire and played.model.view().station0 == frozenset()
    pressed = ChosenPlan(initialise(wanted), wanted, Known(box_active=True, reset_asked=True))
    assert guard(pressed, frozenset({2}), "x").held_back is False
    played.key(2, False)
    assert b"!0X" in played.wire and played.model.view().station0 == {61}


def test_ask_sends_questions_only_and_refuses_what_could_move_a_relay() -> None:
    played = connected(EmulatorModel())
    before = played.wire
    ticket, actions = played.session.ask(RelayStatusRequest(), RelayStatus, played.now)
    assert ticket > 0 and written(actions) == b"|;"
    for command in (SetState((StateOp.RESET,)), SetAntenna(1, AntennaKind.BOTH, 2, (3,))):
        with pytest.raises(TypeError, match="not a question"):
            played.session.ask(command, Pong, played.now)
    assert played.wire == before


# ---------------------------------------------------------------------------- the relay dwell

C = StationAntennas(tx=2, tx_relays=frozenset({7}), rx=2, rx_relays=frozenset({7}))
D = StationAntennas(tx=4, tx_relays=frozenset({9}), rx=4, rx_relays=frozenset({9}))
STATE_C = replace(STATE_A, stations=(C,) + (StationAntennas(),) * 5)
STATE_D = replace(STATE_A, stations=(D,) + (StationAntennas(),) * 5)
DWELL = TIMING.relay_dwell


def automatic(played: Played, state: SwitchState, at: float) -> None:
    played.now = at
    played.run(played.session.apply(state, at, automatic=True))


def tick_to(played: Played, at: float) -> None:
    played.now = at
    played.run(played.session.tick(at))


def test_a_single_automatic_change_is_not_delayed_at_all() -> None:
    played = connected(EmulatorModel())
    automatic(played, STATE_B, 1.0)
    assert played.model.view().relays == {5}
    assert not played.model.view().station(1).inhibited_by_command


def test_automatic_changes_in_a_dwell_wait_and_only_the_latest_lands_at_its_end() -> None:
    played = connected(EmulatorModel())
    automatic(played, STATE_B, 1.0)
    automatic(played, STATE_C, 1.0 + DWELL / 4)
    automatic(played, STATE_D, 1.0 + DWELL / 2)
    view = played.model.view()
    assert view.relays == {5}  # still B's: no relay moved twice within the dwell
    assert view.station(1).inhibited_by_command  # its relays wait: no transmitting meanwhile
    deadline = played.session.next_deadline()
    assert deadline is not None and deadline <= 1.0 + DWELL
    tick_to(played, 1.0 + DWELL * 0.9)
    assert played.model.view().relays == {5}
    before = len(played.wire)
    tick_to(played, 1.0 + DWELL)
    assert played.model.view().relays == {9}  # D, never C
    assert not played.model.view().station(1).inhibited_by_command
    assert b"!1B27;" not in played.wire[before:]  # C's antenna was never sent


def test_a_flood_moves_the_relays_at_most_once_per_dwell() -> None:
    played = connected(EmulatorModel())
    changes = []
    relays = played.model.view().relays
    t = 1.0
    states = [STATE_B, STATE_C, STATE_D, STATE_A]
    for i in range(200):  # 1,000 a second for 0.2 s
        t = 1.0 + i * 0.001
        for deadline in [played.session.next_deadline()]:
            if deadline is not None and deadline <= t:
                tick_to(played, deadline)
                if played.model.view().relays != relays:
                    relays = played.model.view().relays
                    changes.append(played.now)
        automatic(played, states[i % 4], t)
        if played.model.view().relays != relays:
            relays = played.model.view().relays
            changes.append(t)
    tick_to(played, t + DWELL)
    assert played.model.view().relays == {1, 2}  # the latest wanted state (A) landed
    assert len(changes) >= 2
    gaps = [b - a for a, b in pairwise(changes)]
    assert min(gaps) >= DWELL - 1e-9


def test_a_press_is_never_delayed_and_takes_what_waits_with_it() -> None:
    played = connected(EmulatorModel())
    automatic(played, STATE_B, 1.0)
    automatic(played, STATE_C, 1.01)
    assert played.model.view().relays == {5}
    played.now = 1.02
    played.run(played.session.apply(STATE_D, 1.02))  # the operator's press
    assert played.model.view().relays == {9}
    assert not played.model.view().station(1).inhibited_by_command
    before = len(played.wire)
    tick_to(played, 1.0 + DWELL)
    assert played.wire[before:].replace(b"';", b"") == b""  # nothing waited any more


def test_tables_that_tighten_go_out_while_the_relays_wait() -> None:
    played = connected(EmulatorModel())
    automatic(played, STATE_B, 1.0)
    stricter = replace(STATE_C, conflicts=STATE_C.conflicts | {(2, 3)})
    automatic(played, stricter, 1.01)
    assert b"%C" in played.wire.split(b"!1B35;")[-1]  # the conflict table went out now
    assert played.model.view().relays == {5}
    tick_to(played, 1.0 + DWELL)
    assert played.model.view().relays == {7}


def test_a_change_back_within_a_dwell_moves_no_relay_and_lifts_the_inhibit_at_its_end() -> None:
    """A flood that comes back to the band in place: the inhibit is not toggled with every
    packet; it stays until the dwell ends, and then nothing but the inhibit changes."""
    played = connected(EmulatorModel())
    automatic(played, STATE_B, 1.0)
    automatic(played, STATE_C, 1.01)
    assert played.model.view().station(1).inhibited_by_command
    before = len(played.wire)
    automatic(played, STATE_B, 1.02)
    assert played.wire[before:] == b""  # nothing to say: the inhibit stays
    assert played.model.view().station(1).inhibited_by_command
    tick_to(played, 1.0 + DWELL)
    assert played.model.view().relays == {5}
    assert not played.model.view().station(1).inhibited_by_command
    assert b"!1" not in played.wire[before:]  # no relay moved


def test_a_session_that_ends_drops_what_waits_and_the_next_plans_the_latest() -> None:
    model = EmulatorModel()
    played = connected(model)
    automatic(played, STATE_B, 1.0)
    automatic(played, STATE_C, 1.01)
    played.run(played.session.lost("pulled"))
    assert played.session.next_deadline() is None
    played.now = 2.0
    played.run(played.session.opened(2.0))
    assert played.session.phase is Phase.RUNNING
    assert model.view().relays == {7}
    assert not model.view().station(1).inhibited_by_command
