"""Multi-operator rules: inhibits, shared transmit antennas, partners, alternates (5.9-5.14)."""

from __future__ import annotations

import pytest
from engine_builders import antenna, config, engine, pair, radio, ref, so2r

from moas_gui.config.model import AlternateRule, FrequencyRange, RadioRef
from moas_gui.engine import NO_ANTENNA, Engine, Unavailable


def _shared_tx(interlocked: bool = True, partners: bool = False) -> Engine:
    """One transmit antenna "Both" (SharedTX) and two receive directions."""
    rel = {(1, 1): [0], (1, 2): [8]}
    kw1 = {"always": (RadioRef(1, 2),)} if interlocked else {}
    kw2 = {"always": (RadioRef(1, 1),)} if interlocked else {}
    if partners:
        kw1["partner"] = (RadioRef(1, 2),)
        kw2["partner"] = (RadioRef(1, 1),)
    return engine(config([
        antenna(0, (20,), rel, conflicts=(0, 1, 2), fast=(0, 1, 2), shared_tx=True,
                short="Both"),
        antenna(1, (20,), {(1, 1): [1], (1, 2): [9]}, conflicts=(0, 1), fast=(0, 1, 2),
                short="East"),
        antenna(2, (20,), {(1, 1): [2], (1, 2): [10]}, conflicts=(0, 2), fast=(0, 1, 2),
                short="West"),
    ], [radio(1, 1, 1, **kw1), radio(1, 2, 2, **kw2)]))


def test_interlocked_radios_share_a_transmit_antenna() -> None:
    e = _shared_tx()
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    e.select(1, 1, 1, target="rx")
    e.select(1, 2, 0, target="tx")
    e.select(1, 2, 2, target="rx")
    assert pair(e, 1, 1) == (0, 1)
    assert pair(e, 1, 2) == (0, 2)
    st = e.switch_states()[1]
    a = e.slot_of(1, 0, 1, 1)
    b = e.slot_of(1, 0, 1, 2)
    assert a is not None and b is not None and a != b
    assert (min(a, b), max(a, b)) not in st.conflicts       # waived for these two only
    assert (a, a) in st.conflicts and (b, b) in st.conflicts


def test_radios_that_are_not_interlocked_cannot_share_a_transmit_antenna() -> None:
    e = _shared_tx(interlocked=False)
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    with pytest.raises(Unavailable, match="in use by station 1 radio 1"):
        e.select(1, 2, 0)


def test_receiving_on_the_shared_antenna_disconnects_while_the_other_transmits() -> None:
    e = _shared_tx()
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    e.select(1, 2, 0, target="tx")
    e.select(1, 2, 2, target="rx")
    assert pair(e, 1, 1) == (0, 0)
    st = e.switch_states()[1]
    assert st.use_alternate[1] == {1}         # station 2 transmitting moves station 1
    assert st.station(1).alt == NO_ANTENNA and st.station(1).alt_relays == frozenset()
    assert st.use_alternate[0] == {2}         # West is part of Both: station 2 too


def test_partner_listens_on_the_partners_receive_antenna() -> None:
    e = _shared_tx(partners=True)
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    e.select(1, 2, 0, target="tx")
    e.select(1, 2, 2, target="rx")
    st = e.switch_states()[1]
    assert st.use_alternate[1] == {1}
    assert st.station(1).alt == e.slot_of(1, 2, 1, 1)
    assert st.station(1).alt_relays == {2}
    assert e.radio_view(1, 1).alt == 2
    west_1, west_2 = e.slot_of(1, 2, 1, 1), e.slot_of(1, 2, 1, 2)
    assert west_1 is not None and west_2 is not None
    assert (min(west_1, west_2), max(west_1, west_2)) not in st.conflicts


def test_alternate_rule_moves_the_receiver_when_the_other_transmits_nearby() -> None:
    e = engine("ms-one-amp")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    assert pair(e, 1, 1) == (0, 0) and pair(e, 1, 2) == (1, 1)
    st = e.switch_states()[1]
    assert st.use_alternate[1] == {1} and st.use_alternate[0] == {2}
    assert st.station(1).alt == e.slot_of(1, 5, 1, 1)
    assert st.station(1).alt_relays == {5}
    assert e.radio_view(1, 2).alt == 5
    e.set_frequency(1, 2, 21200)
    st = e.switch_states()[1]
    assert st.use_alternate[1] == frozenset()


