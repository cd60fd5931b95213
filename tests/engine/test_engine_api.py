"""The engine's public names, value shapes, and refusals that leave everything as it was."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from engine_builders import engine, so2r

import moas_gui.engine as engine_pkg
from moas_gui.engine import (
    BadRequest,
    Changes,
    Engine,
    EngineError,
    NotFound,
    RadioRef,
    Unavailable,
)
from moas_gui.engine.changes import make_changes


def test_public_names_are_frozen() -> None:
    assert sorted(engine_pkg.__all__) == [
        "AntennaView", "BadRequest", "ButtonView", "Changes", "Engine", "EngineError",
        "LayoutView", "NO_ANTENNA", "NO_CHANGES", "NotFound", "NotRunning", "RadioRef",
        "RadioView", "StationAntennas", "SwitchState", "Unavailable",
    ]


def test_a_radio_entry_lists_its_relative_antennas_at_its_frequency() -> None:
    from moas_gui.config import load_config

    path = Path(__file__).resolve().parents[2] / "examples" / "big-station.moas"
    config = load_config(path).unwrap()
    e = Engine(config)
    e.set_frequency(1, 1, 14025)
    listed = e.radio_view(1, 1).relative
    expected = next(entry.ids for group in config.relative_antennas
                    if group.station in (None, 1) and group.radio in (None, 1)
                    for entry in group.antennas if entry.range.contains(14025))
    assert listed == expected and len(listed) > 1
    assert e.radio_view(1, 1).to_dict()["relative"] == list(expected)


def test_radio_entry_has_the_protocol_fields() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    assert e.radio_view(1, 1).to_dict() == {
        "station": 1, "radio": 1, "khz": 14025.0, "tx_khz": 14025.0, "tx": 0, "rx": 0,
        "alt": None, "transmitting": False, "inhibited": False, "note": "", "relative": None,
        "radio_rx_antenna": False,
        "why": {"rule": "f4_lowest", "text": "lowest-numbered antenna covering 14025 kHz",
                "passed_over": []},
        "held_by": None, "held_since": None}
    assert e.antenna_views()[0].to_dict() == {"id": 0, "short": "Tri", "long": "Tribander",
                                              "rotator": None, "offset": 0}


def test_changes_merge_and_report_emptiness() -> None:
    a = make_changes(radios=[RadioRef(1, 1)], log=["one"])
    b = make_changes(layouts=True, log=["two"])
    merged = a.merge(b)
    assert merged.radios == {RadioRef(1, 1)} and merged.layouts and merged.log == ("one", "two")
    assert not Changes() and merged


def test_engine_starts_with_every_switch_state() -> None:
    e = Engine(so2r())
    assert set(e.switch_states()) == {1}
    assert all(v.tx is None for v in e.radios())


def _snapshot(e: Engine) -> tuple[object, ...]:
    return e.radios(), e.switch_states()


@pytest.mark.parametrize(("call", "error", "words"), [
    (lambda e: e.set_frequency(1, 1, -5), BadRequest, "positive number"),
    (lambda e: e.set_frequency(1, 1, math.nan), BadRequest, "positive number"),
    (lambda e: e.set_frequency(1, 1, "14025"), BadRequest, "positive number"),
    (lambda e: e.set_frequency(1, 1, 14025, tx_khz=0), BadRequest, "tx_khz"),
    (lambda e: e.set_frequency(7, 1, 14025), NotFound, "station 7 radio 1"),
    (lambda e: e.set_frequency(True, 1, 14025), BadRequest, "station"),
    (lambda e: e.set_transmitting(9, 1, True), NotFound, "switch 9"),
    (lambda e: e.set_transmitting(1, 7, True), BadRequest, "port"),
    (lambda e: e.select(1, 1, 12345), NotFound, "antenna 12345"),
    (lambda e: e.select(1, 2, 0), Unavailable, "in use by station 1 radio 1"),
    (lambda e: e.select(1, 1, 2), Unavailable, "does not cover"),
    (lambda e: e.select(1, 1, 0, target="sideways"), BadRequest, "target"),
    (lambda e: e.run_function(1, 1, 77), NotFound, "function 77"),
    (lambda e: e.relative(1, 1, step=1), Unavailable, "no relative antennas"),
    (lambda e: e.select_direction(1, 90), NotFound, "rotator 1"),
    (lambda e: e.layout(1, 1, 2, -1), BadRequest, "columns"),
])
def test_refusals_say_what_was_wrong_and_change_nothing(call, error, words) -> None:  # type: ignore[no-untyped-def]
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14200)
    before = _snapshot(e)
    with pytest.raises(error) as info:
        call(e)
    assert words in str(info.value)
    assert isinstance(info.value, EngineError) and info.value.code in {
        "bad_request", "not_found", "unavailable", "not_running"}
    assert _snapshot(e) == before


def test_alternate_receiver_frequency_is_refused() -> None:
    from engine_builders import antenna, config, radio
    e = engine(config([antenna(0, (20,), {(1, 1): [0], (1, 3): [1]})],
                      [radio(1, 1, 1, alt_receiver=3)]))
    with pytest.raises(BadRequest, match="follows its frequency"):
        e.set_frequency(1, 3, 14025)
    e.set_frequency(1, 1, 14025)
    assert e.radio_view(1, 3).khz == 14025.0
