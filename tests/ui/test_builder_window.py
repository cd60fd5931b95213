"""The station builder's window under pytest-qt (offscreen): each page on a copy of an
example, the findings as links, saving (diff, questions, FILE.bak), the new-station
guide, one window per file, and Save and Restart through the server window."""

from __future__ import annotations

import shutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from client_support import run_on_qt
from helpers import until
from test_server_window import Harness

from moas_gui.builder.claims import release
from moas_gui.builder.fields import LISTS
from moas_gui.config import parse_config
from moas_gui.status import ServerState
from moas_gui.ui.builder_fields import ComboField, GroupsField, LineField, PickManyField
from moas_gui.ui.builder_pages import GridPage, LayoutPage, RelayPage, WhatIfPage
from moas_gui.ui.builder_window import BuilderWindow, ListPage, open_builder
from moas_gui.ui.qt import QApplication, QMenu, Qt

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


class Answers:
    """The window's questions, answered by the test."""

    def __init__(self) -> None:
        self.answers: list[bool] = []
        self.questions: list[str] = []
        self.diffs: list[str] = []

    def ask(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        self.questions.append(f"{title}: {text}")
        answered(self.answers.pop(0))

    def diff(self, diff: str, answered: Callable[[bool], None]) -> None:
        self.diffs.append(diff)
        answered(self.answers.pop(0))


@pytest.fixture
def station(tmp_path: Path) -> Path:
    path = tmp_path / "station.moas"
    shutil.copyfile(EXAMPLES / "small-station.moas", path)
    return path


@pytest.fixture
def window(qtbot: Any, station: Path) -> Iterator[tuple[BuilderWindow, Answers]]:
    said: list[str] = []
    opened = open_builder(station, None, said.append)
    assert opened is not None, said
    answers = Answers()
    opened.ask = answers.ask
    opened.show_diff = answers.diff
    yield opened, answers
    opened.closing_confirmed = True
    opened.close()
    release(station)


@pytest.fixture(scope="module")
def looked_at(qapp: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[BuilderWindow, Path]]:
    """One window on a copy of the small example, shared by the tests that only look at
    it (they move between pages and select rows, and edit nothing).  Its claim on the file
    lives in a state directory of its own (each test gets another one)."""
    folder = tmp_path_factory.mktemp("looked-at")
    station = folder / "station.moas"
    shutil.copyfile(EXAMPLES / "small-station.moas", station)
    with pytest.MonkeyPatch.context() as env:
        env.setenv("XDG_STATE_HOME", str(folder / "state"))
        said: list[str] = []
        opened = open_builder(station, None, said.append)
        assert opened is not None, said
        yield opened, station
        assert not opened.doc.can_undo, "a test that only looks edited the shared window's file"
        opened.closing_confirmed = True
        opened.close()
        release(station)


def list_page(window: BuilderWindow, title: str) -> ListPage:
    page = window.go(title)
    assert isinstance(page, ListPage)
    return page


def finish(field: LineField, text: str) -> None:
    field.edit.setText(text)
    field.edit.setModified(True)
    field.edit.editingFinished.emit()


def test_the_window_fits_1024_by_600(looked_at: tuple[BuilderWindow, Path]) -> None:
    builder, _ = looked_at
    for title in builder.pages:
        builder.go(title)
        hint = builder.minimumSizeHint()
        assert hint.width() <= 1024 and hint.height() <= 600, (title, hint)
    assert builder.width() <= 1024 and builder.height() <= 600


def test_a_page_is_made_when_it_is_first_shown(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    assert builder.stack.count() == len(builder.pages) == len(LISTS) + 5
    assert builder.stack.currentWidget() is builder.pages["Antennas"]
    assert not builder.pages.made("Rotators") and not builder.pages.made("Relay map")
    page = builder.go("Rotators")
    assert builder.pages.made("Rotators") and builder.stack.currentWidget() is page
    assert builder.stack.indexOf(page) == builder.nav.currentRow() == builder.pages.titles.index("Rotators")
    assert builder.stack.count() == len(builder.pages)
    builder.nav.setCurrentRow(builder.pages.titles.index("Relay map"))  # chosen in the list
    assert builder.stack.currentWidget() is builder.pages["Relay map"]
    assert isinstance(builder.stack.currentWidget(), RelayPage)


@pytest.mark.parametrize("spec", LISTS, ids=lambda s: s.title)
def test_every_list_has_a_page_whose_fields_quote_the_manual(
        looked_at: tuple[BuilderWindow, Path], spec: Any) -> None:
    builder, _ = looked_at
    page = list_page(builder, spec.title)
    if page.list is not None:
        count = builder.doc.count((spec.key,))
        assert page.list.table.rowCount() == count
        if count:
            page.list.select(0)
            assert page.list.form.isVisible() or not builder.isVisible()
        form = page.list.form
    else:
        assert page.form is not None
        form = page.form
    assert set(form.fields) == {f.key for f in spec.fields}
    for key, widget in form.fields.items():
        assert f"(MOAS II manual, section {spec.field(key).section})" in widget.toolTip(), key


def test_a_typed_value_changes_only_its_line_and_undo_takes_it_back(
        window: tuple[BuilderWindow, Answers], station: Path) -> None:
    builder, _ = window
    page = list_page(builder, "Antennas")
    assert page.list is not None
    page.list.select(0)
    short = page.list.form.fields["ShortName"]
    assert isinstance(short, LineField) and short.edit.text() == "Tribander"
    before = station.read_text(encoding="utf-8")
    finish(short, "Yagi")
    assert builder.doc.get(("Antennas", 0, "ShortName")) == "Yagi"
    assert builder.doc.text == before.replace('"ShortName": "Tribander"', '"ShortName": "Yagi"', 1)
    assert builder.windowTitle().endswith("*")
    assert page.list.table.item(0, 1).text() == "Yagi"
    builder.action_undo.trigger()
    assert builder.doc.text == before and short.edit.text() == "Tribander"
    builder.action_redo.trigger()
    assert builder.doc.get(("Antennas", 0, "ShortName")) == "Yagi"
    finish(short, "")
    assert not builder.doc.has(("Antennas", 0, "ShortName")), "emptied: the name is removed"


def test_pickers_offer_the_file_s_antennas_and_rotators(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = list_page(builder, "Antennas")
    assert page.list is not None
    page.list.select(0)
    rotator = page.list.form.fields["Rotator"]
    assert isinstance(rotator, ComboField)
    assert [rotator.combo.itemText(i) for i in range(rotator.combo.count())] == [
        "(not set)", "1 Tribander"]
    assert rotator.combo.currentText() == "1 Tribander"
    conflicts = page.list.form.fields["Conflicts"]
    assert isinstance(conflicts, PickManyField)
    names = [conflicts.list.item(i).text() for i in range(conflicts.list.count())]
    assert names == ["0 Tribander", "1 40 Dipole", "2 80 Dipole", "3 Vertical"]
    conflicts.list.item(3).setCheckState(Qt.CheckState.Checked)
    assert builder.doc.get(("Antennas", 0, "Conflicts")) == [0, 3]
    rotator.combo.setCurrentIndex(0)
    rotator.combo.activated.emit(0)
    assert not builder.doc.has(("Antennas", 0, "Rotator"))
    control = page.list.form.fields["Control"]
    assert isinstance(control, GroupsField)
    control.groups.select(1)
    stations = control.groups.form.fields["Stations"]
    assert isinstance(stations, GroupsField)
    stations.groups.select(1)
    relays = stations.groups.form.fields["Relays"]
    assert isinstance(relays, LineField) and relays.edit.text() == "4, 28"
    finish(relays, "4, 29")
    assert builder.doc.get(("Antennas", 0, "Control", 1, "Stations", 1, "Relays")) == [4, 29]
    radio = stations.groups.form.fields["Radio"]
    assert isinstance(radio, ComboField) and radio.combo.currentText() == "radio 2"


def test_a_new_item_inside_an_item_starts_with_what_it_needs(
        window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = list_page(builder, "Antennas")
    assert page.list is not None
    page.list.select(2)
    control = page.list.form.fields["Control"]
    assert isinstance(control, GroupsField)
    control.groups.add_button.click()
    assert builder.doc.get(("Antennas", 2, "Control", 1)) == {
        "LowerFrequency": 14000, "UpperFrequency": 14350, "Stations": []}
    stations = control.groups.form.fields["Stations"]
    assert isinstance(stations, GroupsField)
    stations.groups.add_button.click()
    assert builder.doc.get(("Antennas", 2, "Control", 1, "Stations")) == [
        {"Station": 1, "Radio": 1, "Relays": []}], "never an empty entry (every radio)"


def test_adding_and_removing_items(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = list_page(builder, "Rotators")
    assert page.list is not None
    page.list.add_button.click()
    assert builder.doc.get(("Rotators", 1)) == {"ID": 2, "Control": "Test"}
    assert page.list.current() == 1
    page.list.remove_button.click()
    assert builder.doc.count(("Rotators",)) == 1


def test_findings_appear_as_the_file_is_edited_and_lead_to_their_field(
        qtbot: Any, window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    builder.doc.set(("Antennas", 2, "Rotator"), 7)

    def found() -> Any:
        items = [builder.findings.item(i) for i in range(builder.findings.count())]
        return next((i for i in items if "uses rotator 7" in i.text()), None)
    qtbot.waitUntil(lambda: found() is not None, timeout=30000)
    item = found()
    assert item.text().endswith('error: antenna 2 uses rotator 7, which is not in "Rotators"')
    builder.go("Switches")
    builder.findings.itemClicked.emit(item)
    page = builder.stack.currentWidget()
    assert isinstance(page, ListPage) and page.spec.key == "Antennas"
    assert page.list is not None and page.list.current() == 2
    assert builder.show_field(item.data(Qt.ItemDataRole.UserRole).path) is page.list.form.fields["Rotator"]
    relays = builder.show_field(("Antennas", 3, "Control", 1, "Stations", 0, "Relays"))
    assert isinstance(relays, LineField) and relays.edit.text() == "3, 17"
    assert builder.show_field(("UseN1MMLogger",)) is not None
    assert isinstance(builder.stack.currentWidget(), ListPage)
    assert builder.stack.currentWidget().spec.title == "Miscellaneous"
    builder.doc.undo()
    qtbot.waitUntil(lambda: found() is None, timeout=30000)


def test_the_grid_page_edits_who_may_use_an_antenna(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = builder.go("Band x antenna")
    assert isinstance(page, GridPage)
    col = [page.table.horizontalHeaderItem(c).text() for c in range(page.table.columnCount())].index("40 m")
    assert page.table.item(0, col).text() == ""
    assert page.table.item(1, col).text() == "1/1 1/2"
    page.offer(0, col)
    assert page.menu is not None
    actions = page.menu.actions()
    assert [a.text() for a in actions] == ["station 1 radio 1", "station 1 radio 2"]
    actions[1].setChecked(True)
    assert page.table.item(0, col).text() == "1/2"
    page.menu.close()


def test_the_relay_map_flags_a_relay_two_radios_share(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = builder.go("Relay map")
    assert isinstance(page, RelayPage)
    assert page.summary.text().startswith("22 relays used, 42 never used, 0 shared")
    assert page.table.item(0, 0).text() == "Tribander 10 m; Tribander 15 m; Tribander 20 m"
    assert page.table.item(4, 1).text() == "Tribander 10 m; Tribander 15 m; Tribander 20 m"
    assert page.table.item(8, 6).text() == "never used"
    builder.doc.set(("Antennas", 1, "Control", 0, "Stations", 1, "Relays"), [0, 26])
    assert "1 shared where they should not be" in page.summary.text()
    assert page.table.item(0, 6).text().startswith("shared: station 1 radio 1 (Tribander")


def test_the_layout_preview_moves_a_button(window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    page = builder.go("Layout preview")
    assert isinstance(page, LayoutPage)
    page.band.setCurrentIndex(page.band.findText("20 m"))
    page.refresh()
    labels = {(b.row, b.column): w.text() for w, b in page.buttons}
    assert labels == {(0, 0): "Tribander", (0, 2): "Vertical", (1, 0): "Swap", (1, 1): "RX=TX"}
    widget, _button = page.buttons[0]
    widget.click()
    page.arrows["Right"].click()
    labels = {(b.row, b.column): w.text() for w, b in page.buttons}
    assert labels[(0, 1)] == "Tribander"
    assert builder.doc.get(("Layout", 0, "Matrix", 4, "Buttons", 0, "Column")) == 1


def test_what_if_asks_a_fresh_engine(qtbot: Any, window: tuple[BuilderWindow, Answers]) -> None:
    builder, _ = window
    qtbot.waitUntil(lambda: builder.checked is not None, timeout=30000)
    page = builder.go("What if")
    assert isinstance(page, WhatIfPage)
    _ref, use, khz, keyed = page.rows[0]
    use.setChecked(True)
    khz.setText("14025")
    page.rows[1][1].setChecked(True)
    page.rows[1][2].setText("14200")
    keyed.setChecked(True)
    page.ask_button.click()
    qtbot.waitUntil(lambda: "station 1 radio 2" in page.answer.toPlainText(), timeout=30000)
    text = page.answer.toPlainText()
    assert "station 1 radio 1 at 14025 kHz, transmitting: transmit 0 Tribander" in text
    assert "inhibited while station 1 radio 1 transmits" in text
    page.plan_button.click()
    qtbot.waitUntil(lambda: builder.plan_window is not None, timeout=60000)
    builder.plan_window.close()
    builder.doc.set(("Antennas", 0, "ShortName"), "Yagi")  # asked at once: the draft as it is now
    page.ask_button.click()
    qtbot.waitUntil(lambda: "transmit 0 Yagi" in page.answer.toPlainText(), timeout=30000)
    builder.doc.set(("Antennas", 0, "Rotator"), 7)
    page.ask_button.click()
    qtbot.waitUntil(lambda: "The draft has errors" in page.answer.toPlainText(), timeout=30000)


def test_saving_shows_the_diff_first_and_keeps_the_previous_file(
        window: tuple[BuilderWindow, Answers], station: Path) -> None:
    builder, answers = window
    before = station.read_bytes()
    builder.doc.set(("TCPPort",), 12070)
    answers.answers.append(False)
    builder.action_save.trigger()
    assert '+  "TCPPort": 12070,' in answers.diffs[-1] and station.read_bytes() == before
    answers.answers.append(True)
    builder.action_save.trigger()
    assert station.read_bytes() == before.replace(b"12059", b"12070")
    assert station.with_name("station.moas.bak").read_bytes() == before
    builder.doc.set(("TCPPort",), 12071)
    builder.action_save.trigger()  # after the first save of the session: no diff again
    assert len(answers.diffs) == 2 and b"12071" in station.read_bytes()


def test_saving_a_file_with_errors_asks_first(window: tuple[BuilderWindow, Answers], station: Path) -> None:
    builder, answers = window
    before = station.read_bytes()
    builder.doc.set(("Antennas", 0, "Rotator"), 7)
    answers.answers.append(False)
    builder.action_save.trigger()
    assert "The running server would refuse it" in answers.questions[-1]
    assert station.read_bytes() == before
    answers.answers += [True, True]  # yes, save it; yes, the diff
    builder.action_save.trigger()
    assert b'"Rotator": 7' in station.read_bytes()


def test_a_new_station_opens_the_guide_and_becomes_a_file_check_accepts(
        qtbot: Any, tmp_path: Path) -> None:
    path = tmp_path / "new.moas"
    builder = open_builder(path)
    assert builder is not None
    answers = Answers()
    builder.show_diff = answers.diff
    try:
        assert builder.stack.currentWidget() is builder.guide_page
        builder.guide_page.make.click()
        assert builder.doc.count(("Radios",)) == 2 and builder.doc.count(("Antennas",)) == 2
        assert isinstance(builder.stack.currentWidget(), ListPage)
        answers.answers.append(True)
        builder.action_save.trigger()
        result = parse_config(path.read_text(encoding="utf-8"), str(path))
        assert result.ok, result.problems
        assert not path.with_name("new.moas.bak").exists()
    finally:
        builder.close()
        release(path)


def test_a_file_open_in_one_builder_window_is_refused_to_another(
        window: tuple[BuilderWindow, Answers], station: Path) -> None:
    said: list[str] = []
    assert open_builder(station, None, said.append) is None
    assert 'already open in the builder window "Station builder - station.moas"' in said[0]


def test_closing_with_changes_asks_first(qtbot: Any, station: Path) -> None:
    builder = open_builder(station)
    assert builder is not None
    answers = Answers()
    builder.ask = answers.ask
    builder.doc.set(("TCPPort",), 1)
    answers.answers.append(False)
    builder.close()
    assert builder.isVisible() and "Close and lose them?" in answers.questions[-1]
    gone: list[object] = []
    builder.destroyed.connect(lambda *_: gone.append(True))
    answers.answers.append(True)
    builder.close()
    qtbot.waitUntil(lambda: bool(gone))
    again = open_builder(station)
    assert again is not None, "the claim went with the window"
    again.close()
    release(station)


def test_save_and_restart_goes_through_file_restart_and_asks_while_keyed(
        qapp: Any, tmp_path: Path) -> None:
    harness = Harness(tmp_path)
    path = tmp_path / "station.moas"
    shutil.copyfile(EXAMPLES / "small-station.moas", path)

    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(path))
        await window.idle()
        app = harness.app
        assert app is not None
        await until(lambda: app.status.state is ServerState.NORMAL)
        file_menu = next(m for m in window.findChildren(QMenu) if m.title() == "&File")
        assert "&Edit Station..." in [a.text() for a in file_menu.actions()]
        window.action_edit_station.trigger()
        builder = window.builder_windows[0]
        assert isinstance(builder, BuilderWindow) and builder.doc.path == path
        window.action_edit_station.trigger()  # a second window on the same file: refused
        assert len(window.builder_windows) == 1 and window.last_dialog is not None
        assert 'already open in the builder window "Station builder - station.moas"' in \
            window.last_dialog.text()
        answers = Answers()
        builder.show_diff = answers.diff
        first = app.engine
        builder.doc.set(("Antennas", 0, "ShortName"), "Yagi")
        answers.answers.append(True)  # the diff
        builder.action_apply.trigger()  # nobody transmits: restarted without a question
        await window.idle()
        assert app.engine is not first and app.engine is not None
        assert app.engine.config.antennas[0].short_name == "Yagi"
        # while a station transmits: asked first, naming it; No keeps the station as it is
        app.apply_changes(app.engine.set_frequency(1, 1, 14025.0))
        box = app.emulators()[1]
        await until(lambda: bool(box.view().relays))
        box.set_tr(1, True)
        await until(lambda: app.keyed_radios() == ["station 1 radio 1 (switch 1 port 1)"])
        second = app.engine
        builder.doc.set(("Antennas", 0, "ShortName"), "Beam")
        harness.answers.append(False)
        builder.action_apply.trigger()
        await window.idle()
        assert "Transmitting now:\n  station 1 radio 1 (switch 1 port 1)" in harness.questions[-1]
        assert app.engine is second and b'"Beam"' in path.read_bytes()
        # a file with errors is never taken: not saved, not restarted
        builder.doc.set(("Antennas", 0, "Rotator"), 7)
        builder.action_apply.trigger()
        await window.idle()
        assert app.engine is second and b'"Rotator": 7' not in path.read_bytes()
        assert "the running server would refuse it" in builder.statusBar().currentMessage()
        box.set_tr(1, False)
        builder.closing_confirmed = True
        builder.close()
        await harness.close()
    run_on_qt(qapp, scenario())
    assert QApplication.instance() is not None


def test_a_file_with_the_manual_s_json_mistakes_is_mended_from_the_edit_menu(
        qtbot: Any, tmp_path: Path) -> None:
    path = tmp_path / "broken.moas"
    shutil.copyfile(Path(__file__).resolve().parents[1] / "builder" / "manual-broken" /
                    "systems-functions.moas", path)
    builder = open_builder(path)
    assert builder is not None
    try:
        qtbot.waitUntil(lambda: builder.checked is not None, timeout=30000)
        texts = [builder.findings.item(i).text() for i in range(builder.findings.count())]
        assert any("error: write false in lowercase, not False" in t for t in texts)
        assert builder.action_mend.isEnabled()
        builder.action_mend.trigger()
        assert builder.statusBar().currentMessage() == "Mended 3 JSON mistakes"
        assert not builder.action_mend.isEnabled() and builder.doc.syntax == []
        qtbot.waitUntil(lambda: builder.checked is not None and builder.checked.text == builder.doc.text,
                        timeout=30000)
        texts = [builder.findings.item(i).text() for i in range(builder.findings.count())]
        assert not any("lowercase" in t or "missing comma" in t for t in texts)
    finally:
        builder.closing_confirmed = True
        builder.close()
        release(path)


def test_a_file_that_is_not_json_at_all_says_so(qtbot: Any, tmp_path: Path) -> None:
    path = tmp_path / "notes.moas"
    path.write_text("these are my notes, not a station\n")
    builder = open_builder(path)
    assert builder is not None
    try:
        assert "cannot be read as JSON" in builder.statusBar().currentMessage()
        qtbot.waitUntil(lambda: builder.findings.count() > 0, timeout=30000)
        assert "error:" in builder.findings.item(0).text()
        page = list_page(builder, "Antennas")
        assert page.list is not None
        page.list.add_button.click()  # refused with the reason, the file untouched
        assert "cannot be read as JSON" in builder.statusBar().currentMessage()
        assert builder.doc.text == "these are my notes, not a station\n"
    finally:
        builder.close()
        release(path)


def test_no_two_items_of_a_builder_menu_share_a_mnemonic(window: tuple[BuilderWindow, Answers]) -> None:
    from test_menu_mnemonics import clashes, every_menu

    builder, _ = window
    builder.doc.set(("TCPPort",), 1)  # Undo names the edit: its mnemonic stays
    menus = every_menu(builder)
    assert len(menus) >= 4
    found = [c for name, texts in menus for c in clashes(name, texts)]
    assert found == []
    assert builder.action_undo.text() == "&Undo set TCPPort"
