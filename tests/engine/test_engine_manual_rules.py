"""Rules of the manual found broken by random operator sequences and by a reference
implementation of appendix F; one test per rule, with the passage that decides it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from engine_builders import antenna, config, engine, pair, radio

from moas_gui.config import load_config, parse_config
from moas_gui.config.model import Config, Function, RadioRef, Switch, System
from moas_gui.engine import Engine
from moas_gui.engine.errors import Unavailable


def test_a_radio_joining_a_shared_system_out_of_band_gets_the_member_in_use() -> None:
    """5.10: "If a radio is using the shared antenna and another radio is switched to it,
    it will be connected but the shared antenna will not change." (step 6 here)"""
    e = engine("big-station")
    e.set_frequency(1, 1, 2000)
    e.relative(1, 1, step=1)
    assert pair(e, 1, 1) == (11, 91)
    e.set_frequency(2, 1, 1799.5)
    assert pair(e, 2, 1) == (None, 91)


def test_a_radio_joining_a_shared_system_in_band_gets_the_member_in_use() -> None:
    """5.10 in band: the 80 m 4-square is in use, so radio 2.1 at 4000 kHz can only listen
    on the beverages (one coax), which radio 1.1 has on Bev S."""
    e = engine("big-station")
    e.set_frequency(1, 1, 3600)
    e.select(1, 1, 91, target="rx")
    assert pair(e, 1, 1) == (20, 91)
    e.set_frequency(2, 1, 4000)
    assert pair(e, 2, 1) == (None, 91)
    assert e.radio_view(2, 1).inhibited


