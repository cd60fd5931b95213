"""The server window's dialogs, all non-blocking: each is shown with ``open()``
and answers through a signal, so the qasync loop (client port, switch links,
hand-overs) runs on while it waits; see docs/architecture.md."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from .qt import QDesktopServices, QFileDialog, QMessageBox, Qt, QUrl, QWidget


def docs_path() -> Path:
    """The manual: ``moas_gui/manual`` in an installed package (the build copies
    ``docs/`` there), the ``docs`` folder in a checkout."""
    package = Path(__file__).resolve().parent.parent
    shipped = package / "manual"
    if (shipped / "README.md").is_file():
        return shipped
    return package.parent / "docs"


def show_message(parent: QWidget, icon: QMessageBox.Icon, title: str, text: str) -> QMessageBox:
    """A message with an OK button, left open beside the window."""
    box = QMessageBox(icon, title, text, QMessageBox.StandardButton.Ok, parent)
    box.setModal(False)
    box.open()
    return box


def show_problems(parent: QWidget, title: str, text: str, problems: str,
                  folder: Path) -> QMessageBox:
    """A file's problems, in the dialog itself (not behind "Show Details"), with a
    button that opens the file's folder in the system's file manager (not an editor:
    the desktop's opener for a text file may be a terminal program)."""
    box = QMessageBox(QMessageBox.Icon.Critical, title, text, QMessageBox.StandardButton.Ok,
                      parent)
    box.setInformativeText(problems)
    box.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
    opener = box.addButton("Open Folder", QMessageBox.ButtonRole.ActionRole)
    opener.clicked.disconnect()  # the box stays open: the operator reads on
    opener.clicked.connect(
        lambda: QDesktopServices.openUrl(QUrl.fromLocalFile(str(folder))))
    box.setModal(False)
    box.open()
    return box


def ask_yes_no(parent: QWidget, title: str, text: str,
               answered: Callable[[bool], None]) -> QMessageBox:
    """A window-modal Yes/No question (No by default); ``answered(yes)`` once closed."""
    buttons = QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No
    box = QMessageBox(QMessageBox.Icon.Question, title, text, buttons, parent)
    box.setDefaultButton(QMessageBox.StandardButton.No)
    box.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    box.finished.connect(
        lambda _result: answered(box.clickedButton() is box.button(QMessageBox.StandardButton.Yes)))
    box.open()
    return box


def choose_file(parent: QWidget, title: str, saving: bool, start: Path,
                chosen: Callable[[str], None]) -> QFileDialog:
    """An Open (a configuration) or Save (switch data) dialog starting in ``start``;
    ``chosen(path)`` when the user picks a file, nothing when they cancel."""
    if saving:
        dialog = QFileDialog(parent, title, str(start / "moas-switch-data.txt"),
                             "Text files (*.txt);;All files (*)")
        dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
    else:
        dialog = QFileDialog(parent, title, str(start),
                             "MOAS configurations (*.moas *.txt);;All files (*)")
        dialog.setFileMode(QFileDialog.FileMode.ExistingFile)
    dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    dialog.fileSelected.connect(chosen)
    dialog.open()
    return dialog


__all__ = ["ask_yes_no", "choose_file", "docs_path", "show_message"]
