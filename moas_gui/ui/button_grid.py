"""The grid of antenna and function buttons (manual 5.16).

The grid shows what the server's layout says and nothing more: each button
carries the server's :class:`~moas_gui.client.model.ButtonView` and is drawn
by its state (colours and second cues in :mod:`.client_style`).  A click emits
:attr:`ButtonGrid.pressed`, a double-click :attr:`ButtonGrid.double_pressed`.
An unavailable button keeps its unavailable look but can be clicked: the window
answers the click with the button's reason and sends nothing (its tooltip says
the same).  A right-click anywhere on the grid emits :attr:`ButtonGrid.why_asked`
with the button under the pointer (None between buttons).  Which antennas a press
adds, removes or replaces is the server's decision.

While the window does not have the server's state now (not connected, or the
switches stopped: :mod:`moas_gui.client.screen`), :meth:`ButtonGrid.set_greyed`
draws every button grey with no check mark, says why in its tooltip, and lets
it be pressed, so the window can answer the press with the reason instead of
dropping it.

A double-click is a click followed by a double-click: the first press is sent
at once (no waiting to see whether a second comes, which would slow every
ordinary press), and the double-click then asks for the exclusive selection.
"""

from __future__ import annotations

from moas_gui.client.model import ButtonState, ButtonType, ButtonView, LayoutView

from .client_style import Colours
from .qt import (
    QAbstractButton,
    QBrush,
    QColor,
    QContextMenuEvent,
    QFont,
    QGridLayout,
    QMouseEvent,
    QPainter,
    QPaintEvent,
    QPen,
    QPoint,
    QRectF,
    QSize,
    QSizePolicy,
    Qt,
    QWheelEvent,
    QWidget,
    Signal,
)

__all__ = ["ButtonGrid", "LayoutButton", "grid_size"]

CHECK = "\u2714"
WHEEL_NOTCH = 120
"""Qt's angle delta of one click of a mouse wheel (1/8 degree units)."""


def grid_size(layout: LayoutView | None, rows: int, columns: int) -> tuple[int, int]:
    """Rows and columns to show: those chosen, grown to hold every button of
    the layout (a button is never hidden because the grid is too small)."""
    if layout is not None:
        for button in layout.buttons:
            rows = max(rows, button.row + 1)
            columns = max(columns, button.column + 1)
    return rows, columns


