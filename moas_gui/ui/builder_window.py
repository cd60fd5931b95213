"""The station builder's window (``moas-server --edit FILE``, File > Edit Station...).

A page for every list of the file and for the station at a glance, the findings of
``--check`` below them (checked off the window's thread a moment after each edit, each
a link to its field), Undo and Redo, Save (the diff first, and a question when the file
has errors) and Save and Restart (through the server window's own Restart, which asks
first while a station transmits; from ``moas-server --edit``, a request to the running
server, :mod:`moas_gui.cli.builder_restart`, which refuses while a station the operator
has not confirmed transmits, so the builder asks first, naming who does).  Every question is a dialog opened with ``open()``:
no nested event loop.  The model underneath is :mod:`moas_gui.builder` (no Qt).
"""

from __future__ import annotations

import asyncio
import logging
import sys
from collections.abc import Callable, Iterator, Mapping
from functools import partial
from pathlib import Path
from typing import Any

from moas_gui.builder import Document, EditError
from moas_gui.builder.apply import ServerAnswer, question
from moas_gui.builder.checking import Checked, CheckFinding, check_text
from moas_gui.builder.claims import FileClaimed, claim, release
from moas_gui.builder.fields import LISTS, MISCELLANEOUS, ListSpec, list_for
from moas_gui.builder.spans import Path as ValuePath

from .builder_fields import Editor, GroupForm, GroupList
from .builder_pages import GridPage, GuidePage, LayoutPage, Page, RelayPage, WhatIfPage, Worker
from .qt import (
    QBrush,
    QCloseEvent,
    QColor,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QHBoxLayout,
    QKeySequence,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMainWindow,
    QMessageBox,
    QPlainTextEdit,
    QScrollArea,
    QSplitter,
    QStackedWidget,
    Qt,
    QTimer,
    QVBoxLayout,
    QWidget,
    added,
)
from .screen_fit import fit_to_screen

log = logging.getLogger(__name__)

CHECK_DELAY_MS = 400
"""The findings are checked again this long after the last edit."""
PLAN_SECONDS = 3.0
"""Processor time the station plan's findings may take with each check."""
ERROR_COLOR = QColor(170, 0, 0)
WARNING_COLOR = QColor(140, 90, 0)


class ListPage(Page):
    """One list of the file (or the miscellaneous items): its table and the selected
    item's form, with the manual's words for the list above them."""

    def __init__(self, spec: ListSpec, editor: Editor, parent: QWidget | None = None) -> None:
        super().__init__(editor.doc, editor.say, parent)
        self.spec = spec
        self.editor = editor
        column = QVBoxLayout(self)
        column.setContentsMargins(0, 0, 0, 0)
        about = QLabel(f"<b>{spec.title}</b> (manual section {spec.section}): {spec.about}", self)
        about.setWordWrap(True)
        column.addWidget(about)
        self.scroller = QScrollArea(self)
        self.scroller.setWidgetResizable(True)
        column.addWidget(self.scroller, 1)
        self.list: GroupList | None = None
        self.form: GroupForm | None = None
        if spec.key:
            self.list = GroupList(spec.fields, spec.columns, editor, spec.key, self.scroller,
                                  new=lambda: dict(spec.new))
            self.scroller.setWidget(self.list)
        else:
            self.form = GroupForm(spec.fields, editor, self.scroller)
            self.scroller.setWidget(self.form)

    def refresh(self) -> None:
        if self.list is not None:
            self.list.set_path((self.spec.key,))
        elif self.form is not None:
            self.form.set_base(())

    def show_path(self, rest: ValuePath) -> QWidget | None:
        """Show the item and field at ``rest`` (scrolled to); returns the field's widget."""
        widget: QWidget | None = None
        if self.list is not None:
            widget = self.list.show_path(rest)
        elif self.form is not None:
            widget = self.form.show_path(rest)
        if widget is not None:
            self.scroller.ensureWidgetVisible(widget)
        return widget


