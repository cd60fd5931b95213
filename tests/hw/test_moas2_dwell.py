"""The relay dwell's pure parts: what the box holds while relay changes wait (never less
strict than before or after), which stations wait, and when the waiting state lands."""

from __future__ import annotations

from dataclasses import replace

from hypothesis import given
from hypothesis import strategies as st

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.dwell import RelayDwell, interim, moves_relays, waiting_stations

IDLE = StationAntennas()


def on(slot: int, *relays: int) -> StationAntennas:
    return StationAntennas(tx=slot, tx_relays=frozenset(relays), rx=slot,
                           rx_relays=frozenset(relays))


BEFORE = SwitchState(stations=(on(1, 1), on(2, 2), IDLE, IDLE, IDLE, IDLE),
                     conflicts=frozenset({(1, 1), (2, 2)}), fast=frozenset({(1, 2), (1, 3)}),
                     inhibited=frozenset({6}))
AFTER = replace(BEFORE, stations=(on(3, 5), on(2, 2), IDLE, IDLE, IDLE, IDLE),
                conflicts=frozenset({(3, 3), (2, 3)}), fast=frozenset({(1, 3), (2, 3)}),
                inhibited=frozenset({4}))


def test_only_the_stations_whose_relays_differ_wait() -> None:
    assert waiting_stations(BEFORE, AFTER) == {1}
    assert moves_relays(BEFORE, AFTER)
    assert not moves_relays(BEFORE, replace(BEFORE, conflicts=frozenset()))


def test_a_change_of_who_moves_to_an_alternate_moves_relays_of_those_stations() -> None:
    moved = replace(BEFORE, use_alternate=(frozenset({2, 3}),) + (frozenset(),) * 5)
    assert moves_relays(BEFORE, moved)
    assert waiting_stations(BEFORE, moved) == {2, 3}


def test_the_interim_keeps_the_relays_and_tightens_the_tables() -> None:
    held = interim(BEFORE, AFTER)
    assert held.stations == BEFORE.stations
    assert held.conflicts == BEFORE.conflicts | AFTER.conflicts
    assert held.fast == {(1, 3)}
    assert held.inhibited == {1, 4, 6}


def test_the_dwell_holds_only_while_it_runs_and_lands_at_its_end() -> None:
    dwell = RelayDwell(0.1)
    assert not dwell.holds(0.0)  # no dwell runs: at once
    dwell.started(0.0)
    assert dwell.holds(0.05) and not dwell.holds(0.1)
    dwell.waiting = True
    assert dwell.deadline() == 0.1 and not dwell.due(0.09) and dwell.due(0.1)
    dwell.drop()
    assert dwell.deadline() is None and not dwell.holds(0.05)
    off = RelayDwell(0.0)
    off.started(0.0)
    assert not off.holds(0.0)


slots = st.integers(0, 63)
pairs = st.frozensets(st.tuples(slots, slots).map(lambda p: (min(p), max(p))), max_size=6)
stations = st.tuples(*[st.builds(on, slots, st.integers(0, 63)) | st.just(IDLE)] * 6)
states = st.builds(SwitchState, stations=stations, conflicts=pairs, fast=pairs,
                   inhibited=st.frozensets(st.integers(1, 6)))


@given(states, states)
def test_the_interim_is_never_less_strict_than_before_or_after(a: SwitchState,
                                                               b: SwitchState) -> None:
    held = interim(a, b)
    assert held.stations == a.stations
    assert held.conflicts >= a.conflicts | b.conflicts
    assert held.fast <= a.fast & b.fast
    assert held.inhibited >= a.inhibited | b.inhibited | waiting_stations(a, b)
