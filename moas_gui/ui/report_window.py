"""View > Contest report and File > Export antenna log: what the antenna journal holds,
as charts, and as an ADIF file.

:class:`ReportWindow` shows the four charts of :mod:`moas_gui.antenna_log.report_charts`
for a chosen period, each on a tab, drawn by matplotlib's Qt canvas (a tab's chart is
drawn when it is on the screen: its tab chosen, the window shown), and exports the
report as PNG or as one HTML page (drawn and written in the report's thread, in turn
with the reports).  :class:`AdifExportWindow` writes the contacts of a chosen period
as ADIF.  Both read the journal they are given (``None``: the journal is turned off)
and say plainly when there is nothing to show.  The report is read from the journal
in the report's own thread, one report at a time
(:data:`~moas_gui.antenna_log.report.REPORTS`, shared with the web page's
``/report``), its period bounded as the page's is; only the charts on the screen are
drawn on the window's thread.  Their file dialogs open with ``open()``, never
``exec()``: the server's event loop keeps running.
"""

from __future__ import annotations

import contextlib
import logging
import math
import sqlite3
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import UTC, datetime
from functools import partial
from pathlib import Path

from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure

from moas_gui.antenna_log.adif import parse_utc, write_adif
from moas_gui.antenna_log.records import JournalReader, Period
from moas_gui.antenna_log.report import (
    REPORTS,
    ContestReport,
    NothingRecorded,
    bounded_period,
    contest_report,
    last_hours,
    whole_journal,
)
from moas_gui.antenna_log.report_charts import (
    CHARTS,
    draw_chart,
    period_text,
    save_html,
    save_png,
)

from .qt import (
    QComboBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QShowEvent,
    QSpinBox,
    Qt,
    QTabWidget,
    QVBoxLayout,
    QWidget,
    Signal,
)
from .screen_fit import fit_to_screen

__all__ = ["NO_JOURNAL", "AdifExportWindow", "PeriodChooser", "ReportWindow"]

log = logging.getLogger(__name__)

SIZE = (1000, 540)
"""The size the report asks for: within a 1024x600 screen, less its frame and a panel."""
NO_JOURNAL = (
    "The antenna journal is turned off (--no-antenna-log, or in the menu), so there is "
    "nothing to show. docs/antenna-log.md says what it records once it is on."
)
EMPTY_JOURNAL = (
    "The antenna journal is empty: nothing has been recorded yet. Antenna changes, "
    "transmissions and the loggers' contacts appear here once the station works."
)
PERIODS = ("Whole journal", "Last hours", "From – to")

ChooseFile = Callable[[str, str, str, Callable[[str], None]], None]
"""``(title, file filter, suggested name, chosen)``: a save dialog; ``chosen(path)``."""


def _iso(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%dT%H:%MZ")


class PeriodChooser(QWidget):
    """The whole journal, the last N hours, or from one UTC time to another."""

    changed = Signal()

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.kind = QComboBox()
        self.kind.addItems(PERIODS)
        self.hours = QSpinBox()
        self.hours.setRange(1, 24 * 30)
        self.hours.setValue(6)
        self.hours.setSuffix(" h")
        self.start = QLineEdit()
        self.end = QLineEdit()
        for edit in (self.start, self.end):
            edit.setPlaceholderText("2026-11-28T00:00Z")
            edit.setToolTip("ISO 8601, in UTC")
            edit.setMaximumWidth(170)
        self.to_label = QLabel("to")
        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QLabel("Period:"))
        for widget in (self.kind, self.hours, self.start, self.to_label, self.end):
            row.addWidget(widget)
        row.addStretch(1)
        self.kind.currentIndexChanged.connect(self._kind_changed)
        self.hours.valueChanged.connect(self.changed)
        self.start.editingFinished.connect(self.changed)
        self.end.editingFinished.connect(self.changed)
        self._kind_changed()

    def _kind_changed(self) -> None:
        kind = self.kind.currentIndex()
        self.hours.setVisible(kind == 1)
        for widget in (self.start, self.to_label, self.end):
            widget.setVisible(kind == 2)
        self.changed.emit()

    def fill_from(self, extent: Period | None) -> None:
        """Puts the journal's first and last times in the from–to fields, where empty."""
        if extent is None:
            return
        if not self.start.text():
            self.start.setText(_iso(extent.start))
        if not self.end.text():
            self.end.setText(_iso(extent.end + 60))

    def asked(self, now: float) -> Period | None:
        """The period chosen, for the report to bound (None: the whole journal; a from or
        to left empty is infinite: the journal's first or last time).  Raises
        ``ValueError`` saying what is wrong with a from–to."""
        kind = self.kind.currentIndex()
        if kind == 1:
            return last_hours(now, self.hours.value())
        if kind == 2:
            start = parse_utc(self.start.text()) if self.start.text().strip() else -math.inf
            end = parse_utc(self.end.text()) if self.end.text().strip() else math.inf
            if start >= end:
                raise ValueError(f"{self.start.text()} is not before {self.end.text()}")
            return Period(start, end)
        return None

    def period(self, reader: JournalReader, now: float) -> Period | None:
        """The period chosen; None for an empty journal's whole.  Raises ``ValueError``
        saying what is wrong with a from–to."""
        kind = self.kind.currentIndex()
        if kind == 1:
            return last_hours(now, self.hours.value())
        if kind == 2:
            start = parse_utc(self.start.text())
            end = parse_utc(self.end.text())
            if start >= end:
                raise ValueError(f"{self.start.text()} is not before {self.end.text()}")
            return Period(start, end)
        return whole_journal(reader)