def test_alt_active_limits_which_radios_switch_to_the_alternate() -> None:
    rule = AlternateRule(FrequencyRange(14000, 14350), (), (), 2)
    rel = {(1, 1): [0], (1, 2): [8], (1, 3): [16]}
    e = engine(config([
        antenna(0, (20,), rel), antenna(1, (20,), {(1, 1): [1], (1, 2): [9], (1, 3): [17]}),
        antenna(2, (20,), {(1, 1): [2], (1, 2): [10], (1, 3): [18]}, rx_only=True),
        antenna(3, (20,), {(1, 1): [3], (1, 2): [11], (1, 3): [19]}),
    ], [radio(1, 1, 1, alternate=(rule,), alt_active=(RadioRef(1, 3),)), radio(1, 2, 2),
        radio(1, 3, 3)]))
    for n, khz in ((1, 14025), (2, 14100), (3, 14200)):
        e.set_frequency(1, n, khz)
    st = e.switch_states()[1]
    assert st.use_alternate[2] == {1}         # station 3 is in AltActive
    assert st.use_alternate[1] == frozenset()  # station 2 is not


def test_inhibit_only_on_transmit_asserts_the_inhibit_while_transmitting() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0]})],
                      [radio(1, 1, 1, inhibit_only_on_transmit=True)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 1, 14500)
    assert e.radio_view(1, 1).inhibited
    assert e.switch_states()[1].inhibited == frozenset()
    e.set_transmitting(1, 1, True)
    assert e.switch_states()[1].inhibited == {1}
    e.set_transmitting(1, 1, False)
    assert e.switch_states()[1].inhibited == frozenset()


def test_radio_view_shows_inhibit_while_an_interlocked_radio_transmits() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 7025)
    changes = e.set_transmitting(1, 1, True)
    assert changes.radios == {ref(1, 1), ref(1, 2)}
    assert e.radio_view(1, 1).transmitting
    view = e.radio_view(1, 2)
    assert view.inhibited and view.note == "inhibited while station 1 radio 1 transmits"
    e.set_transmitting(1, 1, False)
    assert not e.radio_view(1, 2).inhibited


def test_transmit_event_on_an_unused_port_changes_no_radio() -> None:
    e = engine(so2r())
    changes = e.set_transmitting(1, 5, True)
    assert not changes.radios


def test_antenna_change_while_transmitting_is_left_to_the_switch() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    e.set_transmitting(1, 1, True)
    e.set_transmitting(2, 1, True)
    changes = e.select(1, 1, 47)
    # the wanted state changes now; the switch waits or interrupts (station 1 interrupts)
    assert e.switch_states()[1].station(1).tx == e.slot_of(1, 47, 1, 1)
    assert 1 in e.switch_states()[1].interrupt
    assert set(changes.switches) == {1, 2}


def test_alternate_receiver_antenna_is_used_when_an_alt_active_radio_transmits() -> None:
    rel = {(1, 1): [0], (1, 2): [8], (1, 3): [16]}
    e = engine(config([
        antenna(0, (20,), rel),
        antenna(1, (20,), {(1, 1): [1], (1, 2): [9], (1, 3): [17]}),
        antenna(2, (20,), {(1, 1): [2], (1, 2): [10], (1, 3): [18]}, rx_only=True,
                conflicts=()),
    ], [radio(1, 1, 1, alt_receiver=3, alt_active=(RadioRef(1, 2),)), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert e.radio_view(1, 3).khz == 14025.0    # the alternate receiver follows radio 1
    e.select(1, 3, 2)
    assert pair(e, 1, 3) == (None, 2)
    st = e.switch_states()[1]
    assert st.use_alternate[1] == {1}
    assert st.station(1).alt == e.slot_of(1, 2, 1, 1)
    assert st.station(1).alt_relays == {18}      # the alternate receiver's own relays
    assert e.radio_view(1, 1).alt == 2
