"""Operators' evenings on the example stations, from first report to last QSO."""

from __future__ import annotations

import pytest
from engine_builders import engine, pair, table_problems

from moas_gui.engine import Unavailable


def test_so2r_evening_on_the_small_station() -> None:
    e = engine("small-station")
    e.set_frequency(1, 1, 14025)                 # run on 20 with the tribander
    e.set_frequency(1, 2, 14250)                 # search and pounce on 20: the vertical
    run_ant, sp_ant = pair(e, 1, 1)[0], pair(e, 1, 2)[0]
    assert run_ant != sp_ant
    e.set_transmitting(1, 1, True, now=1)        # CQ
    assert e.radio_view(1, 2).inhibited          # SO2R interlock
    e.set_transmitting(1, 1, False, now=2)
    e.run_function(1, 2, 0)                      # a weak multiplier: swap the beam over
    assert pair(e, 1, 2)[0] == run_ant and pair(e, 1, 1)[0] == sp_ant
    e.run_function(1, 2, 0)                      # and back
    assert pair(e, 1, 1)[0] == run_ant
    e.set_frequency(1, 2, 7050)                  # radio 2 looks at 40
    assert e.radio_view(1, 2).tx is not None and not e.radio_view(1, 2).inhibited
    assert not e.function_status(1, 1, 0)[0]     # the tribander does not cover 40
    e.set_frequency(1, 2, 14250)                 # back to 20: what it had there
    assert pair(e, 1, 2)[0] == sp_ant
    assert table_problems(e) == []


def test_low_band_evening_on_the_big_station() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.set_frequency(2, 1, 3520)
    e.select_direction(10, 40)                   # 160: NE, to Europe
    e.select(1, 1, 90)                           # listen on the NE beverage
    assert pair(e, 1, 1) == (10, 90)
    e.run_function(1, 1, 0)                      # store the Europe pair
    e.select(1, 1, 12)                           # a Caribbean multiplier: SW
    assert pair(e, 1, 1) == (12, 12)
    e.run_function(1, 1, 1)                      # recall Europe
    assert pair(e, 1, 1) == (10, 90)
    e.select(2, 1, 91)                           # 80 m wants a beverage too: joins NE
    assert pair(e, 2, 1) == (20, 90)
    e.set_transmitting(1, 2, True, now=5)        # station 2 keys up on switch 1 port 2
    e.set_transmitting(2, 2, True, now=5)
    assert e.radio_view(2, 1).transmitting
    e.select(2, 1, 21)                           # changes direction while transmitting
    assert e.switch_states()[1].station(2).tx == e.slot_of(1, 21, 2, 1)
    e.set_transmitting(1, 2, False, now=6)
    e.set_transmitting(2, 2, False, now=6)
    e.set_frequency(1, 1, 14025)                 # station 1 goes to 20: stack
    assert pair(e, 1, 1) == (40, 40)
    e.set_frequency(1, 1, 1835)                  # and back to 160: Europe pair again
    assert pair(e, 1, 1) == (10, 90)
    assert table_problems(e) == []


def test_triplexer_evening_sharing_the_stack() -> None:
    e = engine("triplexer")
    e.set_frequency(1, 1, 21025)
    e.set_frequency(1, 2, 14025)
    assert table_problems(e) == []
    e.run_function(1, 1, 2)                      # share the stack through the triplexer
    one, two = pair(e, 1, 1), pair(e, 1, 2)
    assert one == two and one[0] in range(20, 27)
    e.select(1, 1, 24)                           # top + bottom for both
    assert pair(e, 1, 1) == pair(e, 1, 2) == (24, 24)
    e.set_frequency(1, 2, 28500)                 # 10 m: appendix F picks the lowest free ID
    assert pair(e, 1, 2) == (10, 10)
    e.select(1, 2, 20)                           # back on the shared stack: joins top + bottom
    assert pair(e, 1, 2) == (24, 24)
    e.run_function(1, 2, 2)                      # split it again
    assert pair(e, 1, 1)[0] != pair(e, 1, 2)[0]
    assert table_problems(e) == []


def test_two_operators_on_twenty_at_the_multi_multi_station() -> None:
    e = engine("multi-multi-20")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14250)
    assert pair(e, 1, 1)[0] is not None and pair(e, 1, 2)[0] is not None
    e.select(1, 2, 31)                           # 4-square SE for station 2
    assert pair(e, 1, 2) == (31, 31)
    e.select(1, 1, 2, exclusive=True)            # Europe 17 degrees
    e.select(1, 1, 10)                           # + the 6 el
    assert pair(e, 1, 1) == (111, 111)
    with pytest.raises(Unavailable):
        e.select(1, 2, 20)                       # the 6 el is busy on station 1
    e.relative(1, 1, step=1)
    assert pair(e, 1, 1)[0] in (2, 1, 7, 10, 11, 12)
    assert table_problems(e) == []


def test_one_amplifier_evening_moves_the_listener_to_the_vertical() -> None:
    e = engine("ms-one-amp")
    e.run_function(1, 1, 2)                      # amplifier mains on
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    st = e.switch_states()[1]
    assert 50 in st.station0
    assert st.use_alternate[0] == {2}            # radio 1 transmitting: radio 2 on the vertical
    e.set_transmitting(1, 1, True, now=1)
    assert e.radio_view(1, 2).inhibited
    assert not {40, 41} & e.switch_states()[1].station0
    e.set_transmitting(1, 1, False, now=2)
    e.set_transmitting(1, 2, True, now=3)        # radio 2 takes the amplifier
    assert {40, 41} <= e.switch_states()[1].station0
    e.set_transmitting(1, 2, False, now=4)
    assert table_problems(e) == []
