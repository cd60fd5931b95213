"""Relative antennas (appendix G)."""

from __future__ import annotations

import pytest
from engine_builders import engine, pair, so2r

from moas_gui.engine import BadRequest, NotFound, Unavailable


@pytest.fixture
def big():  # type: ignore[no-untyped-def]
    e = engine("big-station")
    e.set_frequency(1, 1, 14025)
    return e


def test_next_walks_the_list_and_wraps_around(big) -> None:  # type: ignore[no-untyped-def]
    seen = []
    for _ in range(5):
        big.relative(1, 1, step=1)
        seen.append(pair(big, 1, 1)[0])
    assert seen == [41, 46, 47, 40, 41]


def test_previous_walks_backwards(big) -> None:  # type: ignore[no-untyped-def]
    big.relative(1, 1, step=-1)
    assert pair(big, 1, 1) == (47, 47)
    big.relative(1, 1, step=-1)
    assert pair(big, 1, 1) == (46, 46)


def test_unavailable_entries_are_skipped(big) -> None:  # type: ignore[no-untyped-def]
    big.set_frequency(2, 1, 14200)
    assert pair(big, 2, 1) == (47, 47)
    big.relative(1, 1, index=2)
    big.relative(1, 1, step=1)
    assert pair(big, 1, 1) == (40, 40)


def test_index_selects_directly_with_receive_ids() -> None:
    e = engine("big-station")
    e.set_frequency(1, 1, 1830)
    e.relative(1, 1, index=1)
    assert pair(e, 1, 1) == (11, 91)
    with pytest.raises(NotFound, match="list has 4"):
        e.relative(1, 1, index=4)


def test_antenna_chosen_by_button_is_found_in_the_list(big) -> None:  # type: ignore[no-untyped-def]
    big.select(1, 1, 46)
    big.relative(1, 1, step=1)
    assert pair(big, 1, 1) == (47, 47)


def test_position_starts_over_on_another_band(big) -> None:  # type: ignore[no-untyped-def]
    big.relative(1, 1, index=3)
    big.set_frequency(1, 1, 21025)
    big.select(1, 1, 57)
    big.relative(1, 1, step=1)
    assert pair(big, 1, 1) == (50, 50)


def test_relative_needs_a_list_and_one_direction() -> None:
    e = engine(so2r())
    e.set_frequency(1, 1, 14025)
    with pytest.raises(Unavailable, match="no relative antennas"):
        e.relative(1, 1, step=1)
    big = engine("big-station")
    big.set_frequency(1, 1, 14025)
    with pytest.raises(BadRequest):
        big.relative(1, 1, step=2)
    with pytest.raises(BadRequest):
        big.relative(1, 1)
    with pytest.raises(BadRequest):
        big.relative(1, 1, step=1, index=0)
