"""The builder's pages beyond the lists: the new-station guide, the station at a glance
(band x antenna grid, relay map, layout preview) and what-if by the real engine.

Each page reads the document when it is shown or the document changes (``refresh``)
and writes through it.  What asks the engine runs off the window's thread
(:class:`Worker`); menus open with ``popup()``, never ``exec()``.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future
from typing import Any

from moas_gui.builder import Document, RadioRef
from moas_gui.builder.guide import (
    BAND_EDGES,
    Guide,
    GuideAntenna,
    GuideRadio,
    GuideSwitch,
    apply_guide,
)
from moas_gui.builder.views import (
    PreviewButton,
    RelayMap,
    band_grid,
    layout_bands,
    layout_preview,
    move_button,
    relay_map,
    set_band_radio,
    switches_of,
)

from .qt import (
    QAbstractItemView,
    QBrush,
    QCheckBox,
    QColor,
    QComboBox,
    QCursor,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QMenu,
    QObject,
    QPlainTextEdit,
    QPushButton,
    QSpinBox,
    QTableWidget,
    QTableWidgetItem,
    QTimer,
    QVBoxLayout,
    QWidget,
    Signal,
)

FLAGGED = QColor(255, 205, 205)
UNUSED = QColor(225, 225, 225)
USABLE = QColor(215, 240, 215)


class Worker(QObject):
    """Runs a function on a thread of its own and hands its result to the window's thread;
    only the newest job's result is delivered.  The thread touches no Qt object: it fills
    a future, which a timer of the window's thread looks at (so a window closed meanwhile
    is never reached from the thread)."""

    POLL_MS = 40

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.job = 0
        self._waiting: tuple[int, Future[Any], Callable[[Any], None]] | None = None
        self._timer = QTimer(self)
        self._timer.setInterval(self.POLL_MS)
        self._timer.timeout.connect(self._look)

    def run(self, work: Callable[[], Any], then: Callable[[Any], None]) -> int:
        self.job += 1
        future: Future[Any] = Future()

        def body() -> None:
            try:
                future.set_result(work())
            except Exception as exc:  # noqa: BLE001 (said on the page, never lost)
                future.set_result(exc)
        self._waiting = (self.job, future, then)
        threading.Thread(target=body, name="builder-worker", daemon=True).start()
        self._timer.start()
        return self.job

    @property
    def busy(self) -> bool:
        return self._waiting is not None

    def _look(self) -> None:
        waiting = self._waiting
        if waiting is None:
            self._timer.stop()
            return
        job, future, then = waiting
        if not future.done():
            return
        self._waiting = None
        self._timer.stop()
        if job == self.job:
            then(future.result())


class Page(QWidget):
    """A page of the builder (its ``refresh`` reads the document again)."""

    def __init__(self, doc: Document, say: Callable[[str], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.say = say

    def refresh(self) -> None:
        raise NotImplementedError


class GuidePage(Page):
    """A new station in minutes: radios and their switch ports, the switch, the antennas on
    the antenna switch's outputs with their bands."""

    made = Signal()

    def __init__(self, doc: Document, say: Callable[[str], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(doc, say, parent)
        column = QVBoxLayout(self)
        column.addWidget(QLabel("<b>A new station.</b> Say which radios there are and which "
                                "switch port (1-6, the keying and inhibit connectors) each is "
                                "wired to, the switch's serial port, and the antennas on the "
                                "antenna switch's outputs with their bands. The relays are laid "
                                "out as docs/configuration.md section 3 advises; everything can "
                                "be changed on the pages afterwards.", self))
        _wrap_first(column)
        row = QHBoxLayout()
        row.addWidget(QLabel("Switch serial port:", self))
        self.port = QLineEdit("emulator", self)
        self.port.setToolTip('The serial port ("COM8", "/dev/ttyUSB0") or "emulator" (6.11)')
        row.addWidget(self.port)
        row.addWidget(QLabel("Antenna switch outputs per radio:", self))
        self.outputs = QSpinBox(self)
        self.outputs.setRange(1, 32)
        self.outputs.setValue(6)
        self.outputs.setToolTip("A 2x6 antenna switch has 6 outputs: radio 1 gets relays 0-5, "
                                "radio 2 relays 6-11 (docs/configuration.md section 3)")
        row.addWidget(self.outputs)
        column.addLayout(row)
        self.radios = self._table(["Station", "Radio", "Switch port"],
                                  [["1", "1", "1"], ["1", "2", "2"]])
        column.addWidget(QLabel("Radios:", self))
        column.addWidget(self.radios)
        column.addLayout(self._buttons(self.radios, ["1", "1", "1"]))
        self.antennas = self._table(["Name", "Output", "Bands"],
                                    [["Tribander", "1", "20 m, 15 m, 10 m"], ["Dipole", "2", "40 m"]])
        self.antennas.setToolTip("Bands by name: " + ", ".join(b[0] for b in BAND_EDGES))
        column.addWidget(QLabel("Antennas (bands by name, e.g. 20 m, 15 m):", self))
        column.addWidget(self.antennas)
        column.addLayout(self._buttons(self.antennas, ["New antenna", "1", "20 m"]))
        self.make = QPushButton("Make the station", self)
        self.make.clicked.connect(self.apply)
        column.addWidget(self.make)
        self.problems = QLabel(self)
        self.problems.setWordWrap(True)
        column.addWidget(self.problems)
        column.addStretch(1)

    def _table(self, headers: list[str], rows: list[list[str]]) -> QTableWidget:
        table = QTableWidget(0, len(headers), self)
        table.setHorizontalHeaderLabels(headers)
        table.horizontalHeader().setStretchLastSection(True)
        table.setMaximumHeight(140)
        for values in rows:
            self._add_row(table, values)
        return table

    def _add_row(self, table: QTableWidget, values: list[str]) -> None:
        row = table.rowCount()
        table.setRowCount(row + 1)
        for col, text in enumerate(values):
            table.setItem(row, col, QTableWidgetItem(text))

    def _buttons(self, table: QTableWidget, blank: list[str]) -> QHBoxLayout:
        row = QHBoxLayout()
        add, remove = QPushButton("Add", self), QPushButton("Remove", self)
        add.clicked.connect(lambda: self._add_row(table, blank))
        remove.clicked.connect(lambda: table.removeRow(max(table.currentRow(), 0))
                               if table.rowCount() else None)
        row.addWidget(add)
        row.addWidget(remove)
        row.addStretch(1)
        return row

    def cells(self, table: QTableWidget) -> list[list[str]]:
        def text(row: int, col: int) -> str:
            item = table.item(row, col)
            return item.text().strip() if item is not None else ""
        return [[text(r, c) for c in range(table.columnCount())] for r in range(table.rowCount())]

    def guide(self) -> Guide:
        """The answers as a :class:`Guide` (:class:`ValueError` for one that is not a number
        or a band)."""
        names = {b[0].replace(" ", ""): (b[1], b[2]) for b in BAND_EDGES}
        radios = [GuideRadio(int(s), int(r), int(p)) for s, r, p in self.cells(self.radios)]
        antennas = []
        for index, (name, output, bands) in enumerate(self.cells(self.antennas)):
            edges = []
            for word in (w.strip().replace(" ", "") for w in bands.split(",") if w.strip()):
                if word not in names:
                    raise ValueError(f"{word!r} is not a band (write e.g. 20 m)")
                edges.append(names[word])
            antennas.append(GuideAntenna(index, name or f"Antenna {index}", int(output), tuple(edges)))
        return Guide(radios, antennas, [GuideSwitch(1, self.port.text().strip() or "emulator")],
                     outputs=self.outputs.value())

    def apply(self) -> None:
        try:
            apply_guide(self.doc, self.guide())
        except ValueError as exc:
            self.problems.setText(f"Not made yet: {exc}")
            return
        self.problems.setText("")
        self.say("The station is made: see the pages, and the findings below")
        self.made.emit()

    def refresh(self) -> None:
        self.make.setEnabled(not self.doc.items(("Radios",)))


class GridPage(Page):
    """Band x antenna: which radios can use each antenna on each band, to transmit and to
    receive; a click on a cell offers the radios to tick."""

    def __init__(self, doc: Document, say: Callable[[str], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(doc, say, parent)
        column = QVBoxLayout(self)
        column.addWidget(QLabel("For each antenna and band, the radios that can use it (RX or "
                                "TX when only one way). Click a cell to add or take away a "
                                "radio; a new one needs its relays on the Antennas page.", self))
        _wrap_first(column)
        self.table = QTableWidget(self)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.cellClicked.connect(self.offer)
        column.addWidget(self.table)
        self.menu: QMenu | None = None
        self.grid = band_grid(doc)

    def refresh(self) -> None:
        self.grid = grid = band_grid(self.doc)
        self.table.setRowCount(len(grid.antennas))
        self.table.setColumnCount(len(grid.bands))
        self.table.setHorizontalHeaderLabels([b[0] for b in grid.bands])
        self.table.setVerticalHeaderLabels([f"{ident} {name}" for _, ident, name in grid.antennas])
        for row, (index, _, _) in enumerate(grid.antennas):
            for col, band in enumerate(grid.bands):
                cell = QTableWidgetItem(grid.cells[(index, band[0])].text())
                if cell.text():
                    cell.setBackground(QBrush(USABLE))
                self.table.setItem(row, col, cell)
        self.table.resizeColumnsToContents()
        for col in range(len(grid.bands)):
            self.table.setColumnWidth(col, max(self.table.columnWidth(col), 56))

    def offer(self, row: int, col: int) -> None:
        grid = self.grid
        if not (0 <= row < len(grid.antennas) and 0 <= col < len(grid.bands)):
            return
        index, band = grid.antennas[row][0], grid.bands[col]
        cell = grid.cells[(index, band[0])]
        self.menu = QMenu(self)
        for ref in grid.radios:
            action = self.menu.addAction(f"station {ref.station} radio {ref.radio}")
            action.setCheckable(True)
            action.setChecked(ref in cell.tx or ref in cell.rx)
            action.toggled.connect(lambda on, r=ref: self.toggle(index, band, r, on))
        self.menu.popup(QCursor.pos())

    def toggle(self, index: int, band: tuple[str, float, float], ref: RadioRef, on: bool) -> None:
        said = set_band_radio(self.doc, index, band, ref, on)
        if said:
            self.say(said)


class RelayPage(Page):
    """Each switch's 64 relays against its ports: which antenna each relay selects for the
    radio on that port; relays never used greyed, relays shared where they should not be
    in red with the reason."""

    def __init__(self, doc: Document, say: Callable[[str], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(doc, say, parent)
        column = QVBoxLayout(self)
        row = QHBoxLayout()
        row.addWidget(QLabel("Switch:", self))
        self.switch = QComboBox(self)
        self.switch.activated.connect(lambda _i: self.refresh())
        row.addWidget(self.switch)
        self.summary = QLabel(self)
        row.addWidget(self.summary, 1)
        column.addLayout(row)
        self.table = QTableWidget(64, 7, self)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().setDefaultSectionSize(20)
        column.addWidget(self.table)

    def refresh(self) -> None:
        switches = switches_of(self.doc)
        chosen = self.switch.currentData()
        self.switch.clear()
        for s in switches:
            self.switch.addItem(f"switch {s}", s)
        self.switch.setCurrentIndex(switches.index(chosen) if chosen in switches else 0)
        found = relay_map(self.doc, switches[self.switch.currentIndex()])
        headers = [f"port {p}: {found.ports[p].station}/{found.ports[p].radio}"
                   if p in found.ports else f"port {p}" for p in range(1, 7)]
        self.table.setHorizontalHeaderLabels([*headers, "note"])
        relays = found.relays()
        self.table.setVerticalHeaderLabels([str(r) for r in relays])
        for row, relay in enumerate(relays):
            self._row(row, relay, found)
        self.table.resizeColumnsToContents()
        for col in range(6):
            self.table.setColumnWidth(col, min(max(self.table.columnWidth(col), 70), 190))
        shared = sum(1 for f in found.flags.values() if f.startswith("shared"))
        unused = sum(1 for f in found.flags.values() if f == "never used")
        self.summary.setText(f"{64 - unused} relays used, {unused} never used, "
                             f"{shared} shared where they should not be")

    def _row(self, row: int, relay: int, found: RelayMap) -> None:
        """One relay: what it selects for the radio of each port, and its note."""
        uses = found.uses[relay]
        flag = found.flags.get(relay, "")
        texts = []
        for port in range(1, 7):
            ref = found.ports.get(port)
            texts.append("; ".join(sorted({f"{u.label} {u.band}" + (
                "" if u.kind == "Relays" else f" ({u.kind})") for u in uses if u.radio == ref})))
        others = sorted({f"{u.label} {u.band}" for u in uses if u.radio not in found.ports.values()})
        texts.append(flag or "; ".join(others))
        color = FLAGGED if flag.startswith("shared") else UNUSED if flag else None
        for col, text in enumerate(texts):
            cell = QTableWidgetItem(text)
            cell.setToolTip(text)
            if color is not None:
                cell.setBackground(QBrush(color))
            self.table.setItem(row, col, cell)


class LayoutPage(Page):
    """Each layout's buttons as the client draws them, band by band; pick a button and
    move it with the arrows (a button already there takes its place)."""

    def __init__(self, doc: Document, say: Callable[[str], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(doc, say, parent)
        column = QVBoxLayout(self)
        row = QHBoxLayout()
        self.layout_box = QComboBox(self)
        self.band = QComboBox(self)
        self.layout_box.activated.connect(lambda _i: self.refresh())
        self.band.activated.connect(lambda _i: self.refresh())
        row.addWidget(QLabel("Layout:", self))
        row.addWidget(self.layout_box)
        row.addWidget(QLabel("Band:", self))
        row.addWidget(self.band)
        self.arrows: dict[str, QPushButton] = {}
        for name, step in (("Left", (0, -1)), ("Right", (0, 1)), ("Up", (-1, 0)), ("Down", (1, 0))):
            button = QPushButton(name, self)
            button.clicked.connect(lambda _c=False, s=step: self.step(*s))
            self.arrows[name] = button
            row.addWidget(button)
        row.addStretch(1)
        column.addLayout(row)
        self.area = QWidget(self)
        self.grid = QGridLayout(self.area)
        column.addWidget(self.area, 1)
        self.buttons: list[tuple[QPushButton, PreviewButton]] = []
        self.picked: PreviewButton | None = None
        self.dims = (1, 1)

    def refresh(self) -> None:
        layouts = self.doc.count(("Layout",))
        chosen = max(self.layout_box.currentIndex(), 0)
        self.layout_box.clear()
        for i in range(layouts):
            value = self.doc.get(("Layout", i))
            who = ""
            if isinstance(value, dict) and "Station" in value:
                who = f" (station {value.get('Station')} radio {value.get('Radio', 'any')})"
            self.layout_box.addItem(f"layout {i + 1}{who}", i)
        if not layouts:
            self._draw(0, 0, [])
            return
        self.layout_box.setCurrentIndex(min(chosen, layouts - 1))
        bands = layout_bands(self.doc, self.layout_box.currentIndex()) or ["all bands"]
        band = self.band.currentText()
        self.band.clear()
        self.band.addItems(bands)
        self.band.setCurrentIndex(bands.index(band) if band in bands else 0)
        rows, columns, buttons = layout_preview(self.doc, self.layout_box.currentIndex(),
                                                self.band.currentText())
        self._draw(rows, columns, buttons)

    def _draw(self, rows: int, columns: int, buttons: list[PreviewButton]) -> None:
        while self.grid.count():
            item = self.grid.takeAt(0)
            old = item.widget() if item is not None else None
            if old is not None:
                old.hide()
                old.deleteLater()
        self.buttons = []
        self.dims = (rows, columns)
        for button in buttons:
            widget = QPushButton(button.label, self.area)
            widget.setCheckable(True)
            widget.setMinimumHeight(40)
            widget.setToolTip(f"{button.kind} {button.id}: row {button.row + 1}, "
                              f"column {button.column + 1}")
            same = self.picked is not None and (self.picked.matrix, self.picked.index) == \
                (button.matrix, button.index)
            widget.setChecked(same)
            widget.clicked.connect(lambda _c=False, b=button: self.pick(b))
            self.grid.addWidget(widget, button.row, button.column)
            self.buttons.append((widget, button))
        for r in range(rows):
            self.grid.setRowStretch(r, 1)
        for c in range(columns):
            self.grid.setColumnStretch(c, 1)

    def pick(self, button: PreviewButton) -> None:
        self.picked = button
        for widget, shown in self.buttons:
            widget.setChecked(shown == button)

    def step(self, rows: int, columns: int) -> None:
        picked = self.picked
        if picked is None:
            self.say("Pick a button first, then move it")
            return
        row, column = picked.row + rows, picked.column + columns
        if not (0 <= row < self.dims[0] and 0 <= column < self.dims[1]):
            return
        move_button(self.doc, self.layout_box.currentIndex(), self.band.currentText(), picked,
                    row, column)
        self.picked = PreviewButton(row, column, picked.kind, picked.id, picked.label,
                                    picked.matrix, picked.index)


class WhatIfPage(Page):
    """Pick radios and frequencies (and who transmits) and see the engine's choice with its
    why, from a fresh engine built from the draft; and the draft's station plan."""

    def __init__(self, doc: Document, say: Callable[[str], None],
                 show_plan: Callable[[Any], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(doc, say, parent)
        self.show_plan = show_plan
        self.worker = Worker(self)
        column = QVBoxLayout(self)
        column.addWidget(QLabel("Tick the radios to tune, give each a frequency in kHz (they tune "
                                "in this order) and tick those that transmit. A fresh engine "
                                "built from the draft answers: the running station is not "
                                "touched.", self))
        _wrap_first(column)
        self.table = QTableWidget(0, 3, self)
        self.table.setHorizontalHeaderLabels(["radio", "kHz", "transmits"])
        self.table.setMaximumHeight(170)
        column.addWidget(self.table)
        row = QHBoxLayout()
        self.ask_button = QPushButton("Ask the engine", self)
        self.ask_button.clicked.connect(self.ask)
        self.plan_button = QPushButton("Station plan of the draft", self)
        self.plan_button.clicked.connect(self.plan)
        row.addWidget(self.ask_button)
        row.addWidget(self.plan_button)
        row.addStretch(1)
        column.addLayout(row)
        self.answer = QPlainTextEdit(self)
        self.answer.setReadOnly(True)
        column.addWidget(self.answer, 1)
        self.rows: list[tuple[RadioRef, QCheckBox, QLineEdit, QCheckBox]] = []

    def refresh(self) -> None:
        refs = [RadioRef(r["Station"], r["Radio"]) for r in self.doc.items(("Radios",))
                if isinstance(r, dict) and isinstance(r.get("Station"), int)
                and isinstance(r.get("Radio"), int)]
        if [r for r, *_ in self.rows] == refs:
            return
        self.table.setRowCount(len(refs))
        self.rows = []
        for i, ref in enumerate(refs):
            use, khz, keyed = QCheckBox(f"{ref.station}/{ref.radio}", self), QLineEdit(self), QCheckBox(self)
            khz.setPlaceholderText("e.g. 14025")
            self.table.setCellWidget(i, 0, use)
            self.table.setCellWidget(i, 1, khz)
            self.table.setCellWidget(i, 2, keyed)
            self.rows.append((ref, use, khz, keyed))

    def scenario(self) -> tuple[list[tuple[RadioRef, float]], list[RadioRef]]:
        tunings = []
        for ref, use, khz, _ in self.rows:
            if use.isChecked():
                tunings.append((ref, float(khz.text())))
        return tunings, [ref for ref, _, _, keyed in self.rows if keyed.isChecked()]

    def ask(self) -> None:
        try:
            tunings, keyed = self.scenario()
        except ValueError:
            self.answer.setPlainText("Each ticked radio needs a frequency in kHz, such as 14025.")
            return
        self.answer.setPlainText("Asking the engine...")
        text, name = self.doc.text, self._name()
        self.worker.run(lambda: _what_if(text, name, tunings, keyed), self._answered)

    def _name(self) -> str:
        return self.doc.path.name if self.doc.path else "new station"

    def _answered(self, result: Any) -> None:
        self.answer.setPlainText(str(result) if not isinstance(result, Exception)
                                 else f"The engine could not answer: {result}")

    def plan(self) -> None:
        text, name = self.doc.text, self._name()
        self.say("Making the station plan of the draft...")
        self.worker.run(lambda: _plan(text, name), self._planned)

    def _planned(self, result: Any) -> None:
        if isinstance(result, str):
            self.say(result)
            return
        if isinstance(result, Exception):
            self.say(f"The station plan could not be made: {result}")
            return
        self.show_plan(result)


DRAFT_HAS_ERRORS = ("The draft has errors (see the findings): the engine is built from a file "
                    "the server would accept.")


def _what_if(text: str, name: str, tunings: list[tuple[RadioRef, float]],
             keyed: list[RadioRef]) -> str:
    """The engine's answers for the draft ``text`` as it is now (off the window's thread)."""
    from moas_gui.builder.checking import check_text
    from moas_gui.builder.whatif import answers_text, what_if

    config = check_text(text, name).config
    if config is None:
        return DRAFT_HAS_ERRORS
    return answers_text(what_if(config, tunings, keyed))


def _plan(text: str, name: str) -> Any:
    """The station plan of the draft ``text`` (or why there is none), off the window's thread."""
    from moas_gui.builder.checking import check_text
    from moas_gui.plan import build_plan

    config = check_text(text, name).config
    if config is None:
        return DRAFT_HAS_ERRORS
    return build_plan(config, name, text)


__all__ = ["GridPage", "GuidePage", "LayoutPage", "Page", "RelayPage", "WhatIfPage", "Worker"]


def _wrap_first(column: QVBoxLayout) -> None:
    """The column's first widget, its note, wraps its words."""
    item = column.itemAt(0)
    note = item.widget() if item is not None else None
    if isinstance(note, QLabel):
        note.setWordWrap(True)
