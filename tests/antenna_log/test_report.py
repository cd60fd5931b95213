"""The contest report's figures (moas_gui.antenna_log.report) from an in-memory journal
whose every record the test knows."""

from __future__ import annotations

from antenna_log_support import T0, MemoryJournal, contact, contest_journal

from moas_gui.antenna_log.records import AntennaSpan, KeySpan, Period
from moas_gui.antenna_log.report import (
    HOUR,
    NO_ANTENNA,
    TimelineSpan,
    contest_report,
    last_hours,
    qsos_per_antenna_per_band,
    rate_per_hour,
    timelines,
    transmit_seconds,
    whole_journal,
)

TWO_HOURS = Period(T0, T0 + 2 * HOUR)


def test_qsos_per_antenna_per_band() -> None:
    report = contest_report(contest_journal(), TWO_HOURS)
    assert report.contacts == 15
    assert report.qsos == {
        "Yagi 20": {"20m": 7},
        "Dipole 20": {"20m": 2},
        "4-Square": {"40m": 6},
    }
    assert report.bands == ["40m", "20m"]
    assert report.antenna_qsos("4-Square") == 6
    assert report.antenna_qsos("Bev NE") == 0


def test_rate_per_clock_hour_per_antenna() -> None:
    report = contest_report(contest_journal(), TWO_HOURS)
    assert report.hours == [T0, T0 + HOUR]
    assert report.rate == {"Yagi 20": [6, 1], "Dipole 20": [0, 2], "4-Square": [4, 2]}


def test_rate_hours_are_clock_hours_from_the_one_the_period_starts_in() -> None:
    contacts = [contact(1, T0 + 1800, "A1A"), contact(2, T0 + 3700, "B1B")]
    hours, rate = rate_per_hour(contacts, Period(T0 + 1000, T0 + 3800))
    assert hours == [T0, T0 + HOUR]
    assert rate == {"Yagi 20": [1, 1]}


def test_transmit_time_per_antenna_from_the_key_line() -> None:
    report = contest_report(contest_journal(), TWO_HOURS)
    assert report.transmit == {"Yagi 20": 600.0, "Dipole 20": 300.0, "4-Square": 1200.0}


def test_transmissions_are_clipped_to_the_period() -> None:
    # the first 4-Square transmission runs from T0+500 to T0+1100: 300 s of it fall before
    report = contest_report(contest_journal(), Period(T0 + 800, T0 + HOUR))
    assert report.transmit["4-Square"] == 300.0
    assert report.transmit["Yagi 20"] == 300.0  # T0+2000 to T0+2300; the first is outside


def test_each_radios_antenna_timeline() -> None:
    report = contest_report(contest_journal(), TWO_HOURS)
    first, second = report.timelines
    assert (first.station, first.radio, second.radio) == (1, 1, 2)
    assert first.label == "Station 1 radio 1"
    assert first.spans["tx"] == [
        TimelineSpan("Yagi 20", T0, T0 + 1.5 * HOUR),
        TimelineSpan("Dipole 20", T0 + 1.5 * HOUR, T0 + 2 * HOUR),
    ]
    assert second.spans["rx"] == [
        TimelineSpan("Bev NE", T0, T0 + HOUR),
        TimelineSpan("4-Square", T0 + HOUR, T0 + 2 * HOUR),
    ]
    assert list(second.spans) == ["tx", "rx"]


def test_a_span_with_no_antenna_leaves_a_gap_and_roles_keep_their_order() -> None:
    spans = [
        AntennaSpan(2, 1, "sub", "Bev SE", T0, T0 + 10),
        AntennaSpan(2, 1, "tx", "", T0, T0 + 10),
        AntennaSpan(2, 1, "tx", "Yagi", T0 + 10, T0 + 20),
        AntennaSpan(1, 2, "alt", "Dipole", T0, T0 + 5),
    ]
    found = timelines(spans)
    assert [(t.station, t.radio) for t in found] == [(1, 2), (2, 1)]
    assert list(found[1].spans) == ["tx", "sub"]
    assert found[1].spans["tx"] == [TimelineSpan("Yagi", T0 + 10, T0 + 20)]


def test_contacts_matched_to_no_radio_count_apart() -> None:
    contacts = [contact(1, T0, "A1A", radio=None), contact(2, T0, "B1B", "", khz=28400.0)]
    assert qsos_per_antenna_per_band(contacts) == {NO_ANTENNA: {"20m": 1}, "Yagi 20": {"10m": 1}}


def test_transmit_seconds_add_up_across_radios() -> None:
    keys = [KeySpan(1, 1, "Tower", T0, T0 + 30), KeySpan(1, 2, "Tower", T0 + 60, T0 + 75)]
    assert transmit_seconds(keys) == {"Tower": 45.0}


def test_an_empty_period() -> None:
    report = contest_report(contest_journal(), Period(T0 - 2 * HOUR, T0 - HOUR))
    assert report.empty
    assert report.contacts == 0 and report.rate == {} and report.antennas == []
    assert report.hours == [T0 - 2 * HOUR]


def test_whole_journal_and_last_hours() -> None:
    assert whole_journal(MemoryJournal()) is None
    assert whole_journal(contest_journal()) == Period(T0, T0 + 2 * HOUR + 1)
    assert last_hours(T0 + 0.5, 3) == Period(T0 + 0.5 - 3 * HOUR, T0 + 1)