def _save_dialog(parent: QWidget) -> ChooseFile:
    def choose(title: str, filters: str, name: str, chosen: Callable[[str], None]) -> None:
        dialog = QFileDialog(parent, title, str(Path.home() / name), filters)
        dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
        dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        dialog.fileSelected.connect(chosen)
        dialog.open()

    return choose


class _JournalWindow(QWidget):
    """What both windows on a journal have: its reader, the clock, a save dialog, a
    notice line (no journal, an empty one, one that cannot be read) and a period."""

    def __init__(self, title: str, reader: JournalReader | None, now: Callable[[], float],
                 parent: QWidget | None) -> None:
        super().__init__(parent)
        self.setWindowTitle(title)
        self.reader = reader
        self._now = now
        self.choose_file: ChooseFile = _save_dialog(self)
        self.notice = QLabel()
        self.notice.setWordWrap(True)
        self.chooser = PeriodChooser()


@dataclass(frozen=True, slots=True)
class _Made:
    """What the report's thread found: the journal's extent (None: empty) and the report,
    or what to say instead."""

    extent: Period | None
    report: ContestReport | None = None
    notice: str = EMPTY_JOURNAL


def _make(reader: JournalReader, asked: Period | None, now: float) -> _Made:
    """The report for ``asked`` (in the report's thread, never the event loop's)."""
    extent = reader.extent()
    try:
        period = bounded_period(reader, asked, now)
    except NothingRecorded as exc:
        return _Made(extent, notice=str(exc))
    if period is None:
        return _Made(None)
    return _Made(extent, contest_report(reader, period))


