"""What each switch is asked to hold: ports, relays, tables, inhibits, modes."""

from __future__ import annotations

from engine_builders import antenna, config, engine, pair, radio, so2r

from moas_gui.config.model import RadioRef, Switch, SwitchPort
from moas_gui.engine import NO_ANTENNA, Engine


def _slot(e: Engine, switch: int, antenna_id: int, station: int, number: int) -> int:
    slot = e.slot_of(switch, antenna_id, station, number)
    assert slot is not None
    return slot


def test_each_port_holds_its_radios_antennas_and_relays() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 7050)
    st = e.switch_states()[1]
    one, two = st.station(1), st.station(2)
    assert one.tx == one.rx == _slot(e, 1, 0, 1, 1)
    assert one.tx_relays == one.rx_relays == {0}
    assert two.tx == two.rx == _slot(e, 1, 1, 1, 2)
    assert two.tx_relays == {9}
    assert st.station(3).tx == NO_ANTENNA and st.station(3).tx_relays == frozenset()


def test_relays_go_to_the_switch_that_owns_them() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 21100)              # 15 m stack top: relays 6, 28 on switch 1, 122/123
    e.select(1, 1, 51, exclusive=True)
    sw1, sw2 = e.switch_states()[1], e.switch_states()[2]
    assert sw1.station(1).tx_relays == {6, 28}
    assert sw2.station(1).tx_relays == {22, 23}
    assert sw1.station(1).tx == _slot(e, 1, 51, 1, 1)


def test_persistent_relays_stay_when_receiving_on_another_system() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 3550)
    e.select(1, 1, 21)                        # 80 m 4-square SE: relay 105 persistent
    e.select(1, 1, 92)                        # W beverage: relay 114 persistent
    sw2 = e.switch_states()[2].station(1)
    assert 5 in sw2.rx_relays                 # the 4-square's direction stays while receiving
    assert 14 in sw2.tx_relays                # the beverage relay stays while transmitting
    e.select(1, 1, 21)
    sw2 = e.switch_states()[2].station(1)
    assert sw2.rx_relays == sw2.tx_relays == {5}


def test_relays_on_a_switch_without_the_radios_port_go_to_station_zero() -> None:
    cfg = config([antenna(0, (20,), {(1, 1): [2, 105]})], [radio(1, 1, 1, switch=1)],
                 switches=[Switch(1, "emulator", indicate_tr=True),
                           Switch(2, "emulator", indicate_tr=True)])
    e = engine(cfg)
    e.set_frequency(1, 1, 14025)
    assert e.switch_states()[1].station(1).tx_relays == {2}
    assert e.switch_states()[2].station0 == {5}
    assert e.switch_states()[2].station(1).tx == NO_ANTENNA


def test_station_zero_relays_of_a_transmitting_radio_wait_for_receive() -> None:
    cfg = config([antenna(0, (20,), {(1, 1): [2, 105]}), antenna(1, (20,), {(1, 1): [3, 106]})],
                 [radio(1, 1, 1, switch=1)],
                 switches=[Switch(1, "emulator", indicate_tr=True),
                           Switch(2, "emulator", indicate_tr=True)])
    e = engine(cfg)
    e.set_frequency(1, 1, 14025)
    e.set_transmitting(1, 1, True)
    e.select(1, 1, 1)
    assert e.switch_states()[2].station0 == {5}       # unchanged while transmitting
    assert e.switch_states()[1].station(1).tx_relays == {3}
    e.set_transmitting(1, 1, False)
    assert e.switch_states()[2].station0 == {6}


def test_interrupt_mode_and_its_delay_are_loaded() -> None:
    e = engine("big-station")
    st = e.switch_states()[1]
    assert st.interrupt == {1, 2}
    assert st.interrupt_delay == 10
    assert st.inhibit_time == 30
    assert engine(so2r()).switch_states()[1].interrupt == frozenset()


def test_always_inhibits_are_loaded_for_each_transmitting_port() -> None:
    st = engine(so2r()).switch_states()[1]
    assert st.inhibit_others[0] == {2}
    assert st.inhibit_others[1] == {1}
    assert st.inhibit_others[2] == frozenset()


