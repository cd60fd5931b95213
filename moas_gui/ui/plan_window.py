"""View > Station plan: the plan of the open configuration as a table, with its findings.

The plan is made by :mod:`moas_gui.plan` on copies of a new engine for the file:
the switches are not touched.  Two filters (radio, band) hide the rows that do not
concern them; the findings below name the line of the file to look at.
"""

from __future__ import annotations

from moas_gui.plan import FINDING_KINDS, Outcome, PairNote, Plan, RadioRef

from .qt import (
    QComboBox,
    QEvent,
    QHBoxLayout,
    QLabel,
    QObject,
    QResizeEvent,
    Qt,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)
from .screen_fit import fit_to_screen

COLUMNS = ("Scenario", "Band", "kHz", "Radio", "TX", "RX", "Why", "Transmit")
FINDING_COLUMNS = ("Line", "Finding", "What to look at")
FITTED = (1, 2, 3)
"""Columns as wide as their texts (band, kHz, radio: short)."""
SHARES = {0: 1.3, 4: 1.2, 5: 1.2, 6: 2.4, 7: 0.9}
"""How the rest of the table's width is shared; their texts wrap, never cut, so the
whole table fits the window's width (no column off-screen at 1024x600)."""
NARROWEST = 70
SIZE = (1000, 540)
"""The size the window asks for: within a 1024x600 screen, less its frame and a panel."""


def _radio(ref: RadioRef) -> str:
    return f"Station {ref.station} radio {ref.radio}"


