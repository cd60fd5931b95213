"""The heading rules: antenna offsets, positions, paths, clamping, unwrapped scales."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.hw.rotators.headings import (
    Travel,
    Turn,
    angular_distance,
    antenna_heading,
    azimuth_of,
    closest_direction,
    normalize,
    plan_turn,
    position_of,
    rotator_heading_for,
    whole_heading,
    window_base,
)

bearings = st.floats(min_value=-1000, max_value=1000, allow_nan=False)
headings = st.floats(min_value=0, max_value=359.999, allow_nan=False)
offsets = st.integers(min_value=-360, max_value=360)
travels = st.builds(
    Travel,
    ccw_limit=st.integers(min_value=0, max_value=359).map(float),
    rotation=st.sampled_from([90.0, 180.0, 300.0, 359.0, 360.0, 400.0, 450.0, 540.0, 720.0]),
    has_stop=st.booleans(),
)


def close(a: float, b: float, tolerance: float = 1e-6) -> bool:
    return angular_distance(a, b) <= tolerance


# ---- plain compass arithmetic -------------------------------------------------------

@given(bearings)
def test_normalize_folds_any_bearing_into_one_turn(bearing: float) -> None:
    result = normalize(bearing)
    assert 0 <= result < 360
    assert math.isclose(math.cos(math.radians(result)), math.cos(math.radians(bearing)),
                        abs_tol=1e-6)


def test_whole_heading_rounds_just_below_north_to_north() -> None:
    assert whole_heading(359.6) == 0
    assert whole_heading(-0.4) == 0
    assert whole_heading(44.5) in (44, 45)
    assert whole_heading(725) == 5


@given(headings, offsets)
def test_antenna_offset_round_trips(rotator: float, offset: int) -> None:
    pointing = antenna_heading(rotator, offset)
    assert close(rotator_heading_for(pointing, offset), rotator)


def test_antenna_at_right_angles_points_ninety_degrees_clockwise_of_the_rotator() -> None:
    assert antenna_heading(300, 90) == 30
    assert rotator_heading_for(30, 90) == 300


# ---- positions ----------------------------------------------------------------------

@given(travels, headings)
def test_every_position_of_a_heading_points_at_it_and_lies_in_the_travel(
    travel: Travel, heading: float
) -> None:
    for position in travel.positions_of(heading):
        assert close(travel.heading_at(position), heading)
        if travel.bounded:
            assert 0 <= position <= travel.rotation


def test_overlap_gives_two_positions_for_headings_in_the_overlap() -> None:
    travel = Travel(ccw_limit=180, rotation=450, has_stop=True)
    assert travel.positions_of(200) == (20.0, 380.0)
    assert travel.positions_of(300) == (120.0,)
    assert travel.heading_at(450) == 270


def test_side_mount_cannot_point_outside_its_travel() -> None:
    travel = Travel(ccw_limit=0, rotation=300)
    assert travel.bounded
    assert travel.positions_of(330) == ()
    assert not travel.reaches(330)
    assert travel.reaches(300)


def test_full_turn_without_stop_is_unbounded_and_with_stop_is_bounded() -> None:
    assert not Travel(0, 360, has_stop=False).bounded
    assert Travel(180, 360, has_stop=True).bounded
    assert Travel(180, 450, has_stop=False).bounded


@pytest.mark.parametrize("rotation", [0, -10, 721])
def test_a_travel_of_no_degrees_or_over_two_turns_is_refused_with_a_sentence(
    rotation: float,
) -> None:
    with pytest.raises(ValueError, match="Rotation must be"):
        Travel(0, rotation)


# ---- paths --------------------------------------------------------------------------

def test_tribander_with_south_stop_goes_the_long_way_round_rather_than_through_the_stop() -> None:
    travel = Travel(ccw_limit=180, rotation=360, has_stop=True)
    start = travel.nearest_position(170)  # 10 degrees counterclockwise of the stop
    turn = plan_turn(travel, start, 190)
    assert turn.start == pytest.approx(350)
    assert turn.end == pytest.approx(10)
    assert turn.direction == -1
    assert turn.degrees == pytest.approx(340)


def test_without_a_stop_the_same_turn_goes_the_short_way() -> None:
    travel = Travel(ccw_limit=180, rotation=360, has_stop=False)
    turn = plan_turn(travel, travel.nearest_position(170), 190)
    assert turn.degrees == pytest.approx(20)
    assert turn.direction == 1


def test_a_half_turn_without_a_stop_goes_clockwise() -> None:
    turn = plan_turn(Travel(0, 360), 0, 180)
    assert turn.direction == 1 and turn.degrees == pytest.approx(180)


def test_overlap_rotator_uses_the_overlap_when_it_is_shorter() -> None:
    travel = Travel(ccw_limit=180, rotation=450, has_stop=True)
    # at position 400 (heading 220, in the overlap), going to 200 stays in the overlap
    turn = plan_turn(travel, 400, 200)
    assert turn.end == pytest.approx(380)
    # from position 10 (heading 190) to 200 goes forward 10 degrees, not to 380
    assert plan_turn(travel, 10, 200).end == pytest.approx(20)


def test_heading_outside_travel_is_clamped_to_the_nearer_end() -> None:
    travel = Travel(ccw_limit=0, rotation=300)
    turn = plan_turn(travel, 100, 320)  # 20 from the CW end (300), 40 from north
    assert turn.clamped
    assert turn.end == 300
    turn = plan_turn(travel, 100, 345)  # 45 from 300, 15 from 0
    assert turn.end == 0


def test_clamping_tie_goes_to_the_end_nearer_the_rotator() -> None:
    travel = Travel(ccw_limit=0, rotation=300)
    assert plan_turn(travel, 250, 330).end == 300
    assert plan_turn(travel, 50, 330).end == 0


@given(travels, st.floats(min_value=0, max_value=720), headings)
def test_bounded_turns_stay_inside_the_travel_and_arrive_when_they_can(
    travel: Travel, current: float, heading: float
) -> None:
    turn = plan_turn(travel, current, heading)
    if travel.bounded:
        assert 0 <= turn.start <= travel.rotation
        assert 0 <= turn.end <= travel.rotation
        if travel.reaches(heading):
            assert not turn.clamped
            assert close(travel.heading_at(turn.end), heading)
            # no reachable position for the heading is nearer than the chosen one
            assert all(abs(p - turn.start) >= turn.degrees - 1e-9
                       for p in travel.positions_of(heading))
        else:
            assert turn.clamped and turn.end in (0.0, travel.rotation)
    else:
        assert turn.degrees <= 180 + 1e-9
        assert close(travel.heading_at(turn.end), heading)


@given(travels, st.floats(min_value=0, max_value=720), headings)
def test_a_turn_with_a_stop_never_passes_the_stop(
    travel: Travel, current: float, heading: float
) -> None:
    if not travel.has_stop:
        return
    turn = plan_turn(travel, current, heading)
    low, high = sorted((turn.start, turn.end))
    # the stop is at positions 0 and rotation: strictly inside the path is forbidden
    assert low >= 0 and high <= travel.rotation


@given(st.floats(min_value=0, max_value=450), st.floats(min_value=0, max_value=500))
def test_position_after_never_overshoots(start: float, turned: float) -> None:
    turn = Turn(start, 225.0)
    position = turn.position_after(turned)
    assert min(start, 225.0) - 1e-9 <= position <= max(start, 225.0) + 1e-9


# ---- electrical directions --------------------------------------------------------------

def test_closest_direction_picks_the_nearest_across_north() -> None:
    assert closest_direction((45.0, 135.0, 225.0, 315.0), 350) == 315.0
    assert closest_direction((45.0, 135.0, 225.0, 315.0), 10) == 45.0
    assert closest_direction((0.0, 180.0), 90) == 0.0  # a tie: the lowest
    assert closest_direction((), 90) is None


# ---- unwrapped azimuth scales (rotctld) --------------------------------------------------

def test_south_stop_on_a_minus_180_scale_reads_west_as_minus_90() -> None:
    travel = Travel(ccw_limit=180, rotation=360, has_stop=True)
    assert window_base(travel, -180) == -180
    assert azimuth_of(travel, 90, -180, 180) == -90
    assert position_of(travel, -90, -180) == 90


def test_north_stop_overlap_is_written_past_360() -> None:
    travel = Travel(ccw_limit=0, rotation=450, has_stop=True)
    assert azimuth_of(travel, 400, -180, 450) == 400
    assert position_of(travel, 400, -180) == 400


def test_a_rotator_without_a_stop_is_sent_the_short_way_on_the_daemons_scale() -> None:
    free = Travel(ccw_limit=0, rotation=360, has_stop=False)
    # The daemon reads 70; 300 is 130 degrees counterclockwise: write it as -60.
    assert azimuth_of(free, 300, -180, 450, near=70) == -60
    assert azimuth_of(free, 10, -180, 450, near=-5) == 10  # 355 to 10: clockwise through north
    assert azimuth_of(free, 10, -180, 450, near=400) == 370  # on the daemon's overlap
    # The short way is off the scale: the long way is all there is.
    assert azimuth_of(free, 300, 0, 360, near=70) == 300
    assert azimuth_of(free, 300, -180, 450) == 300  # nothing read yet


@given(st.floats(min_value=-180, max_value=450), st.floats(min_value=0, max_value=359.9))
def test_a_rotator_without_a_stop_never_turns_more_than_half_a_turn_on_a_wide_scale(
    near: float, heading: float
) -> None:
    free = Travel(ccw_limit=0, rotation=360, has_stop=False)
    azimuth = azimuth_of(free, heading, -180, 450, near=near)
    assert close(normalize(azimuth), heading)
    if -180 + 180 <= near <= 450 - 180:
        assert abs(azimuth - near) <= 180 + 1e-6


@given(travels, st.floats(min_value=0, max_value=720))
def test_positions_survive_the_trip_through_an_unwrapped_scale(
    travel: Travel, position: float
) -> None:
    if not travel.bounded:
        position = normalize(position)
    position = travel.clamp(position)
    low = -180.0
    azimuth = azimuth_of(travel, position, low, low + 1500)  # wide enough for any travel
    back = position_of(travel, azimuth, low, near=position)
    assert close(travel.heading_at(back), travel.heading_at(position))
    if travel.bounded:
        assert back == pytest.approx(position, abs=1e-6)
