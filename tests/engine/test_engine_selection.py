"""Appendix F: selection by frequency, one test per rule."""

from __future__ import annotations

from engine_builders import antenna, config, engine, pair, radio, ref, so2r

from moas_gui.config.model import RadioRef
from moas_gui.engine import Engine


def test_first_report_selects_lowest_id_antenna_covering_the_frequency() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (0, 0)
    e.set_frequency(1, 2, 3550)
    assert pair(e, 1, 2) == (2, 2)


def test_antenna_in_use_is_skipped_for_the_next_lowest() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    changes = e.set_frequency(1, 2, 14200)
    assert pair(e, 1, 2) == (3, 3)
    assert changes.radios == {ref(1, 2)}
    assert changes.log == (("Station 1 radio 2: Vertical \u2014 lowest-numbered antenna covering "
                           "14200 kHz (Tribander is in use by station 1 radio 1)"),)
    why = e.radio_view(1, 2).why
    assert why is not None and why.rule == "f4_lowest"
    assert why.passed_over == ((0, "is in use by station 1 radio 1"),
                               (1, "does not cover 14200 kHz"), (2, "does not cover 14200 kHz"))


def test_band_change_returns_to_antenna_used_last_time() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 3)
    e.set_frequency(1, 1, 7025)
    assert pair(e, 1, 1) == (1, 1)
    e.set_frequency(1, 1, 14100)
    assert pair(e, 1, 1) == (3, 3)


def test_history_restores_different_transmit_and_receive_antennas() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.select(1, 1, 11)
    e.select(1, 1, 92)
    assert pair(e, 1, 1) == (11, 92)
    e.set_frequency(1, 1, 3520)
    assert pair(e, 1, 1) == (20, 20)
    e.set_frequency(1, 1, 1835)
    assert pair(e, 1, 1) == (11, 92)


def test_history_uses_the_remaining_antenna_when_one_is_taken() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 21100)
    e.select(1, 1, 1, target="tx")
    e.select(1, 1, 3, target="rx")
    assert pair(e, 1, 1) == (1, 3)
    e.set_frequency(1, 1, 3550)
    e.set_frequency(1, 2, 7100)
    assert pair(e, 1, 2) == (1, 1)
    e.set_frequency(1, 1, 21200)
    assert pair(e, 1, 1) == (3, 3)


def test_tuning_within_contiguous_ranges_keeps_the_antenna_and_changes_relays() -> None:
    low = {(1, 1): [0, 20]}
    top = antenna(0, ((1800, 1850),), low, short="160 Vert")
    # the same antenna, a second range just above with another relay (an inductor)
    top = top.__class__(**{**{f: getattr(top, f) for f in top.__dataclass_fields__},
                           "control": top.control + antenna(
                               0, ((1850.5, 2000),), {(1, 1): [0]}).control})
    other = antenna(1, ((1800, 2000),), {(1, 1): [1]})
    e = engine(config([top, other], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 1820)
    e.select(1, 1, 0)
    assert e.switch_states()[1].station(1).tx_relays == {0, 20}
    changes = e.set_frequency(1, 1, 1900)
    assert pair(e, 1, 1) == (0, 0)
    assert changes.log == ()
    assert e.switch_states()[1].station(1).tx_relays == {0}


def test_current_antenna_stays_even_when_history_knows_another() -> None:
    e = engine(config([antenna(0, (20, 15), {(1, 1): [0]}),
                       antenna(1, ((1800, 30000),), {(1, 1): [1]}, short="Wide")],
                      [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 21025)
    assert pair(e, 1, 1) == (0, 0)
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 1)
    e.set_frequency(1, 1, 21025)      # one range 1800-30000: step 2 keeps it
    assert pair(e, 1, 1) == (1, 1)


def test_separate_band_ranges_let_history_choose() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 3)
    e.set_frequency(1, 1, 21025)
    e.select(1, 1, 0)
    e.set_frequency(1, 1, 14025)      # the tribander's 20 m range is not contiguous with 15 m
    assert pair(e, 1, 1) == (3, 3)


def test_tuning_just_out_of_band_keeps_the_antenna_and_inhibits() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14000)
    e.set_frequency(1, 1, 13999)
    view = e.radio_view(1, 1)
    assert (view.tx, view.rx) == (0, 0)
    assert view.inhibited
    assert "13999" in view.note
    assert e.switch_states()[1].inhibited == {1}
    e.set_frequency(1, 1, 14001)
    assert not e.radio_view(1, 1).inhibited
    assert e.switch_states()[1].inhibited == frozenset()


