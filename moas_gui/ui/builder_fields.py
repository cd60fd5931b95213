"""The builder's forms: one widget per field of a list (moas_gui.builder.fields says which
kind each is and quotes the manual for its tooltip), a form per group, and a table with
its form for each list of groups.

Every widget reads its value from the document and writes each change through it (one
undo step per change); nothing here keeps a copy of the file.  A widget the user is
typing in is not overwritten by a refresh.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from moas_gui.builder import Document, EditError
from moas_gui.builder.fields import FieldSpec
from moas_gui.builder.spans import Path
from moas_gui.builder.views import label_of

from .qt import (
    QAbstractItemView,
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    Qt,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

NOT_SET = "(not set)"


@dataclass(slots=True)
class Choices:
    """What the pickers offer, read from the draft at each refresh."""

    antennas: list[tuple[int, str]] = field(default_factory=list)
    rotators: list[tuple[int, str]] = field(default_factory=list)
    templates: list[str] = field(default_factory=list)
    functions: list[tuple[int, str]] = field(default_factory=list)
    systems: list[tuple[int, str]] = field(default_factory=list)
    radios: list[tuple[int, int]] = field(default_factory=list)

    @classmethod
    def of(cls, doc: Document) -> Choices:
        data = doc.get(())
        data = data if isinstance(data, dict) else {}

        def listed(key: str) -> list[dict[str, Any]]:
            value = data.get(key)
            return [v for v in value if isinstance(v, dict)] if isinstance(value, list) else []

        def ids(key: str, name: Callable[[dict[str, Any]], str]) -> list[tuple[int, str]]:
            return [(v["ID"], name(v)) for v in listed(key) if isinstance(v.get("ID"), int)]
        return cls(
            ids("Antennas", label_of),
            ids("Rotators", lambda v: str(v.get("ShortName") or v.get("LongName") or "")),
            [str(v["Name"]) for v in listed("Templates") if isinstance(v.get("Name"), str)],
            ids("Functions", lambda v: str(v.get("ShortName") or v.get("Name") or "")),
            ids("Systems", lambda v: str(v.get("DisplayName") or "")),
            [(v["Station"], v["Radio"]) for v in listed("Radios")
             if isinstance(v.get("Station"), int) and isinstance(v.get("Radio"), int)])

    def stations(self) -> list[int]:
        return sorted({s for s, _ in self.radios})


class Editor:
    """What every field widget shares: the document, the choices and where to say things."""

    def __init__(self, doc: Document, say: Callable[[str], None]) -> None:
        self.doc = doc
        self.say = say
        self.choices = Choices.of(doc)

    def refresh_choices(self) -> None:
        self.choices = Choices.of(self.doc)

    def write(self, path: Path, value: object, what: str) -> None:
        """Set (or, for None, remove) the value at ``path``; a refusal is said, not raised."""
        try:
            if value is None:
                if self.doc.has(path):
                    self.doc.remove(path, what)
            else:
                self.doc.set(path, value, what)
        except EditError as exc:
            self.say(str(exc))


def _words(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, list):
        return ", ".join(_words(v) for v in value)
    return str(value)


class FieldWidget(QWidget):
    """One field of a group: ``base`` (the group's path) + the spec's key."""

    def __init__(self, spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.spec = spec
        self.editor = editor
        self.base: Path = ()
        self.setToolTip(spec.tooltip())
        self.row = QHBoxLayout(self)
        self.row.setContentsMargins(0, 0, 0, 0)

    @property
    def path(self) -> Path:
        return (*self.base, self.spec.key)

    def value(self) -> object:
        return self.editor.doc.get(self.path)

    def load(self) -> None:
        raise NotImplementedError

    def write(self, value: object) -> None:
        self.editor.write(self.path, value, f"{self.spec.key}: {_words(value) or NOT_SET}")

    def show_path(self, rest: Path) -> QWidget | None:
        self.setFocus()
        return self


class LineField(FieldWidget):
    """Numbers, texts and lists of them, typed."""

    def __init__(self, spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(spec, editor, parent)
        self.edit = QLineEdit(self)
        self.edit.setToolTip(spec.tooltip())
        self.edit.setPlaceholderText(self._hint())
        self.row.addWidget(self.edit)
        self.edit.editingFinished.connect(self._finished)
        self.setFocusProxy(self.edit)

    def _hint(self) -> str:
        return {"relays": "relay numbers, e.g. 0, 19", "ints": "numbers, e.g. 1, 2",
                "texts": "texts, separated by commas", "number": "kHz" if "requency" in
                self.spec.key else "a number"}.get(self.spec.kind, "")

    def load(self) -> None:
        if self.edit.hasFocus() and self.edit.isModified():
            return
        self.edit.setText(_words(self.value()))
        self.edit.setModified(False)

    def parse(self, text: str) -> object:
        """The typed text as the field's value (:class:`ValueError` with the reason)."""
        text = text.strip()
        if not text:
            return None
        kind = self.spec.kind
        if kind == "text":
            return text
        if kind == "texts":
            return [t.strip() for t in text.split(",") if t.strip()]
        if kind in ("relays", "ints"):
            return [int(t) for t in text.replace(";", ",").split(",") if t.strip()]
        if kind == "number":
            number = float(text)
            return int(number) if number.is_integer() else number
        return int(text)

    def _finished(self) -> None:
        if not self.edit.isModified():
            return
        self.edit.setModified(False)
        try:
            value = self.parse(self.edit.text())
        except ValueError:
            self.editor.say(f"{self.spec.key}: {self.edit.text()!r} is not "
                            f"{'numbers' if self.spec.kind in ('relays', 'ints') else 'a number'}")
            return
        if value != self.value():
            self.write(value)


class ComboField(FieldWidget):
    """One value of a few: true/false, a choice, or a picked antenna, rotator, template,
    function, station or radio (shown by name, written as the file wants it)."""

    def __init__(self, spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(spec, editor, parent)
        self.combo = QComboBox(self)
        self.combo.setToolTip(spec.tooltip())
        self.row.addWidget(self.combo, 1)
        self.combo.activated.connect(self._picked)
        self.setFocusProxy(self.combo)

    def options(self) -> list[tuple[str, object]]:
        kind, c = self.spec.kind, self.editor.choices
        if kind == "bool":
            return [("true", True), ("false", False)]
        if kind == "choice":
            return [(x, x) for x in self.spec.choices]
        if kind == "template":
            return [(x, x) for x in c.templates]
        if kind == "station":
            return [(f"station {s}", s) for s in c.stations()]
        if kind == "radio":
            station = self.editor.doc.get((*self.base, "Station"))
            numbers = sorted({r for s, r in c.radios if station is None or s == station})
            return [(f"radio {r}", r) for r in numbers]
        if kind == "target":
            kind = "function" if self.editor.doc.get((*self.base, "Type")) == "Function" else "antenna"
        table = {"antenna": c.antennas, "rotator": c.rotators, "function": c.functions}[kind]
        return [(f"{i} {name}".rstrip(), i) for i, name in table]

    def load(self) -> None:
        value = self.value()
        options = [(NOT_SET, None), *self.options()]
        if value is not None and value not in [v for _, v in options]:
            options.append((f"{_words(value)} (not in the file's lists)", value))
        self.combo.blockSignals(True)
        self.combo.clear()
        for text, data in options:
            self.combo.addItem(text, data)
        index = next((i for i, (_, v) in enumerate(options)
                      if v == value and type(v) is type(value)), 0)
        self.combo.setCurrentIndex(index)
        self.combo.blockSignals(False)

    def _picked(self, index: int) -> None:
        value = self.combo.itemData(index)
        if value != self.value() or type(value) is not type(self.value()):
            self.write(value)


class PickManyField(FieldWidget):
    """Several antennas, systems or radios, ticked in a list (the file's order kept, new
    ones added at the end)."""

    def __init__(self, spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(spec, editor, parent)
        self.list = QListWidget(self)
        self.list.setToolTip(spec.tooltip())
        self.list.setMaximumHeight(58)
        self.list.setFlow(QListWidget.Flow.LeftToRight)
        self.list.setWrapping(True)
        self.row.addWidget(self.list, 1)
        self.list.itemChanged.connect(self._ticked)
        self.setFocusProxy(self.list)
        self._loading = False

    def options(self) -> list[tuple[str, object]]:
        c = self.editor.choices
        if self.spec.kind == "refs":
            return [(f"{s}/{r}", {"Station": s, "Radio": r}) for s, r in c.radios]
        table = c.systems if self.spec.kind == "systems" else c.antennas
        return [(f"{i} {name}".rstrip(), i) for i, name in table]

    def load(self) -> None:
        value = self.value()
        chosen = value if isinstance(value, list) else []
        options = self.options()
        options += [(f"{_words(v)} (not in the file's lists)", v) for v in chosen
                    if v not in [o for _, o in options]]
        self._loading = True
        self.list.clear()
        for text, data in options:
            item = QListWidgetItem(text, self.list)
            item.setData(Qt.ItemDataRole.UserRole, data)
            item.setFlags(item.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            item.setCheckState(Qt.CheckState.Checked if data in chosen else Qt.CheckState.Unchecked)
        self._loading = False

    def _ticked(self, item: QListWidgetItem) -> None:
        if self._loading:
            return
        value = self.value()
        chosen = list(value) if isinstance(value, list) else []
        data = item.data(Qt.ItemDataRole.UserRole)
        if item.checkState() == Qt.CheckState.Checked and data not in chosen:
            chosen.append(data)
        elif item.checkState() != Qt.CheckState.Checked and data in chosen:
            chosen.remove(data)
        self.write(chosen)


class GroupsField(FieldWidget):
    """A list of groups inside a group (Control, Stations, Matrix, Buttons, ...)."""

    def __init__(self, spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(spec, editor, parent)
        self.groups = GroupList(spec.fields, spec.columns, editor, spec.key, self,
                                new=lambda: dict(spec.new))
        self.row.addWidget(self.groups)

    def load(self) -> None:
        self.groups.set_path(self.path)

    def show_path(self, rest: Path) -> QWidget | None:
        return self.groups.show_path(rest)


def field_widget(spec: FieldSpec, editor: Editor, parent: QWidget | None = None) -> FieldWidget:
    if spec.kind == "groups":
        return GroupsField(spec, editor, parent)
    if spec.kind in ("antennas", "systems", "refs"):
        return PickManyField(spec, editor, parent)
    if spec.kind in ("bool", "choice", "template", "station", "radio", "antenna", "rotator",
                     "function", "target"):
        return ComboField(spec, editor, parent)
    return LineField(spec, editor, parent)


class GroupForm(QWidget):
    """The fields of one group, at ``base``; names the file has and no field shows are
    listed (kept as they are)."""

    def __init__(self, specs: tuple[FieldSpec, ...], editor: Editor,
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.editor = editor
        self.base: Path = ()
        layout = QFormLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        self.fields: dict[str, FieldWidget] = {}
        for spec in specs:
            widget = field_widget(spec, editor, self)
            label = QLabel(spec.key + (" *" if spec.required else ""), self)
            label.setToolTip(spec.tooltip())
            layout.addRow(label, widget)
            self.fields[spec.key] = widget
        self.others = QLabel(self)
        self.others.setWordWrap(True)
        layout.addRow(self.others)

    def set_base(self, base: Path) -> None:
        self.base = base
        for widget in self.fields.values():
            widget.base = base
        self.refresh()

    def refresh(self) -> None:
        for widget in self.fields.values():
            widget.load()
        value = self.editor.doc.get(self.base)
        extra = [k for k in value if k not in self.fields] if isinstance(value, dict) else []
        self.others.setText(("Also in the file, kept as they are: " + ", ".join(extra))
                            if extra else "")

    def show_path(self, rest: Path) -> QWidget | None:
        widget = self.fields.get(str(rest[0])) if rest else None
        if widget is None:
            return None
        inner = widget.show_path(rest[1:])
        return inner if inner is not None else widget


class GroupList(QWidget):
    """A list of groups: a table of its items (a few names as columns), buttons to add,
    remove and move them, and the selected item's form below."""

    def __init__(self, specs: tuple[FieldSpec, ...], columns: tuple[str, ...], editor: Editor,
                 what: str, parent: QWidget | None = None,
                 new: Callable[[], dict[str, object]] | None = None) -> None:
        super().__init__(parent)
        self.editor = editor
        self.what = what
        self.path: Path = ()
        self.columns = columns
        self.new = new or (dict)
        column = QVBoxLayout(self)
        column.setContentsMargins(0, 0, 0, 0)
        self.table = QTableWidget(0, len(columns) or 1, self)
        self.table.setHorizontalHeaderLabels(list(columns) or [what])
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setMaximumHeight(150)
        self.table.setMinimumHeight(96)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().setDefaultSectionSize(22)
        column.addWidget(self.table)
        buttons = QHBoxLayout()
        self.add_button = QPushButton("Add", self)
        self.remove_button = QPushButton("Remove", self)
        self.up_button = QPushButton("Up", self)
        self.down_button = QPushButton("Down", self)
        for button in (self.add_button, self.remove_button, self.up_button, self.down_button):
            buttons.addWidget(button)
        buttons.addStretch(1)
        column.addLayout(buttons)
        self.form = GroupForm(specs, editor, self)
        self.form.setVisible(False)
        column.addWidget(self.form)
        self.add_button.clicked.connect(self.add)
        self.remove_button.clicked.connect(self.remove)
        self.up_button.clicked.connect(lambda: self.move_item(-1))
        self.down_button.clicked.connect(lambda: self.move_item(1))
        self.table.itemSelectionChanged.connect(self._selected)

    def set_path(self, path: Path) -> None:
        changed = path != self.path
        self.path = path
        self.refresh(keep=not changed)

    def items(self) -> list[object]:
        return self.editor.doc.items(self.path)

    def current(self) -> int:
        rows = self.table.selectionModel().selectedRows()
        return rows[0].row() if rows else -1

    def refresh(self, keep: bool = True) -> None:
        items = self.items()
        selected = self.current() if keep else -1
        self.table.blockSignals(True)
        self.table.setRowCount(len(items))
        for row, item in enumerate(items):
            for col, key in enumerate(self.columns or ("",)):
                value = item.get(key) if isinstance(item, dict) and key else item
                self.table.setItem(row, col, QTableWidgetItem(_words(value)))
        if 0 <= selected < len(items):
            self.table.selectRow(selected)
        else:
            self.table.clearSelection()
            selected = -1
        self.table.blockSignals(False)
        self._show_form(selected)

    def _selected(self) -> None:
        self._show_form(self.current())

    def _show_form(self, row: int) -> None:
        self.form.setVisible(row >= 0)
        self.remove_button.setEnabled(row >= 0)
        self.up_button.setEnabled(row > 0)
        self.down_button.setEnabled(0 <= row < len(self.items()) - 1)
        if row >= 0:
            self.form.set_base((*self.path, row))

    def select(self, row: int) -> None:
        if 0 <= row < self.table.rowCount():
            self.table.selectRow(row)
            self._show_form(row)

    def add(self) -> None:
        value = dict(self.new())
        specs = self.form.fields
        if "ID" in specs and specs["ID"].spec.kind == "int" and "ID" not in value:
            taken = [i.get("ID") for i in self.items() if isinstance(i, dict)]
            value = {"ID": max([t for t in taken if isinstance(t, int)], default=-1) + 1, **value}
        try:
            self.editor.doc.append(self.path, value, f"add to {self.what}")
        except EditError as exc:
            self.editor.say(str(exc))
            return
        self.refresh()
        self.select(len(self.items()) - 1)

    def remove(self) -> None:
        row = self.current()
        if row >= 0:
            self.editor.write((*self.path, row), None, f"remove item {row + 1} of {self.what}")

    def move_item(self, step: int) -> None:
        row = self.current()
        if row >= 0 and 0 <= row + step < len(self.items()):
            self.editor.doc.move(self.path, row, row + step)
            self.select(row + step)

    def show_path(self, rest: Path) -> QWidget:
        """Select the item ``rest`` starts with and show its field; returns the widget
        shown (to scroll to)."""
        if rest and isinstance(rest[0], int):
            self.select(rest[0])
            shown = self.form.show_path(rest[1:])
            return shown if shown is not None else self.form
        self.table.setFocus()
        return self.table


__all__ = ["Choices", "Editor", "FieldWidget", "GroupForm", "GroupList", "field_widget"]