def test_same_band_inhibits_apply_only_on_the_same_band() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 21025)
    assert e.switch_states()[1].inhibit_others[0] == frozenset()
    e.set_frequency(2, 1, 14200)
    st = e.switch_states()[1]
    assert st.inhibit_others[0] == {2} and st.inhibit_others[1] == {1}


def test_inhibit_busses_interlock_their_radios() -> None:
    st = engine("multi-multi-20").switch_states()[1]
    assert st.inhibit_others[0] == {2} and st.inhibit_others[1] == {1}


def test_conflict_table_agrees_with_the_configuration_for_antennas_in_use() -> None:
    e = engine("tribander-stack")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    st = e.switch_states()[1]
    ix_conf = {a.id: set(a.conflicts) for a in e.config.antennas}
    used = [(1, 1, pair(e, 1, 1)[0]), (1, 2, pair(e, 1, 2)[0])]
    for s1, r1, a1 in used:
        for s2, r2, a2 in used:
            assert a1 is not None and a2 is not None
            x, y = _slot(e, 1, a1, s1, r1), _slot(e, 1, a2, s2, r2)
            expected = a2 in ix_conf[a1] or a1 in ix_conf[a2]
            assert ((min(x, y), max(x, y)) in st.conflicts) == expected
    assert all(NO_ANTENNA not in p for p in st.conflicts)


def test_fast_table_lets_receive_only_antennas_change_with_no_antenna() -> None:
    e = engine("big-station")
    st = e.switch_states()[1]
    bev = _slot(e, 1, 90, 1, 1)
    assert (bev, NO_ANTENNA) in st.fast
    four_square = _slot(e, 1, 10, 1, 1)
    assert ((four_square, bev) if four_square < bev else (bev, four_square)) in st.fast


def test_shared_system_antennas_share_a_system_number() -> None:
    e = engine("big-station")
    systems = dict(e.switch_states()[1].systems)
    numbers = {systems[_slot(e, 1, a, 1, 1)] for a in (90, 91, 92)}
    numbers |= {systems[_slot(e, 1, a, 2, 1)] for a in (90, 91, 92)}
    assert len(numbers) == 1 and 1 <= numbers.pop() <= 63
    assert _slot(e, 1, 10, 1, 1) not in systems


def test_extra_relays_follow_the_transmit_frequency() -> None:
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 14025)
    assert e.switch_states()[1].station(1).extra == {48, 42, 44, 46}
    e.set_frequency(1, 1, 7025)
    assert e.switch_states()[1].station(1).extra == {48, 42, 44, 45}


def test_extra_relays_of_a_transmitting_station_wait_for_receive() -> None:
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 14025)
    e.set_transmitting(1, 1, True)
    e.set_frequency(1, 1, 7025)
    assert e.switch_states()[1].station(1).extra == {48, 42, 44, 46}
    e.set_transmitting(1, 1, False)
    assert e.switch_states()[1].station(1).extra == {48, 42, 44, 45}


def test_set_and_reset_relays_latch_when_a_station_starts_transmitting() -> None:
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 21025)
    e.set_transmitting(1, 2, True)
    assert {40, 41} <= e.switch_states()[1].station0
    e.set_transmitting(1, 2, False)
    assert {40, 41} <= e.switch_states()[1].station0      # they stay on
    e.set_transmitting(1, 1, True)
    assert not {40, 41} & e.switch_states()[1].station0   # radio 1's Reset
    e.set_transmitting(1, 1, False)


def test_stop_turns_every_switch_inactive_and_start_restores_it() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    changes = e.stop()
    assert set(changes.switches) == {1, 2}
    assert not any(s.active for s in e.switch_states().values())
    assert e.switch_states()[1].station(1).tx_relays      # the antennas are remembered
    e.start()
    assert all(s.active for s in e.switch_states().values())


def test_reset_returns_every_switch_state_again() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    changes = e.reset()
    assert dict(changes.switches) == e.switch_states()


def test_radio_on_two_switches_uses_both_ports() -> None:
    e = engine("big-station")
    assert RadioRef(2, 1) in {RadioRef(v.station, v.radio) for v in e.radios()}
    e.set_frequency(2, 1, 28500)
    assert e.switch_states()[1].station(2).tx != NO_ANTENNA
    assert e.switch_states()[2].station(2).tx != NO_ANTENNA
    assert SwitchPort(2, 2) in e.config.radio(2, 1).switches  # type: ignore[union-attr]