def test_no_antenna_anywhere_disconnects_and_inhibits() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0]})], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 1, 7025)
    # the nearest range is 20 m: still connected there, inhibited
    assert pair(e, 1, 1) == (0, 0)
    assert e.radio_view(1, 1).inhibited
    e2 = engine(config([antenna(0, (20,), {(1, 2): [0]})], [radio(1, 1, 1)]))
    e2.set_frequency(1, 1, 7025)
    view = e2.radio_view(1, 1)
    assert (view.tx, view.rx, view.inhibited) == (None, None, True)
    assert e2.switch_states()[1].station(1).tx == 63


def test_no_select_antenna_is_never_chosen_by_frequency_but_can_be_pressed() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0]}, no_select=True),
                       antenna(1, (20,), {(1, 1): [1]})], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (1, 1)
    e.select(1, 1, 0)
    assert pair(e, 1, 1) == (0, 0)


def test_transmit_only_antenna_is_paired_with_a_fast_receive_only_antenna() -> None:
    rel = {(1, 1): [0]}
    e = engine(config([
        antenna(5, (160,), rel, tx_only=True, fast=(7,)),
        antenna(6, (160,), {(1, 1): [1]}, rx_only=True),
        antenna(7, (160,), {(1, 1): [2]}, rx_only=True),
    ], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 1830)
    # 6 is the lower receive antenna but the change 5 <-> 6 is slow
    assert pair(e, 1, 1) == (5, 7)


def test_protect_same_band_leaves_the_second_radio_without_antenna() -> None:
    cfg = so2r(protect_same_band=True)
    cfg = config(cfg.antennas, [radio(1, 1, 1), radio(1, 2, 2)], protect_same_band=True)
    e = engine(cfg)
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    view = e.radio_view(1, 2)
    assert (view.tx, view.rx, view.inhibited) == (None, None, True)
    assert "station 1 radio 1" in view.note
    e.set_frequency(1, 1, 7025)
    assert pair(e, 1, 2) == (0, 0)
    assert not e.radio_view(1, 2).inhibited


def test_protect_same_band_allows_radios_that_inhibit_each_other() -> None:
    e = engine(so2r(protect_same_band=True))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    assert pair(e, 1, 2) == (3, 3)


def test_antenna_is_taken_over_by_a_radio_it_suits_better() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (1, 2): [8]}),
                       antenna(1, (40,), {(1, 1): [1], (1, 2): [9]})],
                      [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 1, 14400)          # out of band: keeps the tribander, inhibited
    assert pair(e, 1, 1) == (0, 0)
    e.set_frequency(1, 2, 14100)          # the 20 m antenna suits radio 2
    assert pair(e, 1, 2) == (0, 0)
    assert pair(e, 1, 1) == (1, 1)        # radio 1 was selected again: nearest is 40 m
    assert e.radio_view(1, 1).inhibited


