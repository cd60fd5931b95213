"""View > Contest report and File > Export antenna log as windows (offscreen, pytest-qt)
on an in-memory journal: the period chooser, the charts on matplotlib's Qt canvas, the
exports, and what each says when there is no journal.

The windows' module (and matplotlib, which it loads) is imported in the tests, not at the
top: collecting the suite loads every test module in every worker, and matplotlib costs
about 0.4 s of processor time to load."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import adif_io
import pytest
from antenna_log_support import T0, MemoryJournal, charts_loaded, contest_journal

from moas_gui.antenna_log.records import Period
from moas_gui.antenna_log.report import HOUR, REPORTS

if TYPE_CHECKING:
    from moas_gui.ui.report_window import ReportWindow

SCREENSHOTS = os.environ.get("MOAS_SCREENSHOTS")
"""Where to save the windows' pictures (docs/images), when set."""


@pytest.fixture(scope="module", autouse=True)
def _charts_loaded() -> None:
    charts_loaded()  # matplotlib, imported here and kept out of the collector (see there)


def answer_with(window: Any, *paths: str) -> list[str]:
    """Makes the window's save dialog answer with ``paths`` in turn; returns the titles."""
    titles: list[str] = []
    queue = list(paths)

    def choose(title: str, filters: str, name: str, chosen: Callable[[str], None]) -> None:
        titles.append(title)
        chosen(queue.pop(0))

    window.choose_file = choose
    return titles


def made(qtbot: Any, window: ReportWindow) -> None:
    """Waits until the report last asked for has come from the report's thread."""
    qtbot.waitUntil(lambda: not window.pending, timeout=20_000)


def chart_texts(window: ReportWindow, kind: str) -> list[str]:
    figure = window.canvases[kind].figure
    return [text.get_text() for ax in figure.axes for text in ax.texts] + [
        label.get_text() for ax in figure.axes for label in ax.get_xticklabels()
    ]


def test_the_report_shows_the_whole_journal(qtbot: Any, tmp_path: Path) -> None:
    from matplotlib.image import imread

    from moas_gui.antenna_log.report_charts import BAND_COLOURS
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal(), now=lambda: T0 + 3 * HOUR)
    qtbot.addWidget(window)
    made(qtbot, window)
    window.show()
    qtbot.waitExposed(window)
    assert window.width() <= 1024 and window.height() <= 600
    assert not window.notice.isVisible()
    assert window.summary.text() == "2026-11-18 11:00 – 2026-11-18 13:00 UTC: 15 QSOs"
    assert [window.tabs.tabText(i) for i in range(window.tabs.count())] == [
        "QSOs per antenna per band",
        "Rate per hour per antenna",
        "Transmit time per antenna",
        "Antennas per radio",
    ]
    assert window.report is not None and window.report.contacts == 15
    assert sorted(chart_texts(window, "qsos")[:3]) == ["2", "6", "7"]
    qtbot.waitUntil(lambda: window.canvases["qsos"].get_renderer() is not None)
    shot = tmp_path / "report.png"
    assert window.grab().save(str(shot))
    image = imread(str(shot))
    # the bar chart is drawn on the canvas: 20 m's own colour fills a good part of it
    red, green, blue = (int(BAND_COLOURS["20m"][i:i + 2], 16) / 255 for i in (1, 3, 5))
    twenty = ((abs(image[..., 0] - red) < 0.02) & (abs(image[..., 1] - green) < 0.02)
              & (abs(image[..., 2] - blue) < 0.02))
    assert twenty.sum() > 5000
    if SCREENSHOTS:  # the timeline's tab is drawn only for its picture
        window.grab().save(str(Path(SCREENSHOTS) / "contest-report.png"))
        window.tabs.setCurrentIndex(3)
        qtbot.waitUntil(lambda: hasattr(window.canvases["timeline"], "renderer"))
        window.grab().save(str(Path(SCREENSHOTS) / "contest-report-timeline.png"))