def test_tuning_beyond_the_band_edge_and_back_keeps_the_antenna() -> None:
    """Appendix F step 2: "the case where an operator has tuned beyond the band edge and
    then tunes back into the band"."""
    rel = {(1, 1): [1]}
    e = engine(config([antenna(22, (160, 80), rel), antenna(25, (160, 10), {(1, 1): [2]})],
                      [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 29700)
    assert pair(e, 1, 1) == (25, 25)
    e.set_frequency(1, 1, 2001)
    assert pair(e, 1, 1) == (25, 25)
    assert e.radio_view(1, 1).inhibited
    e.set_frequency(1, 1, 1999)
    assert pair(e, 1, 1) == (25, 25)
    assert not e.radio_view(1, 1).inhibited


def test_beyond_the_edge_and_into_another_band_is_a_band_change() -> None:
    e = engine(config([antenna(22, (160, 80), {(1, 1): [1]}),
                       antenna(25, (160, 10), {(1, 1): [2]})], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 29700)
    e.set_frequency(1, 1, 2001)
    e.set_frequency(1, 1, 3600)
    assert pair(e, 1, 1) == (22, 22)


def test_a_band_change_that_keeps_the_antenna_is_remembered() -> None:
    """Appendix F step 3: "if an operator changes from 20 to 15 and back to 20 he'll get the
    antenna he was using when he left 20"."""
    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [n], (2, 1): [n + 8]}
    e = engine(config([antenna(8, (160, 10), rel(1)), antenna(12, (160, 80, 20), rel(2))],
                      [radio(1, 1, 1), radio(2, 1, 2)]))
    e.set_frequency(2, 1, 3999)
    assert pair(e, 2, 1) == (12, 12)
    e.set_frequency(1, 1, 1801)
    assert pair(e, 1, 1) == (8, 8)
    e.set_frequency(2, 1, 1801)
    assert pair(e, 2, 1) == (12, 12)
    e.set_frequency(2, 1, 14175)
    e.set_frequency(1, 1, 1799)
    assert pair(e, 1, 1) == (8, 8)
    e.set_frequency(2, 1, 2000)
    assert pair(e, 2, 1) == (12, 12)
    assert pair(e, 1, 1) == (8, 8)


def _beverages(protect: bool = False, sub: bool = False) -> Config:
    """Two radios on 160 m: verticals 0 and 1, and two beverages on one coax (2, 3) in a
    system of shared members only, toggled by Share (function 1)."""
    refs = [(1, 1), (2, 1)] + ([(1, 3)] if sub else [])

    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {r: [n + 8 * i] for i, r in enumerate(refs)}
    every = (0, 1, 2, 3)
    return config(
        [antenna(0, (160,), rel(0), fast=every), antenna(1, (160,), rel(1), fast=every),
         antenna(2, (160,), rel(2), rx_only=True, conflicts=(2, 3), fast=every),
         antenna(3, (160,), rel(3), rx_only=True, conflicts=(2, 3), fast=every)],
        [radio(1, 1, 1, sub_receiver=3 if sub else None), radio(2, 1, 2)],
        systems=[System(id=1, shared_antennas=(2, 3), shared=True)],
        functions=[Function(id=1, name="Share", int_params=(1,))],
        protect_same_band=protect)


def test_share_turned_off_leaves_one_radio_on_a_member_the_others_move() -> None:
    """6.6.5 with 5.5: out of shared mode the members are ordinary antennas, and two radios
    may not keep one coax's beverages together."""
    e = engine(_beverages())
    e.set_frequency(1, 1, 1830)
    e.set_frequency(2, 1, 1840)
    e.select(1, 1, 2, target="rx")
    e.select(2, 1, 3, target="rx")
    assert pair(e, 1, 1) == (0, 2) and pair(e, 2, 1) == (1, 2)
    e.run_function(1, 1, 1)
    assert not e.system_shared(1)
    assert pair(e, 1, 1) == (0, 2)
    assert pair(e, 2, 1)[1] not in (2, 3)


def test_share_turned_on_brings_a_sub_receiver_to_its_main_radios_member() -> None:
    """5.10: a shared system has one member for all its users; a sub receiver is "an
    additional radio" (1.1.12)."""
    e = engine(_beverages(sub=True))
    e.run_function(1, 1, 1)
    e.set_frequency(1, 1, 1830)
    e.select(1, 1, 3, target="rx")
    e.set_frequency(1, 3, 1830)
    e.select(1, 3, 2)
    assert pair(e, 1, 1) == (0, 3) and pair(e, 1, 3) == (None, 2)
    e.run_function(1, 1, 1)
    assert e.system_shared(1)
    assert pair(e, 1, 1)[1] == pair(e, 1, 3)[1]


def test_same_band_protection_refuses_a_press_connecting_the_second_radio() -> None:
    """1.1.16: "that radio will not be connected to an antenna"."""
    e = engine(_beverages(protect=True))
    e.set_frequency(1, 1, 1830)
    e.set_frequency(2, 1, 1840)
    assert pair(e, 2, 1) == (None, None)
    before = e.switch_states()
    with pytest.raises(Unavailable, match="already on this band"):
        e.select(2, 1, 1)
    assert pair(e, 2, 1) == (None, None)
    assert e.switch_states() == before


def _apart() -> Config:
    """Radio 2.1 has Always 1.1, but 1.1 is on switch 1 only and 2.1 on switch 2 only."""
    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [n], (2, 1): [100 + n]}
    return config([antenna(0, (20,), rel(0)), antenna(1, (20,), rel(1))],
                  [radio(1, 1, 1, switch=1), radio(2, 1, 1, switch=2, always=(RadioRef(1, 1),))],
                  switches=[Switch(1, "emulator", indicate_tr=True),
                            Switch(2, "emulator", indicate_tr=True)])


def test_no_inhibit_is_claimed_between_radios_no_switch_sees_together() -> None:
    """5.11 and 2.4: a switch inhibits a radio while another on it transmits; with no common
    switch nothing applies the inhibit, so the view must not say it does."""
    e = engine(_apart())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    e.set_transmitting(1, 1, True)
    assert e.radio_view(1, 1).transmitting
    view = e.radio_view(2, 1)
    assert not view.inhibited and "transmits" not in view.note
    assert all(not any(s) for s in (st.inhibit_others for st in e.switch_states().values()))


def test_check_warns_about_an_inhibit_no_switch_can_apply(tmp_path: Path) -> None:
    text = json.dumps({
        "Switches": [{"ID": 1, "Port": "emulator"}, {"ID": 2, "Port": "emulator"}],
        "Antennas": [{"ID": 0, "Control": [{"Stations": [{"Relays": [0]}]}]}],
        "Radios": [
            {"Station": 1, "Radio": 1, "Switches": [{"Switch": 1, "Port": 1}]},
            {"Station": 2, "Radio": 1, "Switches": [{"Switch": 2, "Port": 1}],
             "Always": [{"Station": 1, "Radio": 1}]}]}, indent=1)
    path = tmp_path / "apart.moas"
    path.write_text(text)
    result = load_config(path)
    assert result.config is not None
    warnings = [p for p in result.problems if "no switch has ports of both" in p.message]
    assert len(warnings) == 1
    lines = text.splitlines()
    always = next(i for i, line in enumerate(lines) if '"Always"' in line) + 1
    assert warnings[0].line in (always, always + 1, always + 2)


def test_check_warns_when_interrupt_delays_on_one_switch_differ() -> None:
    text = json.dumps({
        "Switches": [{"ID": 1, "Port": "emulator"}],
        "Antennas": [{"ID": 0, "Control": [{"Stations": [{"Relays": [0]}]}]}],
        "Radios": [
            {"Station": 1, "Radio": 1, "Switches": [{"Port": 1}], "Interrupt": True,
             "InterruptModeDelay": 10},
            {"Station": 2, "Radio": 1, "Switches": [{"Port": 2}], "Interrupt": True,
             "InterruptModeDelay": 30}]}, indent=1)
    result = parse_config(text)
    found = [p for p in result.problems if "one interrupt delay" in p.message]
    assert len(found) == 1
    assert "30 ms is used for station 1 radio 1" in found[0].message
    assert '"InterruptModeDelay": 10' in text.splitlines()[found[0].line - 1]
    assert result.config is not None
    assert Engine(result.config).switch_states()[1].interrupt_delay == 30


def test_a_press_does_not_take_an_antenna_another_radio_holds_out_of_range() -> None:
    """1.1.1: "If an antenna is being used by another radio ... The operator will not be able
    to select that antenna unless it is configured to be shared."  Appendix F's hand-over
    speaks of frequency changes only."""
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (2, 1): [8]}),
                       antenna(1, (20, 40), {(1, 1): [1], (2, 1): [9]})],
                      [radio(1, 1, 1), radio(2, 1, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    assert pair(e, 2, 1) == (1, 1)
    e.set_frequency(1, 1, 13990)
    assert pair(e, 1, 1) == (0, 0)
    with pytest.raises(Unavailable, match="in use by station 1 radio 1"):
        e.select(2, 1, 0)
    assert pair(e, 1, 1) == (0, 0)


def test_a_radio_released_from_same_band_protection_takes_only_a_covering_antenna() -> None:
    """Appendix F, last paragraph: "If no suitable antenna is available the antenna will not be
    changed" -- the released radio does not grab the nearest antenna (step 6)."""
    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [n], (2, 1): [n + 8]}
    e = engine(config([antenna(0, (20,), rel(0)), antenna(1, (40,), rel(1))],
                      [radio(1, 1, 1), radio(2, 1, 2)], protect_same_band=True))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    assert pair(e, 2, 1) == (None, None)
    e.set_frequency(1, 1, 13000)
    assert pair(e, 1, 1) == (0, 0)
    assert pair(e, 2, 1) == (None, None)
    view = e.radio_view(2, 1)
    assert view.inhibited and "already on this band" not in view.note
    e.set_frequency(1, 1, 7050)
    assert pair(e, 1, 1) == (1, 1)
    assert pair(e, 2, 1) == (0, 0)


def test_radio_rx_antenna_is_shown_while_the_receive_antenna_is_on_the_radios_input() -> None:
    """6.4: "The information is passed to the client which, if it is a logging program which
    controls the radio, could activate or deactivate the radio's RX Antenna connector"."""
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 3550)
    e.select(1, 1, 5)
    assert not e.radio_view(1, 1).radio_rx_antenna
    changes = e.select(1, 1, 6, target="rx")
    view = e.radio_view(1, 1)
    assert (view.tx, view.rx) == (5, 6)
    assert view.radio_rx_antenna and view.to_dict()["radio_rx_antenna"] is True
    assert RadioRef(1, 1) in changes.radios
    e.select(1, 1, 5, target="rx")
    assert not e.radio_view(1, 1).radio_rx_antenna


