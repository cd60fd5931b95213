"""The ten functions of 5.20 / 6.6, each available only when it applies."""

from __future__ import annotations

import pytest
from engine_builders import antenna, config, engine, pair, radio, so2r

from moas_gui.config.model import Function, RadioRef
from moas_gui.engine import Engine, NotFound, Unavailable


def _with_functions(*functions: Function, **radio_kw: object) -> Engine:
    base = so2r()
    radios = [radio(1, 1, 1, always=(RadioRef(1, 2),), **radio_kw),
              radio(1, 2, 2, always=(RadioRef(1, 1),))]
    return engine(config(base.antennas, radios, functions=functions))


def test_swap_exchanges_antennas_when_each_covers_the_other_frequency() -> None:
    e = engine("small-station")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    before = pair(e, 1, 1), pair(e, 1, 2)
    assert e.function_status(1, 2, 0) == (True, "")
    e.run_function(1, 2, 0)
    assert (pair(e, 1, 2), pair(e, 1, 1)) == before


def test_swap_is_unavailable_when_an_antenna_does_not_cover_the_other_band() -> None:
    e = engine("small-station")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 3550)
    available, reason = e.function_status(1, 1, 0)
    assert not available and "does not cover" in reason
    before = e.switch_states()
    with pytest.raises(Unavailable, match="Swap is not available"):
        e.run_function(1, 1, 0)
    assert e.switch_states() == before


def test_rx_equals_tx_sets_the_receive_antenna_to_the_transmit_antenna() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.select(1, 1, 90)
    e.run_function(1, 1, 2)
    assert pair(e, 1, 1) == (10, 10)
    assert e.function_status(1, 1, 2)[0] is False


def test_store_and_recall_return_to_the_stored_antennas() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    assert not e.function_status(1, 1, 1)[0]
    e.select(1, 1, 10)
    e.select(1, 1, 91)
    e.run_function(1, 1, 0)
    e.select(1, 1, 12)
    assert pair(e, 1, 1) == (12, 12)
    e.run_function(1, 1, 1)
    assert pair(e, 1, 1) == (10, 91)


def test_recall_is_unavailable_where_the_stored_antennas_do_not_work() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.run_function(1, 1, 0)
    e.set_frequency(1, 1, 14025)
    available, reason = e.function_status(1, 1, 1)
    assert not available and "cannot be used" in reason


def test_share_builds_and_splits_the_shared_stack() -> None:
    e = engine("triplexer")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert pair(e, 1, 1) == (0, 0) and pair(e, 1, 2) == (8, 8)
    assert not e.function_on(2)
    e.run_function(1, 1, 2)
    assert e.function_on(2)
    assert pair(e, 1, 1) == (20, 20) and pair(e, 1, 2) == (20, 20)
    e.select(1, 2, 26)                        # all three, for both radios
    assert pair(e, 1, 1) == (26, 26) and pair(e, 1, 2) == (26, 26)
    with pytest.raises(Unavailable, match="while its system is shared"):
        e.select(1, 1, 3)
    e.run_function(1, 2, 2)
    assert not e.function_on(2)
    assert pair(e, 1, 1) == (3, 3)            # the preferred antennas, in order
    assert pair(e, 1, 2) == (9, 9)


def test_relay_function_toggles_a_relay() -> None:
    e = engine("ms-one-amp")
    e.run_function(1, 1, 2)
    assert 50 in e.switch_states()[1].station0 and e.function_on(2)
    e.run_function(1, 2, 2)
    assert 50 not in e.switch_states()[1].station0


def test_relay_tied_to_antennas_follows_them_with_s() -> None:
    amp = Function(6, "Relay", short_name="Amp", int_params=(31, 1, 1, 2, 3),
                   string_params=("T", "S"))
    e = _with_functions(amp)
    e.set_frequency(1, 1, 7025)
    assert pair(e, 1, 1) == (1, 1)
    assert not e.function_status(1, 1, 6)[0]
    e.select(1, 1, 3)
    e.run_function(1, 1, 6)
    assert 31 in e.switch_states()[1].station0
    changes = e.select(1, 1, 1)
    assert 31 not in e.switch_states()[1].station0
    assert any("switched off" in line for line in changes.log)
    e.select(1, 1, 3)
    assert 31 in e.switch_states()[1].station0      # "S": back on with its antenna


