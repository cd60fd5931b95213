"""Inferring whether a rotator turns from heading reports alone."""

from __future__ import annotations

from moas_gui.hw.rotators.headings import angular_distance
from moas_gui.hw.rotators.tracking import TurnTracker


def tracker() -> TurnTracker:
    return TurnTracker(tolerance=2.0, stall_after=5.0, moving_window=1.0)


def test_a_turn_moves_until_a_report_comes_within_tolerance_of_the_target() -> None:
    t = tracker()
    t.observe(0.0, now=0.0)
    t.begin(90.0, now=0.0)
    assert t.moving(0.5)
    assert t.observe(50.0, now=1.0) is None and t.moving(1.0)
    assert t.observe(88.5, now=2.0) == "arrived"
    assert not t.moving(2.0) and t.target is None


def test_coasting_after_arrival_is_not_movement_but_a_real_turn_by_hand_is() -> None:
    t = tracker()
    t.observe(0.0, now=0.0)
    t.begin(90.0, now=0.0)
    t.observe(89.0, now=1.0)
    t.observe(90.0, now=1.1)
    assert not t.moving(1.1)
    t.observe(100.0, now=5.0)
    assert t.moving(5.0) and not t.moving(6.5)


def test_a_turn_with_no_progress_for_the_stall_time_ends() -> None:
    t = tracker()
    t.observe(10.0, now=0.0)
    t.begin(200.0, now=0.0)
    t.observe(30.0, now=2.0)
    assert t.tick(6.0) is None
    assert t.tick(7.5) == "stalled"
    assert t.target is None and not t.moving(7.5)


def test_a_target_already_reached_is_no_turn() -> None:
    t = tracker()
    t.observe(45.0, now=0.0)
    t.begin(46.0, now=0.0)
    assert t.target is None


def test_compass_distance_wraps_at_north() -> None:
    t = TurnTracker(tolerance=2.0, stall_after=5.0, moving_window=1.0, distance=angular_distance)
    t.observe(350.0, now=0.0)
    t.begin(0.5, now=0.0)
    assert t.observe(359.0, now=1.0) == "arrived"