class LayoutButton(QAbstractButton):
    """One button of the grid, painted by its state."""

    double_clicked = Signal()

    def __init__(self, view: ButtonView, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.view = view
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMinimumSize(96, 52)
        self.setCursor(Qt.CursorShape.PointingHandCursor)
        self.knob_cursor = False
        """The knob's cursor is on this button (a ring is drawn)."""
        self.greyed = ""
        """Why the button is drawn grey and its press is answered, not sent ("" when live)."""
        self.show_view(view)

    def set_cursor(self, on: bool) -> None:
        if on != self.knob_cursor:
            self.knob_cursor = on
            self.update()

    def show_view(self, view: ButtonView) -> None:
        self.view = view
        self.setText(view.label or f"#{view.id}")
        kind = "function" if view.type is ButtonType.FUNCTION else "antenna"
        if self.greyed:
            said = self.greyed
        elif view.state is ButtonState.UNAVAILABLE:
            said = f"unavailable: {view.reason}" if view.reason else "unavailable"
        else:
            said = view.state.value
        self.setToolTip(f"{view.label} ({kind} {view.id}): {said}")
        self.setAccessibleName(f"{view.label}: {said}")
        self.update()

    def set_greyed(self, why: str) -> None:
        """Grey with ``why`` (not connected, switches stopped), or live again with ""."""
        if why != self.greyed:
            self.greyed = why
            self.show_view(self.view)

    @property
    def shown_state(self) -> ButtonState | None:
        """The state the button shows now: None while greyed (no state is known to be true)."""
        return None if self.greyed else self.view.state

    def sizeHint(self) -> QSize:
        return QSize(132, 64)

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.LeftButton:
            event.accept()
            self.double_clicked.emit()
            return
        super().mouseDoubleClickEvent(event)

    def paintEvent(self, event: QPaintEvent) -> None:
        view = self.view
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        rect = QRectF(self.rect()).adjusted(3, 3, -3, -3)
        state = view.state
        is_function = view.type is ButtonType.FUNCTION
        if self.greyed:
            fill, text_colour = Colours.GREYED, Colours.GREYED_TEXT
            pen = QPen(Colours.GREYED_FRAME, 1.5, Qt.PenStyle.DotLine)
            state = ButtonState.AVAILABLE  # drawn as no state: nothing selected, not struck
        elif state is ButtonState.SELECTED:
            fill, text_colour, frame = Colours.SELECTED, Colours.SELECTED_TEXT, Colours.SELECTED_FRAME
            pen = QPen(frame, 4)
        elif state is ButtonState.AVAILABLE:
            fill = Colours.FUNCTION if is_function else Colours.AVAILABLE
            text_colour = Colours.AVAILABLE_TEXT
            frame = Colours.FUNCTION_FRAME if is_function else Colours.AVAILABLE_FRAME
            pen = QPen(frame, 1.5)
        else:
            fill, text_colour = Colours.UNAVAILABLE, Colours.UNAVAILABLE_TEXT
            pen = QPen(Colours.UNAVAILABLE_HATCH, 2, Qt.PenStyle.DashLine)
        if self.isDown():
            fill = fill.lighter(140)
        painter.setPen(pen)
        painter.setBrush(QBrush(fill))
        painter.drawRoundedRect(rect, 8, 8)
        if state is ButtonState.UNAVAILABLE:
            painter.setBrush(QBrush(Colours.UNAVAILABLE_HATCH, Qt.BrushStyle.BDiagPattern))
            painter.setPen(Qt.PenStyle.NoPen)
            painter.drawRoundedRect(rect.adjusted(2, 2, -2, -2), 7, 7)
        if self.knob_cursor:
            painter.setPen(QPen(QColor("#80d8ff"), 3))
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawRoundedRect(rect.adjusted(4, 4, -4, -4), 6, 6)
        elif self.hasFocus():
            painter.setPen(QPen(QColor("#80d8ff"), 1, Qt.PenStyle.DotLine))
            painter.setBrush(Qt.BrushStyle.NoBrush)
            painter.drawRoundedRect(rect.adjusted(5, 5, -5, -5), 5, 5)

        font = QFont(self.font())
        font.setPointSizeF(max(11.0, min(16.0, rect.height() / 4.2)))
        font.setBold(state is not ButtonState.UNAVAILABLE and not self.greyed)
        font.setStrikeOut(state is ButtonState.UNAVAILABLE)
        painter.setFont(font)
        painter.setPen(text_colour)
        label = self.text()
        if state is ButtonState.SELECTED:
            label = f"{CHECK} {label}"
        if is_function:
            label = f"\u0192 {label}" if state is not ButtonState.SELECTED else label
        painter.drawText(rect.adjusted(6, 2, -6, -2),
                         int(Qt.AlignmentFlag.AlignCenter) | int(Qt.TextFlag.TextWordWrap), label)
        painter.end()


class ButtonGrid(QWidget):
    """Rows and columns of :class:`LayoutButton`; see the module notes."""

    pressed = Signal(object)
    """A :class:`ButtonView` was clicked."""
    double_pressed = Signal(object)
    """A :class:`ButtonView` was double-clicked (exclusive selection)."""
    wheel_turned = Signal(int)
    """Whole notches of a mouse wheel over the grid: positive turned away from the
    user, negative towards (the knob, :mod:`.knob`)."""
    middle_pressed = Signal()
    """The middle mouse button (a wheel's press) went down over the grid."""
    why_asked = Signal(object)
    """A right-click (or the context-menu key) over the grid: the :class:`ButtonView`
    under the pointer, or None between buttons.  The window shows the menu."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._grid = QGridLayout(self)
        self._grid.setSpacing(6)
        self._grid.setContentsMargins(0, 0, 0, 0)
        self._buttons: dict[tuple[int, int], LayoutButton] = {}
        self.layout_view: LayoutView | None = None
        self.rows = 0
        self.columns = 0
        self._wheel = 0
        self.greyed = ""
        """Why every button is grey (see the module notes); "" when live."""

    def set_greyed(self, why: str) -> None:
        """Greys every button with ``why``, or makes them live again with ""."""
        self.greyed = why
        for button in self._buttons.values():
            button.set_greyed(why)

    def contextMenuEvent(self, event: QContextMenuEvent) -> None:
        event.accept()
        self.why_asked.emit(self.button_at(event.pos()))

    def button_at(self, pos: QPoint) -> ButtonView | None:
        """The view of the button at ``pos`` (grid coordinates), None between buttons."""
        child = self.childAt(pos)
        while child is not None and not isinstance(child, LayoutButton):
            child = child.parentWidget()
        return child.view if isinstance(child, LayoutButton) else None

    def wheelEvent(self, event: QWheelEvent) -> None:
        delta = event.angleDelta()
        self._wheel += delta.y() or delta.x()
        notches = int(self._wheel / WHEEL_NOTCH)
        if notches:
            self._wheel -= notches * WHEEL_NOTCH
            self.wheel_turned.emit(notches)
        event.accept()

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() == Qt.MouseButton.MiddleButton:
            event.accept()
            self.middle_pressed.emit()
            return
        super().mousePressEvent(event)

    @property
    def buttons(self) -> tuple[LayoutButton, ...]:
        return tuple(self._buttons[key] for key in sorted(self._buttons))

    def button_for(self, kind: ButtonType, ident: int) -> LayoutButton | None:
        for button in self.buttons:
            if button.view.type is kind and button.view.id == ident:
                return button
        return None

    def show_layout(self, layout: LayoutView | None, rows: int, columns: int) -> None:
        """Shows ``layout`` in a grid of at least ``rows`` x ``columns`` cells.

        Buttons already on screen are updated in place (so a double-click is
        not lost when the first click's change arrives between the clicks)."""
        self.layout_view = layout
        rows, columns = grid_size(layout, rows, columns)
        wanted = {(b.row, b.column): b for b in layout.buttons} if layout else {}
        for cell in list(self._buttons):
            if cell not in wanted:
                gone = self._buttons.pop(cell)
                self._grid.removeWidget(gone)
                gone.deleteLater()
        for cell, view in wanted.items():
            existing = self._buttons.get(cell)
            if existing is not None:
                existing.show_view(view)
                continue
            button = LayoutButton(view, self)
            button.set_greyed(self.greyed)
            button.clicked.connect(lambda _=False, b=button: self.pressed.emit(b.view))
            button.double_clicked.connect(lambda b=button: self.double_pressed.emit(b.view))
            self._buttons[cell] = button
            self._grid.addWidget(button, *cell)
        if (rows, columns) != (self.rows, self.columns):
            self._set_shape(rows, columns)

    def _set_shape(self, rows: int, columns: int) -> None:
        for row in range(max(rows, self.rows)):
            self._grid.setRowStretch(row, 1 if row < rows else 0)
            self._grid.setRowMinimumHeight(row, 52 if row < rows else 0)
        for column in range(max(columns, self.columns)):
            self._grid.setColumnStretch(column, 1 if column < columns else 0)
            self._grid.setColumnMinimumWidth(column, 96 if column < columns else 0)
        self.rows, self.columns = rows, columns
