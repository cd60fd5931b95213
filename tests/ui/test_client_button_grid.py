"""The button grid on its own: shapes, states, clicks and in-place updates."""

from __future__ import annotations

from typing import Any

from moas_gui.client.model import ButtonState, ButtonType, ButtonView, LayoutView
from moas_gui.ui.button_grid import ButtonGrid, grid_size
from moas_gui.ui.qt import QApplication, QContextMenuEvent, Qt

A, F = ButtonType.ANTENNA, ButtonType.FUNCTION
SEL, AV, UN = ButtonState.SELECTED, ButtonState.AVAILABLE, ButtonState.UNAVAILABLE


def layout(*buttons: ButtonView, rows: int = 2, columns: int = 2) -> LayoutView:
    return LayoutView(1, 1, rows, columns, buttons)


def make_grid(qtbot: Any, view: LayoutView, rows: int = 2, columns: int = 2) -> ButtonGrid:
    grid = ButtonGrid()
    qtbot.addWidget(grid)
    grid.resize(400, 200)
    grid.show_layout(view, rows, columns)
    grid.show()
    return grid


def test_the_grid_grows_to_hold_every_button() -> None:
    view = layout(ButtonView(3, 4, A, 1, "far", AV))
    assert grid_size(view, 2, 2) == (4, 5)
    assert grid_size(None, 2, 3) == (2, 3)


def test_clicks_and_double_clicks_carry_the_button(qtbot: Any) -> None:
    grid = make_grid(qtbot, layout(ButtonView(0, 0, A, 5, "Beam", AV),
                                   ButtonView(1, 1, F, 2, "Swap", AV)))
    clicked: list[ButtonView] = []
    doubled: list[ButtonView] = []
    grid.pressed.connect(clicked.append)
    grid.double_pressed.connect(doubled.append)
    beam = grid.button_for(A, 5)
    assert beam is not None
    # A real double-click is a click, then a double-click event and a release;
    # QTest's double-click is only the second half, so the click comes first here.
    qtbot.mouseClick(beam, Qt.MouseButton.LeftButton)
    qtbot.mouseDClick(beam, Qt.MouseButton.LeftButton)
    assert [b.id for b in clicked] == [5] and [b.id for b in doubled] == [5]
    assert grid.button_for(F, 2) is not None and grid.button_for(A, 2) is None


def test_unavailable_buttons_say_why_and_a_click_reaches_the_window(qtbot: Any) -> None:
    reason = "Antenna 5 (Beam) is in use by station 2 radio 1"
    grid = make_grid(qtbot, layout(ButtonView(0, 0, A, 5, "Beam", UN, reason)))
    beam = grid.buttons[0]
    assert beam.toolTip() == f"Beam (antenna 5): unavailable: {reason}"
    assert reason in beam.accessibleName()
    clicked: list[ButtonView] = []
    grid.pressed.connect(clicked.append)
    qtbot.mouseClick(beam, Qt.MouseButton.LeftButton)
    # the window answers the click with the reason (and sends nothing): see
    # test_client_window's Why? tests
    assert [(b.id, b.state) for b in clicked] == [(5, UN)]


def test_a_right_click_asks_why_about_the_button_under_the_pointer(qtbot: Any) -> None:
    grid = make_grid(qtbot, layout(ButtonView(0, 0, A, 5, "Beam", UN, "in use"),
                                   ButtonView(1, 1, F, 2, "Swap", AV)))
    asked: list[ButtonView | None] = []
    grid.why_asked.connect(asked.append)
    beam = grid.buttons[0]
    centre = beam.rect().center()
    QApplication.sendEvent(beam, QContextMenuEvent(QContextMenuEvent.Reason.Mouse, centre,
                                                   beam.mapToGlobal(centre)))
    assert [v.id if v else None for v in asked] == [5], "the button passes it to the grid"
    assert grid.button_at(beam.geometry().center()) is beam.view
    assert grid.button_at(grid.rect().bottomLeft()) is None


def test_a_new_layout_updates_buttons_in_place_and_drops_the_gone(qtbot: Any) -> None:
    grid = make_grid(qtbot, layout(ButtonView(0, 0, A, 5, "Beam", AV),
                                   ButtonView(0, 1, A, 6, "Dipole", SEL)))
    first = grid.buttons[0]
    grid.show_layout(layout(ButtonView(0, 0, A, 5, "Beam", SEL)), 2, 2)
    assert grid.buttons == (first,)
    assert first.view.state is SEL and first.isEnabled()
    grid.show_layout(layout(ButtonView(0, 0, A, 5, "Beam", UN)), 2, 2)
    assert first.view.state is UN and first.toolTip() == "Beam (antenna 5): unavailable"


def test_states_are_drawn_apart_even_in_grey(qtbot: Any) -> None:
    grid = make_grid(qtbot, layout(ButtonView(0, 0, A, 1, "S", SEL),
                                   ButtonView(0, 1, A, 2, "A", AV),
                                   ButtonView(1, 0, A, 3, "U", UN)))

    def grey_at_corner(index: int) -> int:
        button = grid.buttons[index]
        image = button.grab().toImage()
        colour = image.pixelColor(12, button.height() // 2)
        return round(0.3 * colour.red() + 0.59 * colour.green() + 0.11 * colour.blue())

    selected, available, unavailable = grey_at_corner(0), grey_at_corner(1), grey_at_corner(2)
    assert selected > available + 60 > unavailable + 60
