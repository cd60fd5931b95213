"""A one-line label that shortens its text with "…" when the window is narrow.

A plain QLabel asks for the width of its whole text, so one long antenna name
would set the window's minimum width.  This label asks for little, shows as
much as fits, and keeps the whole text in :meth:`text` and in its tooltip.
"""

from __future__ import annotations

from .qt import QEvent, QLabel, QResizeEvent, QShowEvent, QSize, Qt, QWidget

MIN_WIDTH = 120
"""Pixels the label asks for at least; the rest of the text is elided."""


class ElidedLabel(QLabel):
    """A QLabel whose long text is cut with an ellipsis; the tooltip shows all of it."""

    def __init__(self, text: str = "", parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._full = ""
        self._detail = ""
        self.setText(text)

    def text(self) -> str:
        """The whole text, however much of it shows."""
        return self._full

    def shown_text(self) -> str:
        """What the label shows now (maybe cut with "…")."""
        return super().text()

    def setText(self, text: str) -> None:
        self._full = text
        if self.isVisible():
            self._fit()
        else:  # measured once shown: asking for sizes now would polish the label
            super().setText(text)  # before its object name picks its style sheet rule
        self.updateGeometry()

    def set_detail(self, detail: str) -> None:
        """More words for the tooltip, under the whole text when that is cut (the client's
        display line: why the radio has its antennas)."""
        self._detail = detail
        self._tip(super().text())

    def _tip(self, shown: str) -> None:
        parts = [self._full] if shown != self._full else []
        if self._detail:
            parts.append(self._detail)
        self.setToolTip("\n\n".join(parts))

    def _chrome(self) -> int:
        """Pixels around the text: margins, and a style sheet's padding and border."""
        return max(0, super().sizeHint().width()
                   - self.fontMetrics().horizontalAdvance(super().text()))

    def _fit(self) -> None:
        width = max(1, self.width() - self._chrome())
        shown = self.fontMetrics().elidedText(self._full, Qt.TextElideMode.ElideRight, width)
        super().setText(shown)
        self._tip(shown)

    def sizeHint(self) -> QSize:
        # a pixel or two more: elidedText() cuts a text that fits its width exactly
        width = self.fontMetrics().horizontalAdvance(self._full) + self._chrome() + 2
        return QSize(width, super().sizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(min(MIN_WIDTH, self.sizeHint().width()), super().minimumSizeHint().height())

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self._fit()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._fit()

    def changeEvent(self, event: QEvent) -> None:
        super().changeEvent(event)
        if event.type() in (QEvent.Type.FontChange, QEvent.Type.StyleChange):
            self.updateGeometry()  # a style sheet's font or padding: another size wanted
            if self.isVisible():
                self._fit()


__all__ = ["ElidedLabel"]