def test_the_sub_receiver_of_the_example_gets_the_loop_on_its_own_port() -> None:
    """1.1.12: "The MOAS will select antennas for the sub receiver"; its port gets only a
    receive antenna."""
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 1830)
    e.set_frequency(1, 3, 1830)
    sub = e.radio_view(1, 3)
    assert (sub.tx, sub.rx, sub.radio_rx_antenna) == (None, 6, True)
    port = e.switch_states()[1].station(3)
    assert port.tx == 63 and port.rx_relays == frozenset({14})
    e.set_frequency(1, 3, 14100)
    sub = e.radio_view(1, 3)
    assert sub.rx == 6 and sub.radio_rx_antenna


def test_same_band_protection_uses_the_band_of_the_radio_already_there() -> None:
    """1.1.16: "if a radio switches to a frequency within the range of another radio that radio
    will not be connected to an antenna" -- even when it has no antenna of its own there."""
    e = engine(config([antenna(0, (40,), {(1, 1): [0]}),
                       antenna(1, (20,), {(1, 1): [1], (2, 1): [9]})],
                      [radio(1, 1, 1), radio(2, 1, 2)], protect_same_band=True))
    e.set_frequency(1, 1, 7000)
    assert pair(e, 1, 1) == (0, 0)
    e.set_frequency(2, 1, 7150)
    assert pair(e, 2, 1) == (None, None)
    assert "already on this band" in e.radio_view(2, 1).note
    assert pair(e, 1, 1) == (0, 0)