def test_the_last_hours_and_a_from_to(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal(), now=lambda: T0 + 2 * HOUR)
    qtbot.addWidget(window)
    made(qtbot, window)
    window.chooser.kind.setCurrentIndex(1)
    window.chooser.hours.setValue(1)
    made(qtbot, window)
    assert window.report is not None
    assert window.report.contacts == 5  # the second hour (and its last second)
    window.chooser.kind.setCurrentIndex(2)
    assert window.chooser.start.text() == "2026-11-18T11:00Z"  # the journal's first time
    window.chooser.start.setText("2026-11-18T11:00Z")
    window.chooser.end.setText("2026-11-18T11:30Z")
    window.chooser.end.editingFinished.emit()
    made(qtbot, window)
    assert window.report.contacts == 7 - 2  # DL0AA-DL3AA (300-1800 s) and G0BB, G1BB
    assert window.report.qsos == {"Yagi 20": {"20m": 3}, "4-Square": {"40m": 2}}


def test_a_bad_time_says_so_and_keeps_the_charts(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal())
    qtbot.addWidget(window)
    made(qtbot, window)
    window.show()
    window.chooser.kind.setCurrentIndex(2)  # from the journal's first to its last time
    shown = window.report
    window.chooser.end.setText("tomorrow")
    window.chooser.end.editingFinished.emit()
    assert window.notice.isVisible()
    assert "'tomorrow' is not a time; write it as ISO 8601 in UTC" in window.notice.text()
    assert window.report is shown and window.tabs.isVisible()


def test_with_the_journal_turned_off_it_says_so_plainly(qtbot: Any, tmp_path: Path) -> None:
    from moas_gui.ui.report_window import NO_JOURNAL, ReportWindow

    window = ReportWindow(None)
    qtbot.addWidget(window)
    made(qtbot, window)
    window.show()
    qtbot.waitExposed(window)
    assert window.notice.isVisible() and window.notice.text() == NO_JOURNAL
    assert not window.tabs.isVisible() and not window.export_png.isVisible()
    assert not window.chooser.isVisible()
    if SCREENSHOTS:
        window.grab().save(str(Path(SCREENSHOTS) / "contest-report-off.png"))


def test_an_empty_journal_says_so(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(MemoryJournal())
    qtbot.addWidget(window)
    made(qtbot, window)
    window.show()
    assert "The antenna journal is empty" in window.notice.text()
    assert not window.tabs.isVisible()


def test_export_png_and_html(qtbot: Any, tmp_path: Path) -> None:
    from matplotlib.image import imread

    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal())
    qtbot.addWidget(window)
    made(qtbot, window)
    png, page = tmp_path / "r.png", tmp_path / "r.html"
    titles = answer_with(window, str(png), str(page))
    other = ReportWindow(held := HeldJournal())  # a report in the making holds the desk
    qtbot.addWidget(other)
    qtbot.waitUntil(lambda: REPORTS.busy)
    try:
        window.export_png.click()  # drawn and written in the report's thread, in its turn
        assert window.status.text() == f"Saving {png}..." and not png.exists()
    finally:
        held.go.set()
    qtbot.waitUntil(lambda: window.status.text() == f"Saved {png}", timeout=20_000)
    window.export_html.click()
    qtbot.waitUntil(lambda: window.status.text() == f"Saved {page}", timeout=20_000)
    assert titles == ["Export the contest report as PNG", "Export the contest report as HTML"]
    assert imread(str(png)).shape[:2] == (900, 1600)
    text = page.read_text(encoding="utf-8")
    assert text.count("<svg") == 4 and "<td>4-Square</td><td>6</td>" in text


def test_an_export_that_cannot_be_written_says_why(qtbot: Any, tmp_path: Path) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal())
    qtbot.addWidget(window)
    made(qtbot, window)
    target, image = tmp_path / "missing" / "r.html", tmp_path / "missing" / "r.png"
    answer_with(window, str(target), str(image))
    window.export_html.click()
    qtbot.waitUntil(lambda: window.status.text().startswith(f"Could not save {target}: "),
                    timeout=20_000)
    assert not target.exists()
    window.export_png.click()
    qtbot.waitUntil(lambda: window.status.text()
                    == f"Could not save {image}: No such file or directory", timeout=20_000)
    assert not image.exists()


