"""The emulated MOAS II's timers: slow and fast transitions, the inhibit time,
wait and interrupt modes with the interrupt delay, the receive delay, extra
relays, the three kinds of inhibit, polarity, antenna systems."""

from __future__ import annotations

import pytest
from helpers import FakeClock

from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.station import StationPhase
from moas_gui.hw.moas2.emulator.stepped import SteppedBox


def box_with(commands: str, events: str = "") -> SteppedBox:
    box = SteppedBox(active=True, events=events)
    box.send(commands)
    box.settle()
    return box


# --------------------------------------------------------------------------- slow and fast


def test_slow_transmit_change_while_receiving_inhibits_for_the_inhibit_time() -> None:
    box = box_with("[30;!1B112;")  # all pairs slow: station 1 receives on its TX relays
    box.send("!1B234;", at=100)
    assert box.relays == {3, 4}
    assert box.inhibited(1) and box.station(1).phase is StationPhase.SLOW
    box.wait(129)
    assert box.inhibited(1)
    box.wait(130)
    assert not box.inhibited(1) and box.station(1).phase is StationPhase.RECEIVE


def test_fast_transmit_change_does_not_inhibit() -> None:
    box = box_with("&F12;!1B112;")
    box.send("!1B234;", at=10)
    assert box.relays == {3, 4}
    assert not box.inhibited(1)


def test_same_antenna_with_a_slow_self_transition_is_slow() -> None:
    # A four-square with slow relays: antenna 1 is slow with itself.
    box = box_with("!1B1ab;")
    box.send("!1B1ac;", at=5)
    assert box.inhibited(1)
    assert box.relays == {36, 38}


def test_the_same_antenna_and_relays_again_changes_nothing_and_never_inhibits() -> None:
    box = box_with("/I1;!1B112;")
    box.key(1, True, at=1)
    box.send("!1B112;", at=2)
    assert not box.inhibited(1) and box.station(1).phase is StationPhase.TRANSMIT


def test_receive_antenna_changes_are_always_fast() -> None:
    box = box_with("&F12;&F13;!1T112;!1R234;")
    box.send("!1R356;", at=10)
    assert box.relays == {5, 6}
    assert not box.inhibited(1)


def test_keying_on_a_fast_pair_switches_to_transmit_without_inhibit() -> None:
    box = box_with("&F12;!1T112;!1R234;")
    assert box.relays == {3, 4}
    box.key(1, True, at=10)
    assert box.relays == {1, 2}
    assert not box.inhibited(1) and box.station(1).transmitting


def test_keying_from_an_alternate_on_a_slow_pair_inhibits() -> None:
    box = box_with("&F12;!1T112;!1R234;!1A556;!2B}9;@21;")
    box.key(2, True, at=5)
    assert box.relays == {5, 6, 9}
    box.key(1, True, at=10)
    assert box.relays == {1, 2, 9}
    assert box.inhibited(1) and box.station(1).phase is StationPhase.SLOW
    box.wait(30)
    assert not box.inhibited(1) and box.station(1).phase is StationPhase.TRANSMIT


def test_activating_with_a_station_keyed_leaves_its_relays_open_until_it_receives() -> None:
    box = SteppedBox()
    box.send("!1B112;")
    box.key(1, True, at=1)
    assert box.relays == set() and not box.inhibited(1)
    box.send("*1;", at=2)
    assert box.relays == set() and not box.inhibited(1)
    assert box.station(1).transmitting and box.station(1).pending == (("T", 1),)
    box.key(1, False, at=50)
    assert box.relays == {1, 2} and box.inhibited(1)  # all pairs slow after power-on
    box.wait(70)
    assert not box.inhibited(1)


# --------------------------------------------------------------------------- wait and interrupt


def test_wait_mode_holds_a_change_until_the_station_receives() -> None:
    box = box_with("&1;!1B112;", events="A")
    box.key(1, True, at=0)
    # The receive antenna is not in use while transmitting: it changes at once.
    assert box.send("!1B234;", at=10) == "!1f2;"
    assert box.relays == {1, 2}
    assert box.station(1).pending == (("T", 2),)
    box.wait(500)
    assert box.relays == {1, 2}
    assert box.key(1, False, at=600) == "!1F2;"
    assert box.relays == {3, 4}


