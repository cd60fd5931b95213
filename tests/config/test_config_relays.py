"""Global relay numbers: switch N owns (N-1)*100 .. (N-1)*100+63 (docs/engine.md)."""

from __future__ import annotations

from moas_gui.config.relays import (
    first_relay,
    last_relay,
    local_relay,
    local_relays,
    owns_relay,
    relay_exists,
    relay_span,
    switch_of_relay,
)


def test_each_switch_owns_its_hundred_and_the_first_sixty_four_of_it() -> None:
    assert (first_relay(1), last_relay(1)) == (0, 63)
    assert (first_relay(3), last_relay(3)) == (200, 263)
    assert relay_span(2) == "100-163"
    assert [switch_of_relay(r) for r in (0, 63, 99, 100, 263)] == [1, 1, 1, 2, 3]
    assert [local_relay(r) for r in (0, 63, 164, 263)] == [0, 63, 64, 63]
    assert [relay_exists(r) for r in (63, 64, 99, 100, 163, 164)] == \
        [True, False, False, True, True, False]
    assert owns_relay(2, 100) and owns_relay(2, 163)
    assert not owns_relay(2, 164) and not owns_relay(2, 99) and not owns_relay(1, 100)


def test_local_relays_keep_only_the_switch_s_own_and_number_them_from_zero() -> None:
    assert local_relays(frozenset({5, 105, 163, 164, 200}), 2) == frozenset({5, 63})
    assert local_relays(frozenset({5, 105}), 1) == frozenset({5})
