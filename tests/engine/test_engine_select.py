"""Button presses (5.3, 5.10, 5.16): additive and exclusive antennas, systems, targets."""

from __future__ import annotations

import pytest
from engine_builders import antenna, config, engine, pair, radio, ref, so2r

from moas_gui.config.model import System
from moas_gui.engine import BadRequest, NotFound, NotRunning, Unavailable


@pytest.fixture
def big():  # type: ignore[no-untyped-def]
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (40, 40)
    return e


def test_additive_press_takes_an_antenna_out_of_the_stack_and_back(big) -> None:  # type: ignore[no-untyped-def]
    big.select(1, 1, 41)
    assert pair(big, 1, 1) == (46, 46)      # Mid + Bot
    big.select(1, 1, 43)
    assert pair(big, 1, 1) == (42, 42)      # Mid alone
    big.select(1, 1, 41)
    assert pair(big, 1, 1) == (44, 44)      # Top + Mid
    big.select(1, 1, 43)
    assert pair(big, 1, 1) == (40, 40)      # all three


def test_exclusive_press_selects_its_combination(big) -> None:  # type: ignore[no-untyped-def]
    big.select(1, 1, 45)
    assert pair(big, 1, 1) == (45, 45)
    big.select(1, 1, 40)
    assert pair(big, 1, 1) == (40, 40)


def test_press_that_would_leave_nothing_selected_is_ignored(big) -> None:  # type: ignore[no-untyped-def]
    big.select(1, 1, 42, exclusive=True)
    assert pair(big, 1, 1) == (42, 42)
    changes = big.select(1, 1, 42)
    assert pair(big, 1, 1) == (42, 42)
    assert not changes.radios and not changes.switches
    assert "ignored" in changes.log[0]


def test_double_click_selects_an_additive_antenna_alone(big) -> None:  # type: ignore[no-untyped-def]
    big.select(1, 1, 43, exclusive=True)
    assert pair(big, 1, 1) == (43, 43)


def test_nested_systems_combine_the_europe_stack_with_other_antennas() -> None:
    e = engine("multi-multi-20")
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 1, exclusive=True)
    assert pair(e, 1, 1) == (1, 1)            # Europe 7 degrees
    e.select(1, 1, 10)
    assert pair(e, 1, 1) == (104, 104)        # + 6 el
    e.select(1, 1, 2)
    assert pair(e, 1, 1) == (111, 111)        # Europe 17 degrees + 6 el
    e.select(1, 1, 5)
    assert pair(e, 1, 1) == (146, 146)        # + 5 el above the stack
    e.select(1, 1, 2)
    assert pair(e, 1, 1) == (132, 132)        # the Europe stack taken out: 5 el + 6 el
    e.select(1, 1, 11, exclusive=True)
    assert pair(e, 1, 1) == (11, 11)


def test_pressing_the_selected_europe_angle_alone_changes_nothing() -> None:
    e = engine("multi-multi-20")
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 3, exclusive=True)
    changes = e.select(1, 1, 3)
    assert pair(e, 1, 1) == (3, 3)
    assert "ignored" in changes.log[0]


def test_a_combination_nobody_configured_is_unavailable() -> None:
    rel = {(1, 1): [0]}
    e = engine(config([antenna(0, (20,), rel), antenna(1, (20,), {(1, 1): [1]})],
                      [radio(1, 1, 1)],
                      systems=[System(1, additive_antennas=(0, 1))]))
    e.set_frequency(1, 1, 14025)
    with pytest.raises(Unavailable, match="No antenna combines"):
        e.select(1, 1, 1)
    assert pair(e, 1, 1) == (0, 0)


def test_receive_only_press_changes_only_the_receive_antenna() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.select(1, 1, 91)
    assert pair(e, 1, 1) == (10, 91)
    e.select(1, 1, 12)
    assert pair(e, 1, 1) == (12, 12)


def test_tx_and_rx_targets_set_one_antenna_each() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 7100)
    e.select(1, 1, 31, target="tx")
    e.select(1, 1, 30, target="rx")
    assert pair(e, 1, 1) == (31, 30)


def test_receive_antenna_that_is_slow_with_the_transmit_antenna_is_refused() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 7100)
    e.select(1, 1, 31)
    with pytest.raises(Unavailable, match="fast enough"):
        e.select(1, 1, 32, target="rx")
    assert pair(e, 1, 1) == (31, 31)


def test_receive_only_antenna_cannot_transmit() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    with pytest.raises(Unavailable, match="receive only"):
        e.select(1, 1, 90, target="tx")


def test_transmit_only_antenna_cannot_receive() -> None:
    e = engine(config([antenna(5, (160,), {(1, 1): [0]}, tx_only=True)], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 1830)
    with pytest.raises(Unavailable, match="transmit only"):
        e.select(1, 1, 5, target="rx")


def test_joining_a_shared_system_in_use_gets_the_member_its_users_have() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.select(1, 1, 90)
    e.set_frequency(2, 1, 3520)
    changes = e.select(2, 1, 92)
    assert pair(e, 2, 1) == (20, 90)          # asked for W, joined NE
    assert any("joined" in line for line in changes.log)
    e.select(2, 1, 91)                        # now a user: changes it for everybody
    assert pair(e, 2, 1) == (20, 91)
    assert pair(e, 1, 1) == (10, 91)


def test_antenna_in_use_by_another_radio_is_refused_with_its_user() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    before = e.switch_states()
    with pytest.raises(Unavailable) as err:
        e.select(1, 2, 0)
    assert str(err.value) == "Antenna 0 (Tri) is in use by station 1 radio 1"
    assert err.value.code == "unavailable"
    assert pair(e, 1, 2) == (3, 3)
    assert e.switch_states() == before


def test_antenna_that_does_not_cover_the_frequency_is_refused() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    with pytest.raises(Unavailable, match="does not cover 14025 kHz"):
        e.select(1, 1, 2)


def test_busy_antenna_is_reached_through_its_other_path() -> None:
    e = engine("tribander-stack")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert pair(e, 1, 1) == (0, 0)            # Top on the main feed
    assert pair(e, 1, 2) == (8, 8)            # Mid through the sub feed
    changes = e.select(1, 2, 2)               # add Bot: Mid + Bot needs the main feed
    assert pair(e, 1, 2) == (5, 5)
    assert pair(e, 1, 1) == (7, 7)            # radio 1 moved to the sub feed, still Top
    assert any("another path" in line for line in changes.log)


def test_requests_naming_nothing_real_are_refused() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    with pytest.raises(NotFound, match="There is no antenna 99"):
        e.select(1, 1, 99)
    with pytest.raises(NotFound, match="station 3 radio 1"):
        e.select(3, 1, 0)
    with pytest.raises(BadRequest, match="target"):
        e.select(1, 1, 0, target="up")


def test_presses_while_the_switches_are_stopped_are_refused() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    changes = e.stop()
    assert all(not s.active for s in changes.switches.values())
    with pytest.raises(NotRunning):
        e.select(1, 1, 3)
    e.set_frequency(1, 1, 7025)               # reports are still taken while stopped
    assert pair(e, 1, 1) == (1, 1)
    e.set_frequency(1, 1, 14025)
    e.start()
    e.select(1, 1, 3)
    assert pair(e, 1, 1) == (3, 3)
    assert e.switch_states()[1].active


def test_unchanged_press_returns_no_changes() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    assert not e.select(1, 1, 0)
    assert ref(1, 1) in e.select(1, 1, 3).radios
