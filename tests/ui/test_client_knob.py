"""The knob in the desktop client: the stepping rules, and the wheel, keys and volume
keys of a USB knob in a real window against the protocol server (fake backend)."""

from __future__ import annotations

from typing import Any

from client_support import LiveServer, run_on_qt
from helpers import until
from test_client_window import button, open_window

from moas_gui.client.knob import knob_antennas, knob_step
from moas_gui.client.model import ButtonState, ButtonType, ButtonView, LayoutView
from moas_gui.ui.qt import QApplication, QKeySequence, QPoint, QPointF, Qt, QWheelEvent


def _view(row: int, column: int, ident: int, state: str = "available",
          kind: ButtonType = ButtonType.ANTENNA) -> ButtonView:
    return ButtonView(row, column, kind, ident, f"#{ident}", ButtonState(state))


def test_the_knob_steps_through_usable_antennas_in_reading_order_and_wraps() -> None:
    layout = LayoutView(1, 1, 2, 3, (
        _view(1, 0, 7), _view(0, 2, 5, "selected"), _view(0, 0, 9, "unavailable"),
        _view(0, 1, 3), _view(1, 1, 0, kind=ButtonType.FUNCTION), _view(1, 2, 3)))
    items = knob_antennas(layout)
    assert items == (3, 5, 7)
    assert knob_antennas(None) == ()
    assert knob_step(items, 5, 1) == 7
    assert knob_step(items, 7, 1) == 3  # past the end: back to the start
    assert knob_step(items, 3, -1) == 7
    assert knob_step(items, 5, 4) == 7
    assert knob_step(items, None, 1) == 3
    assert knob_step(items, 99, -1) == 7
    assert knob_step(items, None, 0) is None
    assert knob_step((), 5, 1) is None


def _wheel(widget: Any, notches: int) -> None:
    """One real wheel event over ``widget``: negative notches turn towards the user."""
    centre = QPointF(widget.width() / 2, widget.height() / 2)
    event = QWheelEvent(centre, QPointF(widget.mapToGlobal(QPoint(10, 10))), QPoint(0, 0),
                        QPoint(0, 120 * notches), Qt.MouseButton.NoButton,
                        Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(widget, event)


def test_the_wheel_moves_a_cursor_and_a_press_selects(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            knob = window.knob
            _wheel(window.grid, -1)
            assert knob.cursor == button(window, "Tribander").view.id
            assert button(window, "Tribander").knob_cursor
            assert not button(window, "20 Stack").knob_cursor
            assert live.calls("select") == [], "turning alone selects nothing"
            _wheel(window.grid, -1)  # past the end: back to the first
            assert knob.cursor == button(window, "20 Stack").view.id
            _wheel(window.grid, 1)
            assert knob.cursor == button(window, "Tribander").view.id
            assert knob.press()
            await until(lambda: button(window, "Tribander").view.state is ButtonState.SELECTED,
                        what="the press selecting the Tribander")
            assert live.calls("select") == [(1, 1, 1, "both", False)]
            stack = button(window, "20 Stack").view.id
            assert knob.step(1) == stack
            assert knob.press(exclusive=True)
            await until(lambda: (1, 1, stack, "both", True) in live.calls("select"),
                        what="the exclusive press")

    run_on_qt(qapp, scenario())


def _key(window: Any, *keys: Any) -> None:
    """What Qt does when the key is pressed with the window active: the shortcut bound
    to exactly that key sequence fires."""
    wanted = QKeySequence(*keys)
    found = [s for s in window.knob.shortcuts if s.key() == wanted]
    assert len(found) == 1, f"{wanted.toString()} is bound {len(found)} times"
    found[0].activated.emit()


def test_keys_and_a_usb_knobs_volume_keys_step_and_press(qapp: QApplication,
                                                         qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            tribander = button(window, "Tribander").view.id
            stack = button(window, "20 Stack").view.id
            _key(window, Qt.Key.Key_Right)  # from the antenna in use, 20 Stack
            assert window.knob.cursor == tribander
            _key(window, Qt.Key.Key_Left)
            assert window.knob.cursor == stack
            _key(window, Qt.Key.Key_VolumeUp)  # what a USB volume knob sends
            assert window.knob.cursor == tribander
            assert live.calls("select") == []
            _key(window, Qt.Key.Key_Return)
            await until(lambda: live.calls("select") == [(1, 1, tribander, "both", False)],
                        what="Return selecting the cursor's antenna")
            _key(window, Qt.Key.Key_VolumeDown)
            _key(window, Qt.Modifier.SHIFT | Qt.Key.Key_Return)
            await until(lambda: (1, 1, stack, "both", True) in live.calls("select"),
                        what="Shift+Return selecting it alone")
            # the relative list: Page Down moves its cursor, Ctrl+Return selects
            before = window.relative_box.currentIndex()
            _key(window, Qt.Key.Key_PageDown)
            index = window.relative_box.currentIndex()
            assert index == (before + 1) % window.relative_box.count()
            _key(window, Qt.Modifier.CTRL | Qt.Key.Key_Return)
            await until(lambda: (1, 1, None, index) in live.calls("relative"),
                        what="Ctrl+Return selecting from the relative list")
            _key(window, Qt.Key.Key_VolumeMute)  # a knob's press: the relative list was last
            await until(lambda: live.calls("relative").count((1, 1, None, index)) == 2,
                        what="a knob press on the relative list")
            _key(window, Qt.Modifier.ALT | Qt.Key.Key_1)
            assert window.radio == 1
            assert window.knob.choose_radio(1) and not window.knob.choose_radio(7)

    run_on_qt(qapp, scenario())