def test_wait_mode_keeps_the_old_antenna_busy_for_other_stations() -> None:
    box = box_with("&1;%C11;%C22;!1B112;")
    box.key(1, True, at=0)
    box.send("!1B234;!2B156;", at=10)
    assert box.station(2).tx.antenna == 63
    box.key(1, False, at=20)
    assert box.station(1).tx.antenna == 2 and box.station(2).tx.antenna == 1
    assert box.relays == {3, 4, 5, 6}


def test_interrupt_mode_inhibits_waits_the_delay_switches_then_releases() -> None:
    box = box_with("&1;/I1;]5;[20;!1B112;", events="A")
    box.key(1, True, at=0)
    out = box.send("!1B234;", at=100)
    assert out == "!1f2;"  # the receive side changes at once; transmit waits
    assert box.inhibited(1) and box.station(1).phase is StationPhase.INTERRUPT
    assert box.relays == {1, 2}
    box.wait(104)
    assert box.relays == {1, 2} and box.inhibited(1)
    assert box.wait(105) == "!1F2;"
    assert box.relays == {3, 4} and box.inhibited(1)
    assert box.station(1).phase is StationPhase.SLOW
    box.wait(124)
    assert box.inhibited(1)
    box.wait(125)
    assert not box.inhibited(1) and box.station(1).phase is StationPhase.TRANSMIT


def test_interrupt_with_zero_delay_switches_at_once_under_inhibit() -> None:
    box = box_with("&1;/I1;!1B112;")
    box.key(1, True, at=0)
    box.send("!1B234;", at=10)
    assert box.relays == {3, 4} and box.inhibited(1)
    box.wait(30)
    assert not box.inhibited(1)


def test_interrupt_mode_reserves_the_new_antenna_and_keeps_the_old_one_busy() -> None:
    box = box_with("&1;%C11;%C22;/I1;]10;!1B112;")
    box.key(1, True, at=0)
    box.send("!1B234;", at=5)
    box.send("!2B156;!3B278;", at=6)
    assert box.station(2).tx.antenna == 63 and box.station(3).tx.antenna == 63
    box.wait(15)
    assert box.station(2).tx.antenna == 1  # antenna 1 free once station 1 switched
    assert box.station(3).tx.antenna == 63


def test_key_released_during_an_interrupt_still_finishes_it() -> None:
    box = box_with("&1;/I1;]10;!1B112;\\150;", events="T")
    box.key(1, True, at=0)
    box.send("!1B234;", at=5)
    box.key(1, False, at=7)
    box.wait(15)
    assert box.relays == {3, 4} and box.inhibited(1)
    assert box.wait(35) == ""
    assert box.station(1).phase is StationPhase.RELEASE
    assert box.wait(57) == ">12;"


# --------------------------------------------------------------------------- receive delay, extra


def test_receive_delay_keeps_the_transmit_relays_after_the_key_drops() -> None:
    box = box_with("&F12;!1T112;!1R234;\\1200;", events="T")
    assert box.key(1, True, at=0) == "<11;"
    assert box.key(1, False, at=100) == ""
    assert box.relays == {1, 2} and box.station(1).phase is StationPhase.RELEASE
    assert box.wait(299) == ""
    assert box.wait(300) == ">12;"
    assert box.relays == {3, 4}


def test_keying_again_during_the_receive_delay_stays_on_transmit() -> None:
    box = box_with("&F12;!1T112;!1R234;\\1200;", events="T")
    box.key(1, True, at=0)
    box.key(1, False, at=10)
    assert box.key(1, True, at=100) == ""
    assert box.wait(1000) == ""
    assert box.relays == {1, 2}


def test_extra_relays_close_only_while_transmitting() -> None:
    box = box_with("&1;!1B112;!1X0AB;")
    assert box.relays == {1, 2}
    box.key(1, True, at=1)
    assert box.relays == {1, 2, 10, 11}
    box.key(1, False, at=2)
    assert box.relays == {1, 2}


def test_extra_relay_change_while_transmitting_waits_in_wait_mode() -> None:
    box = box_with("&1;!1B112;!1X0A;")
    box.key(1, True, at=1)
    box.send("!1X0B;", at=2)
    assert box.relays == {1, 2, 10}
    box.key(1, False, at=3)
    box.key(1, True, at=4)
    assert box.relays == {1, 2, 11}