def test_radio_without_antenna_gets_one_when_another_radio_frees_it() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (1, 2): [8]}),
                       antenna(1, (40,), {(1, 1): [1], (1, 2): [9]})],
                      [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert pair(e, 1, 2) == (1, 1)
    assert e.radio_view(1, 2).inhibited
    changes = e.set_frequency(1, 1, 7000)
    assert pair(e, 1, 1) == (1, 1)
    assert pair(e, 1, 2) == (0, 0)
    assert ref(1, 2) in changes.radios
    assert not e.radio_view(1, 2).inhibited


def test_an_antenna_kept_out_of_range_goes_to_the_next_radio_reporting_a_frequency() -> None:
    """Appendix F: "if another radio changes frequency and the antenna is the best choice for
    it the antenna will be selected by the other radio"; the restart rule alone does not take
    an antenna in use (1.1.1)."""
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (1, 2): [8]})],
                      [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    e.set_frequency(1, 1, 7000)
    assert pair(e, 1, 1) == (0, 0)
    assert pair(e, 1, 2) == (None, None)
    e.set_frequency(1, 2, 14100)
    assert pair(e, 1, 2) == (0, 0)
    assert pair(e, 1, 1) == (None, None)
    assert e.radio_view(1, 1).inhibited


def test_split_transmit_frequency_outside_the_antenna_inhibits() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14345, tx_khz=14355)
    view = e.radio_view(1, 1)
    assert (view.tx, view.khz, view.tx_khz) == (0, 14345.0, 14355.0)
    assert view.inhibited and "14355" in view.note


def test_out_of_band_inhibits_a_radio_whose_frequency_is_unknown() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (1, 2): [1]})],
                      [radio(1, 1, 1, out_of_band=True), radio(1, 2, 2)]))
    assert e.radio_view(1, 1).inhibited
    assert not e.radio_view(1, 2).inhibited
    assert e.switch_states()[1].inhibited == {1}


def test_antenna_with_inhibit_flag_inhibits_transmit() -> None:
    e = engine(config([antenna(0, (20,), {(1, 1): [0]}, inhibit=True)], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (0, 0)
    assert e.radio_view(1, 1).inhibited


def _sub_station(own_port: bool, persist: bool = False, use_main: bool = True) -> Engine:
    rel = {(1, 1): [0], (1, 3): [10]}
    radios = [radio(1, 1, 1, sub_receiver=3, use_main_freq=use_main,
                    persist_sub_receiver=persist)]
    if own_port:
        radios.append(radio(1, 3, 3))
    return engine(config([
        antenna(0, (20,), rel, conflicts=(0,), fast=(0, 1)),
        antenna(1, (20,), {(1, 1): [1], (1, 3): [11]}, fast=(0, 1)),
        antenna(2, (20,), {(1, 3): [12]}, rx_only=True),
    ], radios))


def test_sub_receiver_follows_the_main_frequency_and_gets_its_own_antenna() -> None:
    e = _sub_station(own_port=True)
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (0, 0)
    assert e.radio_view(1, 3).khz == 14025.0
    assert e.radio_view(1, 3).tx is None
    assert e.radio_view(1, 3).rx is not None
    st = e.switch_states()[1]
    assert st.station(3).tx == 63          # not persistent: nothing while transmitting
    assert st.station(3).rx_relays == {10} or st.station(3).rx_relays == {11}


def test_sub_receiver_without_its_own_port_rides_on_the_main_receive_relays() -> None:
    e = _sub_station(own_port=False, persist=True)
    e.set_frequency(1, 1, 14025)
    e.select(1, 3, 2)
    st = e.switch_states()[1].station(1)
    assert 12 in st.rx_relays and 12 in st.tx_relays
    e2 = _sub_station(own_port=False, persist=False)
    e2.set_frequency(1, 1, 14025)
    e2.select(1, 3, 2)
    st2 = e2.switch_states()[1].station(1)
    assert 12 in st2.rx_relays and 12 not in st2.tx_relays


def test_sub_receiver_history_is_separate_from_the_main_radio() -> None:
    e = _sub_station(own_port=False, use_main=True)
    e.set_frequency(1, 1, 14025)
    e.select(1, 3, 2)
    e.select(1, 1, 1)
    e.set_frequency(1, 1, 14400)
    e.set_frequency(1, 1, 14100)
    assert e.radio_view(1, 3).rx == 2
    assert pair(e, 1, 1) == (1, 1)


def test_radio_refs_are_stable_objects() -> None:
    e = engine(so2r())
    assert {(v.station, v.radio) for v in e.radios()} == {(1, 1), (1, 2)}
    assert RadioRef(1, 1) == ref(1, 1)