class Pages(Mapping[str, Page]):
    """The window's pages by title, in the navigation's order, each made the first time it
    is shown or asked for (a window opens with the page it shows; most are never visited).
    Until then a page's place in the stack holds an empty widget."""

    def __init__(self, stack: QStackedWidget) -> None:
        self.stack = stack
        self.titles: list[str] = []
        self._make: dict[str, Callable[[], Page]] = {}
        self._made: dict[str, Page] = {}
        self._waiting: dict[str, QWidget] = {}

    def add(self, title: str, make: Callable[[], Page] | Page) -> None:
        """The page ``title`` next: made already, or made by ``make`` when first wanted."""
        self.titles.append(title)
        if isinstance(make, Page):
            self._made[title] = make
            self.stack.addWidget(make)
        else:
            self._make[title] = make
            self._waiting[title] = QWidget(self.stack)
            self.stack.addWidget(self._waiting[title])

    def made(self, title: str) -> bool:
        return title in self._made

    def __getitem__(self, title: str) -> Page:
        page = self._made.get(title)
        if page is None:
            page = self._made[title] = self._make.pop(title)()
            row = self.titles.index(title)
            shown = self.stack.currentIndex() == row
            waiting = self._waiting.pop(title)
            self.stack.insertWidget(row, page)
            self.stack.removeWidget(waiting)
            waiting.deleteLater()
            if shown:
                self.stack.setCurrentIndex(row)
        return page

    def __iter__(self) -> Iterator[str]:
        return iter(self.titles)

    def __len__(self) -> int:
        return len(self.titles)

    def show(self, row: int) -> None:
        """Show the page at ``row`` of the navigation (made now if it was not yet)."""
        if 0 <= row < len(self.titles):
            self[self.titles[row]]
            self.stack.setCurrentIndex(row)


AskServer = Callable[[Path, tuple[str, ...] | None, bool], ServerAnswer]
"""``ask(path, confirmed, replace)``: the running server's answer to a restart on ``path``
(``confirmed`` None: only a look at what it runs and who transmits); blocking, so called
off the window's thread."""