# --------------------------------------------------------------------------- inhibits


def test_inhibit_by_command_and_uninhibit() -> None:
    box = box_with("", events="I")
    assert box.send("(12;") == "(12;"
    assert box.inhibited(1) and box.inhibited(2)
    assert box.station(1).inhibited_by_command
    assert box.send(")1;") == ")2;"
    assert not box.inhibited(1) and box.inhibited(2)


def test_inhibit_by_command_waits_for_activation() -> None:
    box = SteppedBox()
    box.send("(1;")
    assert not box.inhibited(1)
    box.send("*1;")
    assert box.inhibited(1)


def test_a_transmitting_station_inhibits_the_stations_listed_for_it() -> None:
    box = box_with("&F12;~123;\\110;")
    box.key(1, True, at=0)
    assert box.inhibited(2) and box.inhibited(3) and not box.inhibited(4)
    assert box.station(2).inhibited_by == frozenset({1})
    box.key(1, False, at=5)
    assert box.inhibited(2)  # still on the air during the receive delay
    box.wait(15)
    assert not box.inhibited(2) and not box.inhibited(3)


def test_two_stations_interlocked_inhibit_each_other() -> None:
    box = box_with("~12;~21;")
    box.key(2, True, at=0)
    assert box.inhibited(1) and not box.inhibited(2)


def test_inhibit_polarity_sets_the_output_level() -> None:
    box = box_with("^E1;")
    assert box.send('"I;') == '"I1;'
    assert box.station(1).inhibit_line_low and not box.station(2).inhibit_line_low
    box.send("(12;")
    assert not box.station(1).inhibit_line_low and box.station(2).inhibit_line_low
    box.send("^1;^I2;")
    assert box.send('"I;') == '"I13456;'
    box.send("^0;")
    assert box.send('"I;') == '"I;'


def test_an_inactive_box_pulls_no_inhibit_line_down() -> None:
    box = SteppedBox()
    box.send("^1;(1;")
    assert not any(st.inhibit_line_low for st in box.model.view().stations)


# --------------------------------------------------------------------------- antenna systems


def test_a_system_change_waits_while_a_station_transmits_on_the_system() -> None:
    box = box_with("&1;_S1121;!1B11;!2B22;")
    box.key(1, True, at=0)
    box.send("!2B13;", at=5)  # antenna 1 does not conflict: shared system
    assert box.station(2).tx.antenna == 2
    box.key(1, False, at=10)
    assert box.station(2).tx.antenna == 1


def test_a_change_outside_any_system_is_not_held_by_a_transmitting_station() -> None:
    box = box_with("&1;_S11;!1B11;!2B22;")
    box.key(1, True, at=0)
    box.send("!2B34;", at=5)
    assert box.station(2).tx.antenna == 3


def test_timers_keep_running_across_advances_in_any_step_size() -> None:
    fine = box_with("&F12;!1T11;!1R22;\\170;")
    coarse = box_with("&F12;!1T11;!1R22;\\170;")
    for box in (fine, coarse):
        box.key(1, True, at=0)
        box.key(1, False, at=1)
    for t in range(2, 100):
        fine.wait(t)
    coarse.wait(99)
    assert fine.relays == coarse.relays == {2}


# --------------------------------------------------------------------------- the real-time box


@pytest.mark.asyncio
async def test_the_running_box_times_out_on_the_clock_it_is_given() -> None:
    """The asyncio box runs its timers by themselves: on a fake clock, the inhibit time
    of the first test here ends exactly 30 ms after the change, without waiting."""
    clock = FakeClock(1000.0)
    box = EmulatedBox(EmulatorModel(), clock=clock)
    changes: list[Traffic] = []
    box.add_listener(lambda kind, _data: changes.append(kind))
    box.receive(b"*1;[30;!1B112;")
    await clock.advance(1.0)  # every timer of the first load runs out
    box.receive(b"!1B234;")
    assert box.model.inhibited(1) and set(box.model.relays()) == {3, 4}
    await clock.advance(0.029)
    assert box.model.inhibited(1)
    changes.clear()
    await clock.advance(0.001)
    assert not box.model.inhibited(1) and box.view().station(1).phase is StationPhase.RECEIVE
    assert Traffic.CHANGED in changes, "the timer ran by itself and told its listeners"
    box.close()