def test_export_antenna_log_writes_the_chosen_period(qtbot: Any, tmp_path: Path) -> None:
    from moas_gui.ui.report_window import AdifExportWindow

    window = AdifExportWindow(contest_journal(), now=lambda: T0 + 2 * HOUR)
    qtbot.addWidget(window)
    window.show()
    assert not window.notice.isVisible() and window.save.isEnabled()
    out = tmp_path / "last-hour.adi"
    titles = answer_with(window, str(out))
    window.chooser.kind.setCurrentIndex(1)
    window.chooser.hours.setValue(1)
    window.callsign.setText("k1xx")
    window.save.click()
    assert titles == ["Export the antenna log as ADIF"]
    qsos, _ = adif_io.read_from_file(str(out))
    assert sorted(q["CALL"] for q in qsos) == ["EA0EE", "EA1EE", "F1CC", "I0DD", "I1DD"]
    assert {q["STATION_CALLSIGN"] for q in qsos} == {"K1XX"}
    assert window.status.text() == f"Wrote 5 contacts to {out}"
    if SCREENSHOTS:
        window.grab().save(str(Path(SCREENSHOTS) / "export-antenna-log.png"))


@pytest.mark.parametrize("reader", [None, MemoryJournal()])
def test_export_antenna_log_without_a_journal(qtbot: Any, reader: Any) -> None:
    from moas_gui.ui.report_window import AdifExportWindow

    window = AdifExportWindow(reader)
    qtbot.addWidget(window)
    window.show()
    assert window.notice.isVisible() and not window.save.isEnabled()
    assert "turned off" in window.notice.text() or "empty" in window.notice.text()


def test_only_the_tab_shown_is_rendered_until_another_is_chosen(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal())
    qtbot.addWidget(window)
    made(qtbot, window)
    canvases = list(window.canvases.values())
    assert not any(c.figure.axes for c in canvases), "nothing drawn while the window is hidden"
    window.show()
    qtbot.waitExposed(window)
    qtbot.waitUntil(lambda: hasattr(canvases[0], "renderer"))
    assert all(not hasattr(c, "renderer") for c in canvases[1:])
    assert canvases[0].figure.axes and not any(c.figure.axes for c in canvases[1:]), \
        "the other charts are not even drawn on their figures yet"
    window.tabs.setCurrentIndex(2)
    qtbot.waitUntil(lambda: hasattr(canvases[2], "renderer"))
    assert not hasattr(canvases[1], "renderer") and not hasattr(canvases[3], "renderer")
    assert canvases[2].figure.axes and not canvases[1].figure.axes and not canvases[3].figure.axes


class HeldJournal(MemoryJournal):
    """A journal whose reading waits until the test lets it go."""

    def __init__(self) -> None:
        super().__init__(**vars(contest_journal()))
        self.go = threading.Event()

    def extent(self) -> Period | None:
        self.go.wait(30)
        return super().extent()


def test_the_report_is_read_off_the_window_s_thread_one_at_a_time(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    first = ReportWindow(held := HeldJournal())
    qtbot.addWidget(first)
    assert first.pending and first.report is None  # the window is back before the journal
    qtbot.waitUntil(lambda: REPORTS.busy)
    second = ReportWindow(contest_journal())  # waits its turn
    qtbot.addWidget(second)
    qtbot.wait(200)
    assert second.pending and REPORTS.busy
    held.go.set()
    made(qtbot, first)
    made(qtbot, second)
    assert first.report is not None and second.report is not None
    assert first.report.contacts == second.report.contacts == 15


def test_more_than_a_year_is_refused_and_a_period_beyond_the_journal_clamped(qtbot: Any) -> None:
    from moas_gui.ui.report_window import ReportWindow

    window = ReportWindow(contest_journal(), now=lambda: T0 + 3 * HOUR)
    qtbot.addWidget(window)
    made(qtbot, window)
    window.show()
    shown = window.report
    window.chooser.kind.setCurrentIndex(2)
    window.chooser.start.setText("1000-01-01")
    window.chooser.end.setText("3000-01-01")
    window.chooser.end.editingFinished.emit()
    made(qtbot, window)
    assert "a report covers at most 366 days" in window.notice.text()
    assert "the journal holds 2026-11-18 11:00 UTC to 2026-11-18 13:00 UTC" in window.notice.text()
    assert window.report is shown
    window.chooser.start.setText("2026-06-01")
    window.chooser.end.setText("2026-12-01")
    window.chooser.end.editingFinished.emit()
    made(qtbot, window)
    assert not window.notice.isVisible() and window.report is not None
    assert window.report.period == Period(T0, T0 + 3 * HOUR + 1)  # the journal, up to now
    assert len(window.report.hours) == 4