class ReportWindow(_JournalWindow):
    """The contest report of one journal (see the module docstring)."""

    _made = Signal(int, object, object)
    """A report asked for came from the report's thread (number, :class:`_Made`, error)."""
    _saved = Signal(str, object)
    """An export was written, or not, in the report's thread (path, error or None)."""

    def __init__(
        self,
        reader: JournalReader | None,
        *,
        now: Callable[[], float] = time.time,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__("Contest report", reader, now, parent)
        self.report: ContestReport | None = None
        self.summary = QLabel()
        self.tabs = QTabWidget()
        self.canvases: dict[str, FigureCanvasQTAgg] = {}
        for kind, title in CHARTS.items():
            canvas = FigureCanvasQTAgg(Figure(figsize=(8, 4.2)))  # type: ignore[no-untyped-call]
            self.canvases[kind] = canvas
            self.tabs.addTab(canvas, title)
        self.export_png = QPushButton("Export &PNG...")
        self.export_html = QPushButton("Export &HTML...")
        close = QPushButton("&Close")
        self.status = QLabel()
        buttons = QHBoxLayout()
        for widget in (self.export_png, self.export_html):
            buttons.addWidget(widget)
        buttons.addWidget(self.status, 1)
        buttons.addWidget(close)
        layout = QVBoxLayout(self)
        layout.addWidget(self.notice)
        layout.addWidget(self.chooser)
        layout.addWidget(self.summary)
        layout.addWidget(self.tabs, 1)
        layout.addLayout(buttons)
        self._stale: set[str] = set()
        """The charts not drawn (on their figure) and rendered since the report changed."""
        self._asked = 0
        """How many reports the window has asked for: only the last one's is shown."""
        self.pending = False
        """A report asked for has not come yet."""
        self._made.connect(self._show)
        self._saved.connect(self._said_saved)
        self.chooser.changed.connect(self.refresh)
        self.tabs.currentChanged.connect(self._draw_shown)
        self.export_png.clicked.connect(self.save_png)
        self.export_html.clicked.connect(self.save_html)
        close.clicked.connect(self.close)
        fit_to_screen(self, *SIZE)
        self.refresh()

    def _say(self, notice: str) -> None:
        self.notice.setText(notice)
        self.notice.setVisible(bool(notice))

    def _show_charts(self, shown: bool) -> None:
        for widget in (self.tabs, self.summary, self.export_png, self.export_html):
            widget.setVisible(shown)

    def refresh(self) -> None:
        """Asks for the report of the chosen period; it is made in the report's own thread
        (:data:`~moas_gui.antenna_log.report.REPORTS`, one report at a time: this waits
        its turn) and shown when it comes (:meth:`_show`)."""
        if self.reader is None:
            self._nothing(NO_JOURNAL)
            return
        self._asked += 1  # a report still being made for an earlier choice is not shown
        try:
            asked = self.chooser.asked(self._now())
        except ValueError as exc:
            self.pending = False
            self._say(f"The period: {exc}")
            return
        self.pending = True
        REPORTS.start(partial(_make, self.reader, asked, self._now()),
                      partial(self._arrived, self._asked))

    def _arrived(self, number: int, made: _Made | None, error: BaseException | None) -> None:
        # in the report's thread: handed to the window's (a queued signal)
        with contextlib.suppress(RuntimeError):  # the window is gone
            self._made.emit(number, made, error)

    def _show(self, number: int, made: _Made | None, error: BaseException | None) -> None:
        if number != self._asked:
            return  # a newer period was chosen meanwhile: its report follows
        self.pending = False
        if isinstance(error, sqlite3.Error | OSError):
            self._nothing(f"Could not read the antenna journal: {error}")
            return
        if isinstance(error, ValueError):
            self._say(f"The period: {error}")
            return
        if error is not None or made is None:
            log.error("The contest report could not be made: %r", error)
            self._nothing(f"The contest report could not be made: {error}")
            return
        self.chooser.fill_from(made.extent)
        if made.report is None:
            self._nothing(made.notice)
            return
        report = made.report
        self._say("")
        self.chooser.setVisible(True)
        self._show_charts(True)
        self.report = report
        qsos = f"{report.contacts} QSO{'s' if report.contacts != 1 else ''}"
        self.summary.setText(f"{period_text(report)}: {qsos}")
        self._stale = set(self.canvases)
        self._draw_shown()

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self._draw_shown()  # a report that came while the window was hidden

    def _draw_shown(self) -> None:
        """Draws and renders the chart of the tab shown, if the report changed since it
        was drawn (the other tabs wait until shown: each takes a moment of the loop's
        thread); none while the window is hidden (a report that comes before the window
        is shown, or after it was closed, would be rendered for nobody, and once more at
        the size the window then has)."""
        shown = self.tabs.currentWidget()
        if not shown.isVisible():
            return
        for kind, canvas in self.canvases.items():
            if canvas is shown and kind in self._stale and self.report is not None:
                self._stale.discard(kind)
                draw_chart(kind, canvas.figure, self.report)
                canvas.draw_idle()  # type: ignore[no-untyped-call]

    def _nothing(self, notice: str) -> None:
        self.report = None
        self._say(notice)
        self.chooser.setVisible(self.reader is not None and notice != EMPTY_JOURNAL)
        self._show_charts(False)

    def save_png(self) -> None:
        """Export PNG...: the four charts in one image."""
        if self.report is not None:
            report = self.report
            self.choose_file(
                "Export the contest report as PNG",
                "PNG images (*.png);;All files (*)",
                "contest-report.png",
                lambda path: self._save(path, lambda: save_png(report, Path(path))),
            )

    def save_html(self) -> None:
        """Export HTML...: one page holding the numbers and the charts."""
        if self.report is not None:
            report = self.report
            self.choose_file(
                "Export the contest report as HTML",
                "HTML pages (*.html *.htm);;All files (*)",
                "contest-report.html",
                lambda path: self._save(path, lambda: save_html(report, Path(path))),
            )

    def _save(self, path: str, write: Callable[[], None]) -> None:
        """Draws and writes the export in the report's thread, one at a time with the
        reports (not on the window's thread, which is the loop's: a PNG and an HTML
        page take some 0.3 s each); the window says how it went when it is done."""
        if not path:
            return
        self.status.setText(f"Saving {path}...")
        REPORTS.start(write, partial(self._written, path))

    def _written(self, path: str, _result: None, error: BaseException | None) -> None:
        # in the report's thread: handed to the window's (a queued signal)
        with contextlib.suppress(RuntimeError):  # the window is gone
            self._saved.emit(path, error)

    def _said_saved(self, path: str, error: BaseException | None) -> None:
        if error is None:
            self.status.setText(f"Saved {path}")
            log.info("Contest report saved to %s", path)
            return
        why = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
        self.status.setText(f"Could not save {path}: {why}")
        log.error("Could not save the contest report to %s: %s", path, why)


class AdifExportWindow(_JournalWindow):
    """File > Export antenna log: the contacts of a chosen period as an ADIF file."""

    def __init__(
        self,
        reader: JournalReader | None,
        *,
        now: Callable[[], float] = time.time,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__("Export antenna log", reader, now, parent)
        self.callsign = QLineEdit()
        self.callsign.setPlaceholderText("optional: written as STATION_CALLSIGN")
        self.save = QPushButton("&Save ADIF...")
        self.status = QLabel()
        self.status.setWordWrap(True)
        call_row = QHBoxLayout()
        call_row.addWidget(QLabel("Station call:"))
        call_row.addWidget(self.callsign, 1)
        layout = QVBoxLayout(self)
        layout.addWidget(self.notice)
        layout.addWidget(self.chooser)
        layout.addLayout(call_row)
        layout.addWidget(self.save, 0, Qt.AlignmentFlag.AlignLeft)
        layout.addWidget(self.status)
        self.save.clicked.connect(self.choose)
        self.resize(620, 160)
        usable = reader is not None
        try:
            extent = reader.extent() if reader is not None else None
        except (sqlite3.Error, OSError) as exc:
            extent, usable = None, False
            self.notice.setText(f"Could not read the antenna journal: {exc}")
        if reader is None:
            self.notice.setText(NO_JOURNAL)
        elif usable and extent is None:
            self.notice.setText(EMPTY_JOURNAL)
        self.chooser.fill_from(extent)
        usable = usable and extent is not None
        self.notice.setVisible(not usable)
        for widget in (self.chooser, self.callsign, self.save):
            widget.setEnabled(usable)

    def choose(self) -> None:
        """Save ADIF...: checks the period, then asks where."""
        if self.reader is None:
            return
        try:
            period = self.chooser.period(self.reader, self._now())
        except ValueError as exc:
            self.status.setText(f"The period: {exc}")
            return
        if period is None:
            self.status.setText(EMPTY_JOURNAL)
            return
        self.choose_file(
            "Export the antenna log as ADIF",
            "ADIF files (*.adi);;All files (*)",
            "antenna-log.adi",
            lambda path: self.write(path, period),
        )

    def write(self, path: str, period: Period) -> None:
        if not path or self.reader is None:
            return
        try:
            count = write_adif(
                self.reader, period, path, station_callsign=self.callsign.text().strip()
            )
        except (sqlite3.Error, OSError) as exc:
            text = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            self.status.setText(f"Could not export to {path}: {text}")
            log.error("Could not export the antenna log to %s: %s", path, text)
            return
        plural = "" if count == 1 else "s"
        self.status.setText(f"Wrote {count} contact{plural} to {path}")
        log.info("Antenna log exported to %s: %d contact%s", path, count, plural)
