"""View > Station plan: the plan of the open configuration as a table, with its findings.

The plan is made by :mod:`moas_gui.plan` on copies of a new engine for the file:
the switches are not touched.  Two filters (radio, band) hide the rows that do not
concern them; the findings below name the line of the file to look at.
"""

from __future__ import annotations

from moas_gui.plan import FINDING_KINDS, Outcome, Plan, RadioRef

from .qt import (
    QComboBox,
    QHBoxLayout,
    QLabel,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

COLUMNS = ("Scenario", "Band", "Radio", "TX", "RX", "Rule", "Why", "Inhibited")
FINDING_COLUMNS = ("Line", "Finding", "What to look at")


def _radio(ref: RadioRef) -> str:
    return f"Station {ref.station} radio {ref.radio}"


class PlanWindow(QWidget):
    """The station plan of one configuration (see the module docstring)."""

    def __init__(self, plan: Plan, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.plan = plan
        self.setWindowTitle(f"Station plan - {plan.file}")
        self.resize(1100, 640)
        layout = QVBoxLayout(self)
        filters = QHBoxLayout()
        self.radio_filter = QComboBox(self)
        self.radio_filter.addItem("All radios", None)
        for ref in plan.radios:
            self.radio_filter.addItem(_radio(ref), ref)
        self.band_filter = QComboBox(self)
        self.band_filter.addItem("All bands", None)
        for band in plan.bands:
            self.band_filter.addItem(f"{band.name} ({band.probe:g} kHz)", band.name)
        filters.addWidget(QLabel("Radio", self))
        filters.addWidget(self.radio_filter)
        filters.addWidget(QLabel("Band", self))
        filters.addWidget(self.band_filter)
        filters.addStretch(1)
        self.count_label = QLabel(self)
        filters.addWidget(self.count_label)
        layout.addLayout(filters)

        self.table = QTableWidget(0, len(COLUMNS), self)
        self.table.setHorizontalHeaderLabels(COLUMNS)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().hide()
        self._rows: list[tuple[frozenset[RadioRef], frozenset[str]]] = []
        for o in plan.alone:
            self._add("alone", o, frozenset({o.radio}))
        for a, b, _meet, scenarios in plan.pairs:
            for s in scenarios:
                where = (f"{_radio(a)} + {_radio(b)}, both on {s.first.band}" if s.same_band
                         else f"{_radio(a)} on {s.first.band} + {_radio(b)} on {s.second.band}")
                bands = frozenset({s.first.band, s.second.band})
                for o in (s.first, s.second):
                    self._add(where, o, frozenset({a, b}), bands)
        self.table.resizeColumnsToContents()
        layout.addWidget(self.table, 3)

        layout.addWidget(QLabel(f"Findings ({len(plan.findings)})", self))
        self.findings = QTableWidget(len(plan.findings), len(FINDING_COLUMNS), self)
        self.findings.setHorizontalHeaderLabels(FINDING_COLUMNS)
        self.findings.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.findings.verticalHeader().hide()
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
        layout.addWidget(self.findings, 1)

        self.radio_filter.currentIndexChanged.connect(lambda _i: self.apply_filters())
        self.band_filter.currentIndexChanged.connect(lambda _i: self.apply_filters())
        self.apply_filters()

    def _add(self, scenario: str, o: Outcome, radios: frozenset[RadioRef],
             bands: frozenset[str] | None = None) -> None:
        row = self.table.rowCount()
        self.table.insertRow(row)
        inhibited = o.inhibited_by or (o.note if o.inhibited else "")
        why = o.text + ("".join(f"\n{self.plan.name(a)} {r}" for a, r in o.passed_over))
        values = (scenario, o.band, _radio(o.radio), self.plan.name(o.tx), self.plan.name(o.rx),
                  o.rule, o.text, inhibited)
        for column, value in enumerate(values):
            item = QTableWidgetItem(value)
            item.setToolTip(why if column == 6 else value)
            self.table.setItem(row, column, item)
        self._rows.append((radios, bands if bands is not None else frozenset({o.band})))

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