class PlanWindow(QWidget):
    """The station plan of one configuration (see the module docstring)."""

    def __init__(self, plan: Plan, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.plan = plan
        self.setWindowTitle(f"Station plan - {plan.file}")
        layout = QVBoxLayout(self)
        filters = QHBoxLayout()
        self.radio_filter = QComboBox(self)
        self.radio_filter.addItem("All radios", None)
        for ref in plan.radios:
            self.radio_filter.addItem(_radio(ref), ref)
        self.band_filter = QComboBox(self)
        self.band_filter.addItem("All bands", None)
        for band in plan.bands:
            self.band_filter.addItem(band.name, band.name)
        filters.addWidget(QLabel("Radio", self))
        filters.addWidget(self.radio_filter)
        filters.addWidget(QLabel("Band", self))
        filters.addWidget(self.band_filter)
        filters.addStretch(1)
        self.count_label = QLabel(self)
        filters.addWidget(self.count_label)
        layout.addLayout(filters)
        if plan.not_planned():
            layout.addWidget(QLabel(plan.not_planned(), self))

        self.table = QTableWidget(0, len(COLUMNS), self)
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().hide()
        self.table.horizontalHeader().setStretchLastSection(True)
        self._rows: list[tuple[frozenset[RadioRef], frozenset[str]]] = []
        for o in plan.alone:
            self._add_alone(o)
        for a, b, _meet, scenarios in plan.pairs:
            for note in plan.pair_notes(a, b, scenarios):
                self._add_note(a, b, note)
        self.table.setWordWrap(True)
        self.table.setTextElideMode(Qt.TextElideMode.ElideNone)
        self.table.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.table.horizontalHeader().setStretchLastSection(False)
        self.table.resizeColumnsToContents()
        self.table.viewport().installEventFilter(self)
        layout.addWidget(self.table, 3)

        layout.addWidget(QLabel(f"Findings ({len(plan.findings)})", self))
        self.findings = QTableWidget(len(plan.findings), len(FINDING_COLUMNS), self)
        self.findings.setHorizontalHeaderLabels(FINDING_COLUMNS)
        self.findings.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.findings.verticalHeader().hide()
        self.findings.setWordWrap(True)
        self.findings.horizontalHeader().setStretchLastSection(True)
        self._finding_rows: list[tuple[frozenset[RadioRef], frozenset[str]]] = []
        for row, f in enumerate(plan.findings):
            values = (str(f.line) if f.line else "", FINDING_KINDS.get(f.kind, f.kind), f.text)
            for column, value in enumerate(values):
                item = QTableWidgetItem(value)
                item.setToolTip(value)
                self.findings.setItem(row, column, item)
            self._finding_rows.append((frozenset(f.radios), frozenset(
                b for where in f.bands for b in where.split(" + "))))
        self.findings.resizeColumnsToContents()
        self.findings.setColumnWidth(1, min(self.findings.columnWidth(1), 170))
        self.findings.resizeRowsToContents()
        layout.addWidget(self.findings, 2)

        self.radio_filter.currentIndexChanged.connect(lambda _i: self.apply_filters())
        self.band_filter.currentIndexChanged.connect(lambda _i: self.apply_filters())
        self.apply_filters()
        fit_to_screen(self, *SIZE)

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self.findings.resizeRowsToContents()  # wrapped to the findings' new width

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.table.viewport() and event.type() == QEvent.Type.Resize:
            self.fit_columns()  # the table's own width, once the layout has set it
        return super().eventFilter(watched, event)

    def fit_columns(self) -> None:
        """Share the table's width between its columns so that all of them show, and
        let the long texts (antenna names, reasons) wrap onto more lines."""
        table = self.table
        fitted = 0
        for column in FITTED:
            table.resizeColumnToContents(column)
            fitted += table.columnWidth(column)
        rest = max(0, table.viewport().width() - fitted)
        total = sum(SHARES.values())
        for column, share in SHARES.items():
            table.setColumnWidth(column, max(NARROWEST, int(rest * share / total)))
        table.resizeRowsToContents()

    def _add_row(self, values: tuple[str, ...], tips: dict[int, str],
                 radios: frozenset[RadioRef], bands: frozenset[str]) -> None:
        row = self.table.rowCount()
        self.table.insertRow(row)
        for column, value in enumerate(values):
            item = QTableWidgetItem(value)
            item.setToolTip(tips.get(column, value))
            self.table.setItem(row, column, item)
        self._rows.append((radios, bands))

    def _add_alone(self, o: Outcome) -> None:
        passed = self.plan.passed_over(o)
        why = o.text + (f"\npassed over: {passed}" if passed else "")
        transmit = ("cannot: " + o.note) if o.inhibited and o.note else (
            "cannot" if o.inhibited else "")
        values = ("alone", o.band, f"{o.khz:g}", _radio(o.radio), self.plan.name(o.tx),
                  self.plan.name(o.rx), o.text, transmit)
        self._add_row(values, {6: why}, frozenset({o.radio}), frozenset({o.band}))

    def _add_note(self, a: RadioRef, b: RadioRef, note: PairNote) -> None:
        radios = frozenset({a, b})
        o = note.outcome
        if o is None:  # an inhibit on every band
            who = _radio(note.radio) if note.radio is not None else "both"
            self._add_row((f"{_radio(a)} + {_radio(b).lower()}: {note.where}", "all", "", who,
                           "", "", note.text, "cannot while the other transmits"), {},
                          radios, note.bands)
            return
        other = b if o.radio == a else a
        text = note.text.split(": ", 1)[-1]
        why = text.split(" \u2014 ", 1)[-1]
        transmit = "cannot" if o.inhibited else (
            "cannot while the other transmits" if "cannot transmit while" in note.text else "")
        values = (f"{note.where}, with {_radio(other).lower()}",
                  ", ".join(sorted(note.bands, key=self._band_order)),
                  f"{o.khz:g}" if f"{o.khz:g} kHz" in note.text else "",
                  _radio(o.radio), self.plan.name(o.tx), self.plan.name(o.rx), why, transmit)
        self._add_row(values, {6: note.text}, radios, note.bands)

    def _band_order(self, name: str) -> int:
        return next((i for i, b in enumerate(self.plan.bands) if b.name == name), 0)

    def apply_filters(self) -> None:
        """Hide the rows the radio and band filters leave out."""
        radio = self.radio_filter.currentData()
        band = self.band_filter.currentData()
        shown = 0
        for row, (radios, bands) in enumerate(self._rows):
            visible = (radio is None or radio in radios) and (band is None or band in bands)
            self.table.setRowHidden(row, not visible)
            shown += visible
        for row, (radios, bands) in enumerate(self._finding_rows):
            visible = (radio is None or not radios or radio in radios) and (
                band is None or not bands or band in bands)
            self.findings.setRowHidden(row, not visible)
        self.count_label.setText(f"{shown} of {len(self._rows)} rows")

    def visible_rows(self) -> list[tuple[str, ...]]:
        """The rows shown now, as text (what the filters leave)."""
        out = []
        for row in range(self.table.rowCount()):
            if self.table.isRowHidden(row):
                continue
            items = (self.table.item(row, c) for c in range(len(COLUMNS)))
            out.append(tuple(item.text() if item is not None else "" for item in items))
        return out


__all__ = ["COLUMNS", "PlanWindow"]