def test_inhibit_function_adds_a_radio_to_an_inhibit_buss() -> None:
    fn = Function(7, "Inhibit", int_params=(1, 1, 20))
    base = so2r()
    e = engine(config(base.antennas, [radio(1, 1, 1), radio(1, 2, 2, inhibit_buss=(20,))],
                      functions=[fn]))
    assert e.switch_states()[1].inhibit_others[1] == frozenset()
    e.run_function(1, 1, 7)
    assert e.function_on(7)
    st = e.switch_states()[1]
    assert st.inhibit_others[1] == {1} and st.inhibit_others[0] == {2}
    e.run_function(1, 1, 7)
    assert e.switch_states()[1].inhibit_others[1] == frozenset()


def test_extra_function_closes_a_relay_while_transmitting() -> None:
    fn = Function(8, "Extra", int_params=(1, 1, 55))
    e = _with_functions(fn)
    e.set_frequency(1, 1, 14025)
    e.run_function(1, 1, 8)
    assert 55 in e.switch_states()[1].station(1).extra
    e.run_function(1, 1, 8)
    assert 55 not in e.switch_states()[1].station(1).extra


def test_transfer_extra_needs_a_possible_swap_and_an_interlock() -> None:
    fn = Function(8, "Extra", int_params=(1, 1, 1, 2, 55), string_params=("Transfer",))
    e = _with_functions(fn)
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 3550)
    available, reason = e.function_status(1, 1, 8)
    assert not available and "does not cover" in reason
    e.set_frequency(1, 2, 14200)
    assert e.function_status(1, 1, 8) == (True, "")
    e.run_function(1, 1, 8)
    assert 55 in e.switch_states()[1].station(1).extra
    e.set_frequency(1, 2, 3550)               # no longer swappable: the relay drops
    assert 55 not in e.switch_states()[1].station(1).extra


def test_partner_function_pairs_two_radios_once() -> None:
    fns = (Function(9, "Partner", int_params=(1, 1, 1, 2)),
           Function(10, "Partner", int_params=(1, 1, 1, 3)))
    base = so2r()
    e = engine(config(base.antennas, [radio(1, 1, 1), radio(1, 2, 2), radio(1, 3, 3)],
                      functions=fns))
    e.run_function(1, 1, 9)
    assert e.function_on(9)
    available, reason = e.function_status(1, 1, 10)
    assert not available and "already has partner station 1 radio 2" in reason
    e.run_function(1, 1, 9)
    assert not e.function_on(9) and e.function_status(1, 1, 10)[0]


def test_alt_active_function_toggles_the_radios_that_switch_to_the_alternate() -> None:
    fn = Function(11, "AltActive", int_params=(1, 1, 1, 2))
    e = _with_functions(fn)
    assert not e.function_on(11)
    changes = e.run_function(1, 1, 11)
    assert e.function_on(11) and changes.layouts
    e.run_function(1, 1, 11)
    assert not e.function_on(11)


def test_unknown_function_is_not_found() -> None:
    e = engine(so2r())
    with pytest.raises(NotFound, match="There is no function 42"):
        e.run_function(1, 1, 42)
    with pytest.raises(NotFound):
        e.function_status(1, 1, 42)


def test_function_naming_a_missing_radio_says_so() -> None:
    e = _with_functions(Function(3, "AntennaSwap", int_params=(1, 1, 4, 4)))
    available, reason = e.function_status(1, 1, 3)
    assert not available and "does not exist" in reason


def test_antennas_unchanged_by_a_failed_function() -> None:
    e = engine("small-station")
    e.set_frequency(1, 1, 14025)
    views = e.radios()
    with pytest.raises(Unavailable):
        e.run_function(1, 1, 0)               # radio 2 has no antenna yet
    assert e.radios() == views
    assert antenna(0, (20,), {(1, 1): [0]}).id == 0
