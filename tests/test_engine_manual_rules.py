"""Rules of the manual found broken by random operator sequences and by a reference
implementation of appendix F; one test per rule, with the passage that decides it."""

from __future__ import annotations

from engine_builders import antenna, config, engine, pair, radio


def test_a_radio_joining_a_shared_system_out_of_band_gets_the_member_in_use() -> None:
    """5.10: "If a radio is using the shared antenna and another radio is switched to it,
    it will be connected but the shared antenna will not change." (step 6 here)"""
    e = engine("big-station")
    e.set_frequency(1, 1, 2000)
    e.relative(1, 1, step=1)
    assert pair(e, 1, 1) == (11, 91)
    e.set_frequency(2, 1, 1799.5)
    assert pair(e, 2, 1) == (None, 91)


def test_tuning_beyond_the_band_edge_and_back_keeps_the_antenna() -> None:
    """Appendix F step 2: "the case where an operator has tuned beyond the band edge and
    then tunes back into the band"."""
    rel = {(1, 1): [1]}
    e = engine(config([antenna(22, (160, 80), rel), antenna(25, (160, 10), {(1, 1): [2]})],
                      [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 29700)
    assert pair(e, 1, 1) == (25, 25)
    e.set_frequency(1, 1, 2001)
    assert pair(e, 1, 1) == (25, 25)
    assert e.radio_view(1, 1).inhibited
    e.set_frequency(1, 1, 1999)
    assert pair(e, 1, 1) == (25, 25)
    assert not e.radio_view(1, 1).inhibited


def test_beyond_the_edge_and_into_another_band_is_a_band_change() -> None:
    e = engine(config([antenna(22, (160, 80), {(1, 1): [1]}),
                       antenna(25, (160, 10), {(1, 1): [2]})], [radio(1, 1, 1)]))
    e.set_frequency(1, 1, 29700)
    e.set_frequency(1, 1, 2001)
    e.set_frequency(1, 1, 3600)
    assert pair(e, 1, 1) == (22, 22)


def test_a_band_change_that_keeps_the_antenna_is_remembered() -> None:
    """Appendix F step 3: "if an operator changes from 20 to 15 and back to 20 he'll get the
    antenna he was using when he left 20"."""
    def rel(n: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [n], (2, 1): [n + 8]}
    e = engine(config([antenna(8, (160, 10), rel(1)), antenna(12, (160, 80, 20), rel(2))],
                      [radio(1, 1, 1), radio(2, 1, 2)]))
    e.set_frequency(2, 1, 3999)
    assert pair(e, 2, 1) == (12, 12)
    e.set_frequency(1, 1, 1801)
    assert pair(e, 1, 1) == (8, 8)
    e.set_frequency(2, 1, 1801)
    assert pair(e, 2, 1) == (12, 12)
    e.set_frequency(2, 1, 14175)
    e.set_frequency(1, 1, 1799)
    assert pair(e, 1, 1) == (8, 8)
    e.set_frequency(2, 1, 2000)
    assert pair(e, 2, 1) == (12, 12)
    assert pair(e, 1, 1) == (8, 8)
