"""Why a radio has its antennas: every ``why.rule`` the engine can report is reached here, by
the operation that makes that decision, with the words and passed-over antennas it gives."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from engine_builders import antenna, config, engine, pair, radio, so2r

from moas_gui.config.model import RadioRef
from moas_gui.engine import Engine
from moas_gui.engine.snapshot import export_selections, restore_selections
from moas_gui.engine.why import RULES, Why


def why(e: Engine, station: int, number: int) -> Why:
    found = e.radio_view(station, number).why
    assert found is not None
    return found


def protected() -> Engine:
    """Two radios of two stations (no relation between them) with ProtectSameBand: a
    tribander (0) and a 40 m dipole (1)."""
    both = {(1, 1): [0], (2, 1): [8]}
    return engine(config([antenna(0, (20, 15), both, long="Tribander"),
                          antenna(1, (40,), {(1, 1): [1], (2, 1): [9]}, long="40 Dipole")],
                         [radio(1, 1, 1), radio(2, 1, 2)], protect_same_band=True))


def same_band_taken() -> Why:
    e = protected()
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    assert pair(e, 2, 1) == (None, None)
    found = why(e, 2, 1)
    assert "station 1 radio 1 is already on this band" in found.text
    return found


def kept() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 1, 14300)
    return why(e, 1, 1)


def history() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 3)                              # the vertical by hand
    e.set_frequency(1, 1, 7025)
    e.set_frequency(1, 1, 14025)
    assert pair(e, 1, 1) == (3, 3)
    return why(e, 1, 1)


def lowest() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    found = why(e, 1, 2)
    assert found.passed_over[0] == (0, "is in use by station 1 radio 1")
    return found


def tx_rx_pair() -> Why:
    rel = {(1, 1): [0]}
    e = engine(config([antenna(0, (80,), rel, tx_only=True, fast=(0, 1), long="Vertical"),
                       antenna(1, (80,), {(1, 1): [1]}, rx_only=True, fast=(0, 1),
                               long="Beverage")], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 3525)
    assert pair(e, 1, 1) == (0, 1)
    found = why(e, 1, 1)
    assert "Beverage" in found.text
    return found


def nearest() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 5000)
    found = why(e, 1, 1)
    assert "no free antenna covers 5000 kHz" in found.text
    return found


def none() -> Why:
    rel = {(1, 1): [0], (1, 2): [8]}
    e = engine(config([antenna(0, (20,), rel)], [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert pair(e, 1, 2) == (None, None)
    found = why(e, 1, 2)
    assert found.passed_over == ((0, "is in use by station 1 radio 1"),)
    return found


def same_band() -> Why:
    """The radio kept off the band is let go when the other leaves, but the only antenna on
    the band went with it."""
    e = protected()
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14100)
    e.set_frequency(1, 1, 21025)                   # radio 1.1 keeps the tribander on 15 m
    assert pair(e, 1, 1) == (0, 0) and pair(e, 2, 1) == (None, None)
    return why(e, 2, 1)


def press() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 3)
    found = why(e, 1, 1)
    assert found.text == "Vertical pressed by the operator"
    return found


def restart() -> Why:
    rel = {(1, 1): [0], (1, 2): [8]}
    e = engine(config([antenna(0, (20,), rel, long="Tribander"),
                       antenna(1, (40,), {(1, 1): [1], (1, 2): [9]}, long="40 Dipole"),
                       antenna(2, (80,), {(1, 1): [2]}, long="80 Dipole")],
                      [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)                   # nearest: the 40 m dipole
    assert pair(e, 1, 2) == (1, 1)
    e.set_frequency(1, 1, 3525)                    # the tribander is free now ...
    assert pair(e, 1, 2) == (0, 0)                 # ... and the restart rule gives it
    found = why(e, 1, 2)
    assert "once another radio's change freed it" in found.text
    return found


def shared() -> Why:
    e = engine("big-station")
    e.set_frequency(1, 1, 3600)
    e.select(1, 1, 91, target="rx")
    e.set_frequency(2, 1, 4000)
    assert pair(e, 2, 1) == (None, 91)
    found = why(e, 2, 1)
    assert "the member of a shared system that station 1 radio 1 already use" in found.text
    return found


def handover() -> Why:
    rel = {(1, 1): [0], (1, 2): [8]}
    e = engine(config([antenna(0, (40,), rel, long="40 Dipole")],
                      [radio(1, 1, 1), radio(1, 2, 2)]))
    e.set_frequency(1, 1, 14025)                   # nearest: the dipole, not covering
    e.set_frequency(1, 2, 7025)                    # the dipole suits radio 2
    assert pair(e, 1, 2) == (0, 0) and pair(e, 1, 1) == (None, None)
    found = why(e, 1, 2)
    assert "handed over from station 1 radio 1" in found.text
    return found


def moved() -> Why:
    e = engine("tribander-stack")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    e.select(1, 2, 2)
    assert pair(e, 1, 1) == (7, 7)
    return why(e, 1, 1)


def relative() -> Why:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    e.relative(1, 1, step=1)
    return why(e, 1, 1)


def function() -> Why:
    e = engine("small-station")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    e.run_function(1, 2, 0)                        # Swap
    found = why(e, 1, 1)
    assert "Swap" in found.text
    return found


def direction() -> Why:
    e = engine("big-station")
    e.set_frequency(1, 1, 1825)
    rotator = next(r.id for r in e.config.rotators if r.control.name == "ELECTRICAL"
                   and any(a.rotator == r.id and e.radio_view(1, 1).tx == a.id
                           for a in e.config.antennas))
    e.select_direction(rotator, 200)
    found = why(e, 1, 1)
    assert f"rotator {rotator} turned to 200 degrees" == found.text
    return found


def switch() -> Why:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    slot = e.slot_of(1, 3, 1, 1, as_partner_alt=False)
    assert slot is not None
    e.keep_switch_antennas(1, {1: (slot, slot)})
    assert pair(e, 1, 1) == (3, 3)
    return why(e, 1, 1)


SCENARIOS: dict[str, Callable[[], Why]] = {
    "f1_same_band": same_band_taken, "f2_kept": kept, "f3_history": history,
    "f4_lowest": lowest, "f5_tx_rx_pair": tx_rx_pair, "f6_nearest": nearest, "f7_none": none,
    "same_band": same_band, "press": press, "restart": restart, "shared": shared,
    "handover": handover, "moved": moved, "relative": relative, "function": function,
    "direction": direction, "switch": switch,
}


def test_every_rule_has_a_scenario() -> None:
    assert set(SCENARIOS) == set(RULES)


@pytest.mark.parametrize("rule", RULES)
def test_the_engine_reports_the_rule_that_decided(rule: str) -> None:
    found = SCENARIOS[rule]()
    assert found.rule == rule
    assert found.text


def test_the_log_line_says_why_and_debug_lists_what_was_passed_over() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    changes = e.set_frequency(1, 2, 7025)
    # the Info line leaves out what merely does not cover the frequency; Debug lists it
    assert changes.log == (("Station 1 radio 2: 40 m beam \u2014 lowest-numbered antenna covering "
                           "7025 kHz"),)
    assert changes.details == (("Station 1 radio 2 passed over: Tribander does not cover "
                               "7025 kHz"),)


def test_the_radio_entry_carries_why_and_a_restart_keeps_it() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    entry = e.radio_view(1, 2).to_dict()
    assert entry["why"] == {"rule": "f4_lowest",
                            "text": "lowest-numbered antenna covering 14200 kHz",
                            # the entry leaves out what merely does not cover 14200 kHz
                            "passed_over": [
                                {"antenna": 0, "reason": "is in use by station 1 radio 1"}]}
    assert len(e.radio_view(1, 2).why.passed_over) == 3  # type: ignore[union-attr]
    again = Engine(e.config)
    restore_selections(again, export_selections(e))
    assert again.radio_view(1, 2).why == e.radio_view(1, 2).why


def test_a_refused_press_leaves_the_reason_as_it_was() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    before = why(e, 1, 2)
    with pytest.raises(Exception, match="in use"):
        e.select(1, 2, 0)
    assert why(e, 1, 2) == before
    assert RadioRef(1, 2) in {RadioRef(v.station, v.radio) for v in e.radios()}
