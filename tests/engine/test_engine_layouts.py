"""Button layouts (5.16, 6.7) and electrical rotators (5.15)."""

from __future__ import annotations

import pytest
from engine_builders import engine, pair, so2r

from moas_gui.engine import BadRequest, NotFound, Unavailable


def _states(layout) -> dict[int, str]:  # type: ignore[no-untyped-def]
    return {b.id: b.state for b in layout.buttons if b.type == "Antenna"}


def test_closest_layout_for_the_station_and_radio_is_chosen() -> None:
    e = engine("multi-multi-20")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(1, 2, 14100)
    assert (e.layout(1, 1, 5, 2).rows, e.layout(1, 1, 5, 2).columns) == (5, 2)
    assert (e.layout(1, 1, 1, 40).rows, e.layout(1, 1, 1, 40).columns) == (1, 50)
    assert (e.layout(1, 2, 5, 2).rows, e.layout(1, 2, 5, 2).columns) == (4, 3)


def test_buttons_follow_the_radio_frequency() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    ids = {b.id for b in e.layout(1, 1, 4, 3).buttons if b.type == "Antenna"}
    assert {40, 41, 42, 43, 47} <= ids and 10 not in ids
    e.set_frequency(1, 1, 1830)
    ids = {b.id for b in e.layout(1, 1, 4, 3).buttons if b.type == "Antenna"}
    assert {10, 11, 12, 13, 90} <= ids and 40 not in ids
    functions = [b for b in e.layout(1, 1, 4, 3).buttons if b.type == "Function"]
    assert {b.label for b in functions} == {"Store", "Recall", "RX=TX"}


def test_button_states_show_selected_available_and_unavailable() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 44)                          # Top + Mid
    e.set_frequency(2, 1, 14200)
    assert pair(e, 2, 1) == (47, 47)
    states = _states(e.layout(1, 1, 4, 3))
    assert states[41] == states[42] == "selected"      # additive parts of Top + Mid
    assert states[43] == "available"
    assert states[47] == "unavailable"                 # station 2 has it
    other = _states(e.layout(2, 1, 4, 3))
    assert other[41] == "unavailable" and other[47] == "selected"


def test_function_buttons_show_when_they_apply() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    fn = {b.label: b.state for b in e.layout(1, 1, 4, 3).buttons if b.type == "Function"}
    assert fn == {"Store": "available", "Recall": "unavailable", "RX=TX": "unavailable"}
    e.run_function(1, 1, 0)
    e.select(1, 1, 90)
    fn = {b.label: b.state for b in e.layout(1, 1, 4, 3).buttons if b.type == "Function"}
    assert fn == {"Store": "available", "Recall": "available", "RX=TX": "available"}


def test_layout_without_a_frequency_shows_only_buttons_for_every_frequency() -> None:
    e = engine("big-station")
    layout = e.layout(1, 1, 4, 3)
    assert layout.buttons and all(b.type == "Function" for b in layout.buttons)


def test_layout_in_protocol_shape() -> None:
    e = engine("2x6")
    e.set_frequency(1, 1, 14025)
    d = e.layout(1, 1, 2, 3).to_dict()
    assert set(d) == {"station", "radio", "rows", "columns", "buttons"}
    assert d["buttons"][0] == {"row": 0, "column": 0, "type": "Antenna", "id": 1,
                               "label": d["buttons"][0]["label"], "state": "selected"}


def test_radio_with_no_layout_gets_an_empty_one_and_bad_sizes_are_refused() -> None:
    e = engine(so2r())
    assert e.layout(1, 1, 4, 3).buttons == ()
    with pytest.raises(BadRequest, match="rows"):
        e.layout(1, 1, 0, 3)
    with pytest.raises(NotFound):
        e.layout(9, 9, 4, 3)


def test_electrical_rotator_selects_the_direction_closest_to_the_heading() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    assert pair(e, 1, 1) == (10, 10)
    e.select_direction(10, 120)
    assert pair(e, 1, 1) == (11, 11)
    assert e.electrical_heading(10) == 135.0
    e.select_direction(10, 350)
    assert pair(e, 1, 1) == (13, 13)


def test_electrical_rotator_nobody_uses_is_unavailable() -> None:
    e = engine("big-station")
    with pytest.raises(Unavailable, match="No radio is using"):
        e.select_direction(11, 90)
    with pytest.raises(NotFound):
        e.select_direction(99, 90)
