"""Help > Manual: the manual (``docs/``, shipped as ``moas_gui/manual``) rendered in
the program itself, on every system.

Qt renders Markdown (:class:`QTextBrowser`), so the manual never depends on what the
desktop would open a ``.md`` file with (a text editor in a terminal, or nothing).
Links between its pages open in the same window, with Back and Contents; links to
the web open in the browser.
"""

from __future__ import annotations

from pathlib import Path

from .qt import QHBoxLayout, QPushButton, QTextBrowser, QUrl, QVBoxLayout, QWidget

START = "README.md"
"""The manual's first page: the index of the others."""


class ManualWindow(QWidget):
    """The manual, one page at a time (see the module notes)."""

    def __init__(self, folder: Path) -> None:
        super().__init__()
        self.folder = folder
        self.setWindowTitle("MOAS Server manual")
        self.browser = QTextBrowser()
        self.browser.setOpenExternalLinks(True)  # http(s): the web browser
        self.browser.setSearchPaths([str(folder)])
        self.back = QPushButton("Back")
        self.back.clicked.connect(self.browser.backward)
        self.browser.backwardAvailable.connect(self.back.setEnabled)
        self.back.setEnabled(False)
        self.contents = QPushButton("Contents")
        self.contents.clicked.connect(self.home)
        bar = QHBoxLayout()
        bar.addWidget(self.back)
        bar.addWidget(self.contents)
        bar.addStretch(1)
        layout = QVBoxLayout(self)
        layout.addLayout(bar)
        layout.addWidget(self.browser)
        self.resize(900, 560)
        self.home()

    def home(self) -> None:
        self.show_page(START)

    def show_page(self, name: str) -> None:
        """Show the page ``name`` (a file of the manual's folder)."""
        self.browser.setSource(QUrl.fromLocalFile(str(self.folder / name)))

    @property
    def page(self) -> str:
        return Path(self.browser.source().toLocalFile()).name

    def first_heading(self) -> str:
        """The page's first heading, as shown (for tests and the title)."""
        block = self.browser.document().begin()
        while block.isValid():
            if block.blockFormat().headingLevel() > 0:
                return block.text()
            block = block.next()
        return ""


__all__ = ["ManualWindow"]
