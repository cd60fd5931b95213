"""The rules every frequency source shares (moas_gui/sources/base.py)."""

from __future__ import annotations

import logging

import pytest

from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import (
    ActiveRadio,
    BadInputLog,
    ConnectionLog,
    FocusRadio,
    FrequencyReport,
    RunOrSearch,
    SourceEvent,
    SourceHub,
    check_khz,
    event_key,
)


def report(khz: float, origin: str, radio: int = 1) -> FrequencyReport:
    return FrequencyReport(1, radio, khz, khz, origin)


def test_two_sources_for_one_radio_the_newest_wins_and_it_is_logged_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    got: list[SourceEvent] = []
    hub = SourceHub(got.append)
    caplog.set_level(logging.INFO, logger="moas_gui.sources")
    for khz, origin in ((14000.0, "N1MM A"), (7000.0, "rigctld :4532"), (14010.0, "N1MM A"),
                        (7010.0, "rigctld :4532"), (3500.0, "rigctld :4532")):
        hub(report(khz, origin))
    assert [e.rx_khz for e in got if isinstance(e, FrequencyReport)] == [
        14000.0, 7000.0, 14010.0, 7010.0, 3500.0], "every event passes, in order: the newest wins"
    lines = [r.getMessage() for r in caplog.records if "two sources" in r.getMessage()]
    assert lines == [("Station 1 radio 1 is reported by two sources, N1MM A and rigctld :4532: "
                     "the newest wins")]
    assert hub.overlaps == 3 and hub.delivered == 5


def test_different_radios_and_event_kinds_are_not_overlaps() -> None:
    hub = SourceHub(lambda event: None)
    hub(report(14000.0, "A", radio=1))
    hub(report(7000.0, "B", radio=2))
    hub(ActiveRadio(1, 2, "C"))
    hub(FocusRadio(1, 1, "D"))
    hub(RunOrSearch(1, 1, True, "E"))
    assert hub.overlaps == 0


def test_a_stopped_source_is_forgotten_so_its_successor_is_no_overlap() -> None:
    hub = SourceHub(lambda event: None)
    hub(report(14000.0, "A"))
    hub.forget("A")
    hub(report(14000.0, "B"))
    assert hub.overlaps == 0


def test_a_sink_that_raises_is_counted_and_the_next_event_still_goes(
    caplog: pytest.LogCaptureFixture,
) -> None:
    seen: list[SourceEvent] = []

    def sink(event: SourceEvent) -> None:
        seen.append(event)
        if len(seen) == 1:
            raise RuntimeError("engine refused")

    hub = SourceHub(sink)
    hub(report(14000.0, "A"))
    hub(report(14001.0, "A"))
    assert len(seen) == 2 and hub.sink_errors == 1 and hub.delivered == 1
    assert any(r.exc_info for r in caplog.records)


def test_bad_input_is_counted_and_logged_once_a_minute_per_reason_and_place(
    caplog: pytest.LogCaptureFixture,
) -> None:
    now = [0.0]
    log = logging.getLogger("moas_gui.sources.test")
    bad = BadInputLog(log, "Test", clock=lambda: now[0])
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.test")
    for _ in range(50):
        bad.drop("garbage", "10.0.0.1", "not a frame")
    bad.drop("garbage", "10.0.0.2", "not a frame")
    now[0] = 61.0
    bad.drop("garbage", "10.0.0.1", "not a frame")
    lines = [r.getMessage() for r in caplog.records]
    assert lines == [
        "Test input from 10.0.0.1 dropped: not a frame",
        "Test input from 10.0.0.2 dropped: not a frame",
        "Test input from 10.0.0.1 dropped: not a frame (49 more like it since the last such line)",
    ]
    assert bad.counts == {"garbage": 52} and bad.total == 52


def test_a_source_that_goes_and_returns_warns_once_and_says_once_it_is_back(
    caplog: pytest.LogCaptureFixture,
) -> None:
    now = [0.0]
    log = logging.getLogger("moas_gui.sources.test")
    link = ConnectionLog(log, "rigctld 127.0.0.1:4532", clock=lambda: now[0])
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.test")
    link.up()
    for _ in range(100):
        link.lost("connection refused")
        now[0] += 0.5
    link.up()
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    infos = [r.getMessage() for r in caplog.records if r.levelno == logging.INFO]
    debug = [r for r in caplog.records if r.levelno == logging.DEBUG]
    assert len(warnings) == 1 and "lost: connection refused" in warnings[0].getMessage()
    assert infos == ["rigctld 127.0.0.1:4532 connected", "rigctld 127.0.0.1:4532 is back"]
    assert len(debug) == 1, "99 retries over 50 s: one rate-limited debug line"
    assert link.failures == 0 and link.connected


def test_a_source_never_reached_warns_once() -> None:
    log = logging.getLogger("moas_gui.sources.test")
    link = ConnectionLog(log, "flrig")
    link.lost("refused")
    link.lost("refused")
    assert link.failures == 2 and not link.connected


def test_backoff_doubles_to_its_limit_and_resets() -> None:
    backoff = Pauses(Backoff(first=0.5, most=4.0))
    assert [backoff.next() for _ in range(5)] == [0.5, 1.0, 2.0, 4.0, 4.0]
    backoff.reset()
    assert backoff.next() == 0.5


@pytest.mark.parametrize("khz", [0.0, -1.0, 300_000_000.0, float("nan"), float("inf")])
def test_absurd_frequencies_are_refused(khz: float) -> None:
    with pytest.raises(ValueError, match="not a radio frequency"):
        check_khz(khz, "Freq")


def test_event_keys_group_what_replaces_what() -> None:
    assert event_key(report(1.0, "a")) == event_key(report(2.0, "b"))
    assert event_key(ActiveRadio(1, 1, "a")) == event_key(ActiveRadio(1, 2, "b"))
    assert event_key(ActiveRadio(1, 1, "a")) != event_key(FocusRadio(1, 1, "a"))
    assert check_khz(14000.0, "Freq") == 14000.0