class BuilderWindow(QMainWindow):
    """The builder on one document (see the module docstring).  ``apply``: what Save and
    Restart does with the saved file (the server window's restart); else ``ask_server``
    asks a server running in another process; neither: Save and Restart is greyed out."""

    def __init__(self, doc: Document, apply: Callable[[Path], None] | None = None,
                 parent: QWidget | None = None, ask_server: AskServer | None = None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.apply = apply
        self.ask_server = ask_server
        self.server_answer: ServerAnswer | None = None
        """The running server's last final answer to Save and Restart from another process
        (restarted, refused, not reached, or the operator's No)."""
        self.server_worker = Worker(self)
        self.checked: Checked | None = None
        self.dialog: QWidget | None = None
        """The question or diff on screen, if any."""
        self.plan_window: QWidget | None = None
        self.closing_confirmed = False
        self.ask: Callable[[str, str, Callable[[bool], None]], None] = self._ask_dialog
        """Asks a yes/no question without waiting; tests replace it with a fake that answers."""
        self.show_diff: Callable[[str, Callable[[bool], None]], None] = self._diff_dialog
        self.editor = Editor(doc, self.say)
        self.worker = Worker(self)
        self._again = False
        self.timer = QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(CHECK_DELAY_MS)
        self.timer.timeout.connect(self.check_now)
        self._build()
        fit_to_screen(self, 1000, 580)
        doc.listeners.append(self._changed)
        self._title()
        self.refresh()
        self.check_now()
        if not doc.readable:
            self.say("The file cannot be read as JSON (see the findings): mend it in a text "
                     "editor, then open it here again")

    # -- building ---------------------------------------------------------------------------
    def _build(self) -> None:
        self.nav = QListWidget(self)
        self.nav.setFixedWidth(150)
        self.stack = QStackedWidget(self)
        self.pages = Pages(self.stack)
        self.guide_page = GuidePage(self.doc, self.say, self)
        self.guide_page.made.connect(lambda: self.go("Antennas"))
        self._add("New station", self.guide_page)
        for spec in LISTS:
            self._add(spec.title, partial(ListPage, spec, self.editor, self))
        self._add("Band x antenna", partial(GridPage, self.doc, self.say, self))
        self._add("Relay map", partial(RelayPage, self.doc, self.say, self))
        self._add("Layout preview", partial(LayoutPage, self.doc, self.say, self))
        self.what_if = WhatIfPage(self.doc, self.say, self._show_plan, self)
        self._add("What if", self.what_if)
        self.nav.currentRowChanged.connect(self._page_chosen)
        self.findings = QListWidget(self)
        self.findings.itemActivated.connect(self._finding_chosen)
        self.findings.itemClicked.connect(self._finding_chosen)
        upper = QWidget(self)
        row = QHBoxLayout(upper)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(self.nav)
        row.addWidget(self.stack, 1)
        whole = QSplitter(Qt.Orientation.Vertical, self)
        whole.addWidget(upper)
        whole.addWidget(self.findings)
        whole.setStretchFactor(0, 4)
        whole.setStretchFactor(1, 1)
        self.setCentralWidget(whole)
        self._menus()
        new = self.doc.saved is None and not self.doc.items(("Radios",))
        self.nav.setCurrentRow(0 if new else 2)

    def _add(self, title: str, make: Callable[[], Page] | Page) -> None:
        self.pages.add(title, make)
        QListWidgetItem(title, self.nav)

    def _menus(self) -> None:
        bar = self.menuBar()
        file_menu = bar.addMenu("&File")
        self.action_save = added(file_menu.addAction("&Save", self.save))
        self.action_save.setShortcut(QKeySequence.StandardKey.Save)
        self.action_apply = added(file_menu.addAction("Save and &Restart", self.save_and_restart))
        if self.apply is None and self.ask_server is None:
            self.action_apply.setEnabled(False)
            self.action_apply.setToolTip("Open the builder from the server window's File > Edit "
                                         "Station... to restart the running server")
        elif self.apply is None:
            self.action_apply.setToolTip("Saves, then asks this user's running moas-server to "
                                         "restart on the file (asking first while a station "
                                         "transmits); one started with --new-instance cannot "
                                         "be reached")
        file_menu.addSeparator()
        self.action_close = added(file_menu.addAction("&Close", self.close))
        edit = bar.addMenu("&Edit")
        self.action_undo = added(edit.addAction("&Undo", self.undo))
        self.action_undo.setShortcut(QKeySequence.StandardKey.Undo)
        self.action_redo = added(edit.addAction("&Redo", self.redo))
        self.action_redo.setShortcut(QKeySequence.StandardKey.Redo)
        edit.addSeparator()
        self.action_mend = added(edit.addAction("&Mend JSON Mistakes", self.mend))
        self.action_mend.setToolTip("Adds missing commas, takes extra ones away, writes "
                                    "true/false/null in lowercase and puts names and texts in "
                                    "double quotes (manual 6.1), in one undo step")
        view = bar.addMenu("&View")
        self.action_diff = added(view.addAction("&Changes to Be Saved", self.view_diff))

    # -- reading the document ---------------------------------------------------------------
    def say(self, text: str) -> None:
        self.statusBar().showMessage(text, 8000)

    def _title(self) -> None:
        name = self.doc.path.name if self.doc.path else "new station"
        self.setWindowTitle(f"Station builder - {name}{' *' if self.doc.modified else ''}")

    def _changed(self, _doc: Document) -> None:
        self._title()
        self.refresh()
        self.timer.start()

    def refresh(self) -> None:
        self.editor.refresh_choices()
        page = self.stack.currentWidget()
        if isinstance(page, Page):
            page.refresh()
        self.action_mend.setEnabled(bool(self.doc.syntax))
        self.action_undo.setEnabled(self.doc.can_undo)
        self.action_redo.setEnabled(self.doc.can_redo)
        self.action_undo.setText(f"&Undo {self.doc.undo_steps[-1].what}" if self.doc.can_undo else "&Undo")
        self.action_redo.setText(f"&Redo {self.doc.redo_steps[-1].what}" if self.doc.can_redo else "&Redo")

    def _page_chosen(self, row: int) -> None:
        self.pages.show(row)
        self.refresh()

    def go(self, title: str) -> Page:
        row = self.pages.titles.index(title)
        self.nav.setCurrentRow(row)
        return self.pages[title]

    # -- findings ---------------------------------------------------------------------------
    def check_now(self) -> None:
        """Check the draft off the window's thread; the findings follow when ready.  One
        check at a time: edits made meanwhile are checked once it is done."""
        if self.worker.busy:
            self._again = True
            return
        self._again = False
        text, name, root = self.doc.text, str(self.doc.path or "new-station.moas"), self.doc.root
        self.worker.run(lambda: check_text(text, name, root=root, plan_seconds=PLAN_SECONDS),
                        self._checked)

    def _checked(self, result: Any) -> None:
        if self._again:
            self.check_now()
        if isinstance(result, Exception):
            self.say(f"The checks failed: {result}")
            return
        if result.text != self.doc.text:
            return  # an edit came since: its own check follows
        self.checked = result
        self.findings.clear()
        for finding in result.findings:
            item = QListWidgetItem(finding.text, self.findings)
            item.setData(Qt.ItemDataRole.UserRole, finding)
            if finding.is_error:
                item.setForeground(QBrush(ERROR_COLOR))
            elif finding.severity == "warning":
                item.setForeground(QBrush(WARNING_COLOR))
        if result.plan_note:
            QListWidgetItem(result.plan_note, self.findings)
        if not result.findings:
            QListWidgetItem("No findings: moas-server --check accepts this file.", self.findings)
        errors = len(result.errors)
        self.say(f"{errors} error{'s' if errors != 1 else ''}, {len(result.findings) - errors} "
                 "other findings")

    def _finding_chosen(self, item: QListWidgetItem) -> None:
        finding = item.data(Qt.ItemDataRole.UserRole)
        if isinstance(finding, CheckFinding):
            self.show_field(finding.path)

    def show_field(self, path: ValuePath) -> QWidget | None:
        """Show the page and the field ``path`` is about, and put the cursor there;
        returns the field's widget."""
        if not path:
            self.say("This finding is about the file as a whole")
            return None
        spec = list_for(str(path[0]))
        page = self.go(spec.title)
        assert isinstance(page, ListPage)
        return page.show_path(path[1:] if spec is not MISCELLANEOUS else path)

    # -- editing ----------------------------------------------------------------------------
    def undo(self) -> None:
        what = self.doc.undo()
        self.say(f"Undone: {what}" if what else "Nothing to undo")

    def redo(self) -> None:
        what = self.doc.redo()
        self.say(f"Redone: {what}" if what else "Nothing to redo")

    def mend(self) -> None:
        count = self.doc.repair()
        self.say(f"Mended {count} JSON mistake{'s' if count != 1 else ''}" if count
                 else "No JSON mistake the builder can mend")

    # -- saving -----------------------------------------------------------------------------
    def save(self, then: Callable[[Path], None] | None = None) -> None:
        """Save: a place for a new station first; a question when the file has errors (the
        running server would refuse it) or changed on disk; the diff before the first save
        of the session."""
        if self.doc.path is None:
            self._choose_place(then)
            return
        errors = check_text(self.doc.text, str(self.doc.path), root=self.doc.root).errors
        if errors and then is not None:
            self.say(f"Not saved for a restart: the file has {len(errors)} errors, and the "
                     "running server would refuse it (the station carries on)")
            self.show_field(errors[0].path)
            return
        if errors:
            self.ask("Save a file with errors?",
                     f"The file has {len(errors)} error{'s' if len(errors) != 1 else ''}, "
                     f"the first: {errors[0].message}.\n\nThe running server would refuse it. "
                     "Save anyway?", lambda yes: self._save_disk(then) if yes else None)
            return
        self._save_disk(then)

    def _save_disk(self, then: Callable[[Path], None] | None) -> None:
        if self.doc.changed_on_disk():
            self.ask("The file changed on disk",
                     f"{self.doc.path} was changed by another program since it was opened. "
                     "Write this builder's version over it?",
                     lambda yes: self._save_diff(then) if yes else None)
            return
        self._save_diff(then)

    def _save_diff(self, then: Callable[[Path], None] | None) -> None:
        if self.doc.saves == 0 and self.doc.modified:
            self.show_diff(self.doc.diff(), lambda yes: self._write(then) if yes else None)
            return
        self._write(then)

    def _write(self, then: Callable[[Path], None] | None) -> None:
        try:
            path = self.doc.save()
        except (OSError, EditError) as exc:
            self.say(f"Not saved: {exc}")
            QMessageBox(QMessageBox.Icon.Critical, "Not saved", f"Not saved: {exc}",
                        QMessageBox.StandardButton.Ok, self).open()
            return
        self.say(f"Saved {path} (the previous version is {path.name}.bak)")
        log.info("Station builder saved %s", path)
        if then is not None:
            then(path)

    def _choose_place(self, then: Callable[[Path], None] | None) -> None:
        dialog = QFileDialog(self, "Save the new station", str(Path.home() / "station.moas"),
                             "MOAS stations (*.moas);;All files (*)")
        dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
        dialog.setDefaultSuffix("moas")

        def chosen(name: str) -> None:
            try:
                claim(Path(name), self.windowTitle())
            except FileClaimed as exc:
                self.say(str(exc))
                return
            self.doc.path = Path(name)
            self.save(then)
        dialog.fileSelected.connect(chosen)
        self.dialog = dialog
        dialog.open()

    def save_and_restart(self) -> None:
        """Save, then restart the running server on the file (its own File > Restart, which
        asks first while a station transmits); a file with errors is never taken."""
        if self.apply is not None:
            self.save(self.apply)
        elif self.ask_server is not None:
            self.save(lambda path: self.restart_on_server(path))
        else:
            self.say("No server runs in this window: start it on the file to use it")

    def restart_on_server(self, path: Path, confirmed: tuple[str, ...] | None = None,
                          replace: bool = False) -> None:
        """Ask the server running in another process to restart on ``path`` (off the
        window's thread): first a look (``confirmed`` None) at what it runs and who
        transmits, asked about when someone does or it runs another file; then the
        restart itself.  Its answer is said, or asked about (:meth:`_server_answered`)."""
        ask = self.ask_server
        if ask is None:
            return
        self.say(f"Asking the running moas-server to restart on {path.name}..."
                 if confirmed is not None else "Looking for the running moas-server...")
        self.server_worker.run(lambda: ask(path, confirmed, replace),
                               lambda answer: self._server_answered(path, answer, replace))

    def _server_answered(self, path: Path, answer: Any, replace: bool) -> None:
        if isinstance(answer, Exception):
            answer = ServerAnswer(False, f"Could not ask the running moas-server: {answer}",
                            reached=False)
        if answer.looked and not answer.asks and answer.reached:
            self.restart_on_server(path, (), replace)  # nobody transmits: the restart itself
            return
        if answer.asks:
            title, text = question(path, answer)
            again = replace or answer.running is not None
            self.ask(title, text, lambda yes: self.restart_on_server(path, answer.keyed, again)
                     if yes else self._not_asked(path))
            return
        self.server_answer = answer
        log.info("Station builder: %s", answer.said)
        self.say(answer.said)
        if not answer.restarted:
            icon = QMessageBox.Icon.Warning if answer.reached else QMessageBox.Icon.Information
            box = QMessageBox(icon, "Not restarted", answer.said, QMessageBox.StandardButton.Ok,
                              self)
            self.dialog = box
            box.open()

    def _not_asked(self, path: Path) -> None:
        self.server_answer = ServerAnswer(False, f"Not restarted on {path.name}: nothing was sent, "
                                           "the station carries on as it is")
        self.say(self.server_answer.said)

    def view_diff(self) -> None:
        diff = self.doc.diff()
        self.show_diff(diff or "Nothing to save: the file is as it is on disk.", lambda _yes: None)

    # -- questions (never a nested loop) --------------------------------------------------------
    def _ask_dialog(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        buttons = QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No
        box = QMessageBox(QMessageBox.Icon.Question, title, text, buttons, self)
        box.setDefaultButton(QMessageBox.StandardButton.No)
        box.finished.connect(lambda _r: answered(
            box.clickedButton() is box.button(QMessageBox.StandardButton.Yes)))
        self.dialog = box
        box.open()

    def _diff_dialog(self, diff: str, answered: Callable[[bool], None]) -> None:
        dialog = QDialog(self)
        dialog.setWindowTitle("What saving will write")
        column = QVBoxLayout(dialog)
        column.addWidget(QLabel("The lines saving changes (- on disk now, + to be written); "
                                "everything else stays as it is:", dialog))
        text = QPlainTextEdit(diff, dialog)
        text.setReadOnly(True)
        text.setLineWrapMode(QPlainTextEdit.LineWrapMode.NoWrap)
        column.addWidget(text)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Save
                                   | QDialogButtonBox.StandardButton.Cancel, dialog)
        buttons.accepted.connect(dialog.accept)
        buttons.rejected.connect(dialog.reject)
        column.addWidget(buttons)
        dialog.finished.connect(lambda result: answered(result == QDialog.DialogCode.Accepted))
        fit_to_screen(dialog, 760, 460)
        self.dialog = dialog
        dialog.open()

    def _show_plan(self, plan: Any) -> None:
        from .plan_window import PlanWindow

        if self.plan_window is not None:
            self.plan_window.close()
        self.plan_window = PlanWindow(plan)
        self.plan_window.show()

    # -- closing ----------------------------------------------------------------------------
    def closeEvent(self, event: QCloseEvent) -> None:
        if self.doc.modified and not self.closing_confirmed:
            event.ignore()
            self.ask("Close without saving?", "The changes made in this window are not saved. "
                     "Close and lose them?", self._close_anyway)
            return
        self.timer.stop()
        if self.doc.path is not None:
            release(self.doc.path)
        if self._changed in self.doc.listeners:
            self.doc.listeners.remove(self._changed)
        super().closeEvent(event)

    def _close_anyway(self, yes: bool) -> None:
        if yes:
            self.closing_confirmed = True
            QTimer.singleShot(0, self.close)  # not from inside the close being refused


def open_builder(path: str | Path, apply: Callable[[Path], None] | None = None,
                 say: Callable[[str], None] = log.error,
                 ask_server: AskServer | None = None) -> BuilderWindow | None:
    """The builder on ``path`` (a new station when there is no such file), shown; None,
    with the reason said, when another builder window has it or it cannot be read."""
    path = Path(path)
    try:
        doc = Document.open(path) if path.exists() else Document.new(path)
    except (OSError, EditError) as exc:
        say(f"The builder cannot open {path}: {exc}")
        return None
    try:
        claim(path, f"Station builder - {path.name}")
    except FileClaimed as exc:
        say(str(exc))
        return None
    window = BuilderWindow(doc, apply, ask_server=ask_server)
    window.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    window.show()
    return window


def run_builder(path: str, ask_server: AskServer | None = None) -> int:
    """``moas-server --edit FILE``: the builder alone, until its window closes; its Save
    and Restart goes to ``ask_server`` (the running server, in another process)."""
    from .qt import load_qasync
    from .server_window import application_icon, ensure_application

    qasync = load_qasync()
    qt_app = ensure_application()
    qt_app.setWindowIcon(application_icon())
    loop = qasync.QEventLoop(qt_app)
    asyncio.set_event_loop(loop)
    refused: list[str] = []
    window = open_builder(path, None, refused.append, ask_server)
    if window is None:
        print(f"moas-server: {refused[0] if refused else 'the builder did not open'}",
              file=sys.stderr)
        return 1

    async def until_closed() -> int:
        from .control_hook import start_if_asked

        closed = asyncio.Event()
        window.destroyed.connect(lambda *_: closed.set())
        hook = await start_if_asked(window)  # a test's hands, when one names them
        await closed.wait()
        if hook is not None:
            await hook.close()
        return 0

    with loop:
        status: int = loop.run_until_complete(until_closed())
        return status


__all__ = ["AskServer", "BuilderWindow", "ListPage", "open_builder", "run_builder"]
