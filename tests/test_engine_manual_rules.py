"""Rules of the manual found broken by random operator sequences and by a reference
implementation of appendix F; one test per rule, with the passage that decides it."""

from __future__ import annotations

import pytest
from engine_builders import antenna, config, engine, pair, radio

from moas_gui.engine.config.model import Config, Function, System
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
