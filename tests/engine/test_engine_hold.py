"""Hold (issue 32): an operator holds a radio's antennas against its frequency changes;
releasing lets the frequency choose again."""

from __future__ import annotations

import pytest
from engine_builders import EXAMPLES

from moas_gui.config import load_config
from moas_gui.engine import Engine
from moas_gui.engine.errors import BadRequest
from moas_gui.engine.operations import Hold, Select, SetFrequency, perform


def small() -> Engine:
    return Engine(load_config(EXAMPLES / "small-station.moas").unwrap())


def test_a_held_radio_keeps_its_antennas_when_its_band_changes_and_release_follows_it() -> None:
    engine = small()
    perform(engine, SetFrequency(1, 1, 14025.0), now=1.0)
    assert engine.radio_view(1, 1).tx == 0  # the tribander, by frequency
    perform(engine, Select(1, 1, 3, "both", True), now=1.5)  # the vertical, pressed
    changes = perform(engine, Hold(1, 1, "AetherSDR at 127.0.0.1"), now=2.0)
    assert engine.radio_view(1, 1).held_by == "AetherSDR at 127.0.0.1"
    assert any("held by AetherSDR" in line for line in changes.log)
    perform(engine, SetFrequency(1, 1, 21025.0), now=3.0)
    held = engine.radio_view(1, 1)
    assert held.khz == 21025.0
    assert (held.tx, held.rx) == (3, 3)
    assert held.to_dict()["held_by"] == "AetherSDR at 127.0.0.1"
    perform(engine, Hold(1, 1, None), now=4.0)
    released = engine.radio_view(1, 1)
    assert released.held_by is None
    fresh = small()
    perform(fresh, SetFrequency(1, 1, 21025.0), now=1.0)
    assert (released.tx, released.rx) == (fresh.radio_view(1, 1).tx, fresh.radio_view(1, 1).rx)
    assert released.tx != 3


def test_a_held_antenna_that_cannot_work_on_the_new_band_gives_way_to_the_rules() -> None:
    engine = small()
    perform(engine, SetFrequency(1, 1, 14025.0), now=1.0)
    perform(engine, Hold(1, 1, "x"), now=2.0)
    perform(engine, SetFrequency(1, 1, 3525.0), now=3.0)  # the tribander has no 80 m relays
    view = engine.radio_view(1, 1)
    assert view.tx in (2, 3) and view.held_by == "x"


def test_a_press_still_changes_a_held_radio_and_the_hold_stays() -> None:
    engine = small()
    perform(engine, SetFrequency(1, 1, 7025.0), now=1.0)
    perform(engine, Hold(1, 1, "Log4YM at 127.0.0.1"), now=2.0)
    before = engine.radio_view(1, 1)
    other = 3 if before.tx != 3 else 1
    perform(engine, Select(1, 1, other, "both", True), now=3.0)
    after = engine.radio_view(1, 1)
    assert after.tx == other and after.held_by == "Log4YM at 127.0.0.1"


def test_hold_of_no_radio_or_by_nobody_is_refused_and_changes_nothing() -> None:
    engine = small()
    with pytest.raises(Exception, match="no station 1 radio 9|There is no"):
        perform(engine, Hold(1, 9, "x"), now=1.0)
    with pytest.raises(BadRequest):
        perform(engine, Hold(1, 1, "  "), now=1.0)
    assert engine.radio_view(1, 1).held_by is None
    assert perform(engine, Hold(1, 1, None), now=1.0).log == ()


def test_a_hold_keeps_its_first_time_and_a_release_forgets_it() -> None:
    engine = small()
    perform(engine, Hold(1, 1, "AetherSDR at 127.0.0.1", since=1_800_000_000.0), now=1.0)
    view = engine.radio_view(1, 1)
    assert view.held_since == 1_800_000_000.0
    assert view.to_dict()["held_since"] == "2027-01-15T08:00:00Z"
    perform(engine, Hold(1, 1, "AetherSDR at 127.0.0.1", since=1_800_000_060.0), now=2.0)
    assert engine.radio_view(1, 1).held_since == 1_800_000_000.0  # the same holder: kept
    perform(engine, Hold(1, 1, "Log4YM at 127.0.0.1", since=1_800_000_120.0), now=3.0)
    assert engine.radio_view(1, 1).held_since == 1_800_000_120.0  # another holder: anew
    perform(engine, Hold(1, 1, None), now=4.0)
    released = engine.radio_view(1, 1)
    assert released.held_since is None and released.to_dict()["held_since"] is None
