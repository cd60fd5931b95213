"""The transmit-focus rule (moas_gui/engine/focus.py): pure, no I/O."""

from __future__ import annotations

from moas_gui.engine.focus import FocusTable, StationFocus, active_first


def test_the_table_keeps_each_stations_active_and_focus_radio() -> None:
    table = FocusTable()
    assert table.set(1, "active", 2) is None
    assert table.set(1, "focus", 1) is None
    assert table.set(1, "active", 2) == 2  # no change
    assert table.get(1) == StationFocus(active=2, focus=1)
    assert table.get(9) == StationFocus()
    assert table.fields(1, 2) == {"active": True, "focus": False}
    assert table.fields(1, 1) == {"active": False, "focus": True}
    assert table.set(1, "active", 1) == 2


def test_the_active_radio_is_decided_first_and_the_rest_keep_their_order() -> None:
    table = FocusTable()
    table.set(1, "active", 2)
    table.set(2, "active", 1)
    reports = [(1, 1, "a"), (2, 2, "b"), (1, 2, "c"), (2, 1, "d"), (3, 1, "e")]
    ordered = active_first(reports, lambda r: (r[0], r[1]), table)
    assert [r[2] for r in ordered] == ["c", "d", "a", "b", "e"]


def test_without_a_focus_the_order_is_unchanged() -> None:
    reports = [(1, 2), (1, 1)]
    assert active_first(reports, lambda r: r, FocusTable()) == reports