def _shared_tx_on_a_buss() -> Config:
    """Two radios sharing a SharedTX tribander (0), interlocked only through inhibit buss 1,
    which an Inhibit function (1) toggles for radio 2.1; receive antennas 1 and 2."""
    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [n], (2, 1): [n + 8]}
    every = (0, 1, 2)
    return config(
        [antenna(0, (20,), rel(0), shared_tx=True, fast=every),
         antenna(1, (20,), rel(1), rx_only=True, conflicts=(1, 0), fast=every),
         antenna(2, (20,), rel(2), rx_only=True, fast=every)],
        [radio(1, 1, 1, inhibit_buss=(1,)), radio(2, 1, 2, inhibit_buss=(1,))],
        functions=[Function(id=1, name="Inhibit", int_params=(2, 1, 1))])


def test_ending_the_interlock_of_radios_sharing_a_transmit_antenna_is_refused() -> None:
    """5.12: "if the radios use inhibits so that only one can transmit at a time ... then
    they can" select conflicting antennas -- only then."""
    e = engine(_shared_tx_on_a_buss())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    assert pair(e, 1, 1)[0] == 0 and pair(e, 2, 1)[0] == 0
    assert e.function_on(1)
    before = e.switch_states()
    with pytest.raises(Unavailable, match="only while each inhibits the other"):
        e.run_function(2, 1, 1)
    assert e.function_on(1) and e.switch_states() == before


def test_a_radio_transmitting_on_a_shared_antenna_moves_the_other_off_it() -> None:
    """5.12/5.13: a radio listening on an antenna another transmits on is moved to its
    alternate while that one transmits (here none: the switch connects nothing)."""
    e = engine(_shared_tx_on_a_buss())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    e.select(2, 1, 0)
    assert pair(e, 2, 1) == (0, 0)
    e.set_transmitting(1, 1, True)
    states = e.switch_states()[1]
    assert 2 in states.use_alternate[0]
    assert e.radio_view(2, 1).alt is None
    assert e.radio_view(2, 1).inhibited
