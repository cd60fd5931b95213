"""The compass: its arithmetic, what it draws, what a click asks for, and the
compass of the client window against the protocol server."""

from __future__ import annotations

from typing import Any

import pytest
from client_support import LOOPBACK, LiveServer, run_on_qt
from helpers import until
from hypothesis import given
from hypothesis import strategies as st

from moas_gui.client import Backoff, ClientConnection
from moas_gui.client.model import (
    AntennaView,
    ButtonState,
    ButtonType,
    ButtonView,
    LayoutView,
    RadioView,
    RotatorView,
    Snapshot,
)
from moas_gui.ui.client_style import Colours
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.compass import CompassPanel, CompassTarget, CompassWidget, compass_targets
from moas_gui.ui.compass_geometry import (
    heading_at,
    normalize,
    point_at,
    qt_arc,
    rotator_heading,
    travel_marks,
)
from moas_gui.ui.qt import QApplication, QColor, QPoint, Qt

# -- arithmetic ---------------------------------------------------------------------------------


@pytest.mark.parametrize(("x", "y", "heading"), [
    (100, 0, 0.0), (200, 100, 90.0), (100, 200, 180.0), (0, 100, 270.0), (200, 0, 45.0),
])
def test_heading_at_reads_screen_points_clockwise_from_north(x: float, y: float,
                                                              heading: float) -> None:
    assert heading_at(100, 100, x, y) == pytest.approx(heading)


def test_the_very_centre_points_nowhere() -> None:
    assert heading_at(100, 100, 101, 102) is None


@given(st.floats(min_value=0, max_value=359.99), st.floats(min_value=20, max_value=500))
def test_point_at_and_heading_at_agree(heading: float, radius: float) -> None:
    x, y = point_at(50, 60, radius, heading)
    back = heading_at(50, 60, x, y)
    assert back is not None
    assert min(abs(back - heading), 360 - abs(back - heading)) < 1e-6


def test_offset_is_taken_off_the_rotator_heading() -> None:
    assert rotator_heading(90, 90) == 0
    assert rotator_heading(10, 90) == 280
    assert normalize(-30) == 330 and normalize(720) == 0


def test_a_side_mount_has_a_dead_zone_after_its_travel() -> None:
    marks = travel_marks(0, 300, False)
    assert marks.dead == (300, 60) and marks.stop == 0 and marks.overlap is None
    turned = travel_marks(0, 300, False, offset=90)
    assert turned.dead == (30, 60) and turned.stop == 90


def test_overlap_and_stop_of_a_rotator_past_a_full_turn() -> None:
    marks = travel_marks(180, 450, True)
    assert marks.dead is None and marks.overlap == (180, 90) and marks.stop == 180
    assert travel_marks(180, 360, True) == type(marks)(stop=180)
    assert travel_marks(0, 360, False) == type(marks)()
    assert travel_marks(None, None, True) == type(marks)()


def test_qt_arcs_turn_the_compass_way() -> None:
    assert qt_arc(0, 90) == (90 * 16, -90 * 16)
    assert qt_arc(300, 60) == (-210 * 16, -60 * 16)


# -- which rotators a radio's compass offers -----------------------------------------------------

SNAPSHOT = Snapshot(
    radios=(RadioView(1, 1, 14025.0, tx=6, rx=9),),
    antennas=(AntennaView(6, "Stack", "20m stack", rotator=1, offset=90),
              AntennaView(9, "Bev", "Beverage", rotator=None),
              AntennaView(11, "NE", "4-square NE", rotator=4, offset=45),
              AntennaView(12, "SW", "4-square SW", rotator=4, offset=225),
              AntennaView(13, "Tri", "Tribander", rotator=2)),
    rotators=(RotatorView(1, "Tower", heading=0.0), RotatorView(2, "Tri", heading=10.0),
              RotatorView(4, "4SQ", heading=45.0, electrical=True)),
)


def test_targets_start_with_the_radios_antennas_then_the_buttons() -> None:
    layout = LayoutView(1, 1, 1, 3, (
        ButtonView(0, 0, ButtonType.ANTENNA, 13, "Tri", ButtonState.AVAILABLE),
        ButtonView(0, 1, ButtonType.ANTENNA, 11, "NE", ButtonState.AVAILABLE),
        ButtonView(0, 2, ButtonType.FUNCTION, 6, "Swap", ButtonState.AVAILABLE)))
    targets = compass_targets(SNAPSHOT, SNAPSHOT.radios[0], layout)
    assert [t.rotator.id for t in targets] == [1, 2, 4]
    assert targets[0].offset == 90 and targets[0].antenna == "Stack"
    assert [(d.heading, d.label) for d in targets[2].directions] == [(45, "NE"), (225, "SW")]
    assert compass_targets(SNAPSHOT, None, layout) == ()


# -- the widget ---------------------------------------------------------------------------------


def make_compass(qtbot: Any, rotator: RotatorView, offset: float = 0.0) -> CompassWidget:
    compass = CompassWidget()
    qtbot.addWidget(compass)
    compass.resize(300, 300)
    compass.show_target(CompassTarget(rotator, "Beam", offset))
    return compass


def colour_at(compass: CompassWidget, heading: float, fraction: float) -> QColor:
    image = compass.grab().toImage()
    point = compass.point_for_heading(heading, fraction).toPoint()
    return image.pixelColor(point)


def close(a: QColor, b: QColor, tolerance: int = 40) -> bool:
    return all(abs(x - y) <= tolerance for x, y in
               ((a.red(), b.red()), (a.green(), b.green()), (a.blue(), b.blue())))


def test_the_heading_is_drawn_where_the_rotator_points(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=120.0))
    assert close(colour_at(compass, 120, 0.5), Colours.HEADING)
    assert not close(colour_at(compass, 300, 0.5), Colours.HEADING)
    turned = make_compass(qtbot, RotatorView(1, "Beam", heading=120.0), offset=90)
    assert close(colour_at(turned, 210, 0.5), Colours.HEADING)


def test_the_target_and_the_dead_zone_are_drawn(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Side", heading=10.0, target=200.0,
                                              moving=True, ccw_limit=0, rotation=300))
    assert close(colour_at(compass, 200, 0.97), Colours.TARGET)
    dead = colour_at(compass, 330, 0.6)
    alive = colour_at(compass, 250, 0.6)
    assert dead.red() > dead.blue() + 40, "the dead zone is red"
    assert close(alive, Colours.COMPASS_FACE, 12)


def test_with_no_heading_nothing_on_the_dial_reads_as_a_needle(qtbot: Any) -> None:
    """The stop of a rotator whose heading is not known yet is a mark on the rim, not a
    red spoke from the centre that reads as a needle pointing at it (issue 30)."""
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=None, ccw_limit=180,
                                              rotation=360, has_stop=True))
    assert close(colour_at(compass, 180, 0.8), Colours.STOP)  # the stop, on the rim
    for fraction in (0.2, 0.4, 0.6):
        assert not close(colour_at(compass, 180, fraction), Colours.STOP), fraction
        assert not close(colour_at(compass, 180, fraction), Colours.HEADING), fraction


def test_a_click_asks_for_the_heading_under_it(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=0.0))
    asked: list[float] = []
    compass.rotate_requested.connect(asked.append)
    for heading in (90, 225):
        qtbot.mouseClick(compass, Qt.MouseButton.LeftButton,
                         pos=compass.point_for_heading(heading, 0.7).toPoint())
    assert asked == [90.0, 225.0]


def test_a_drag_asks_for_where_it_is_released(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=0.0))
    asked: list[float] = []
    compass.rotate_requested.connect(asked.append)
    start = compass.point_for_heading(10, 0.7).toPoint()
    end = compass.point_for_heading(135, 0.7).toPoint()
    qtbot.mousePress(compass, Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(compass, pos=end)
    qtbot.mouseRelease(compass, Qt.MouseButton.LeftButton, pos=end)
    assert asked == [135.0]


def test_a_click_on_an_offset_antenna_asks_for_the_rotator_heading(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=0.0), offset=90)
    asked: list[float] = []
    compass.rotate_requested.connect(asked.append)
    qtbot.mouseClick(compass, Qt.MouseButton.LeftButton,
                     pos=compass.point_for_heading(90, 0.7).toPoint())
    assert asked == [0.0]


def test_an_offline_rotator_is_grey_and_ignores_clicks(qtbot: Any) -> None:
    compass = make_compass(qtbot, RotatorView(1, "Beam", heading=120.0, online=False))
    asked: list[float] = []
    compass.rotate_requested.connect(asked.append)
    qtbot.mouseClick(compass, Qt.MouseButton.LeftButton, pos=QPoint(150, 40))
    assert asked == []
    assert not close(colour_at(compass, 120, 0.5), Colours.HEADING)
    panel = CompassPanel()
    qtbot.addWidget(panel)
    panel.show_targets((CompassTarget(RotatorView(1, "Beam", heading=1.0, online=False)),))
    assert not panel.stop_button.isEnabled()
    assert panel.heading_label.text() == "offline"


# -- in the window, against the server ----------------------------------------------------------


def test_the_window_compass_turns_and_stops_the_rotator(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live:
            connection = ClientConnection(LOOPBACK, live.port, backoff=Backoff(0.02, 2, 0.1))
            window = ClientWindow(connection)
            window.start()
            window.show()
            try:
                panel = window.compass_panel
                await until(lambda: panel.current is not None and not panel.greyed,
                            what="the compass of the 20 m stack")
                assert panel.current.rotator.id == 2  # type: ignore[union-attr]
                assert panel.heading_label.text() == "45\u00b0"
                compass = panel.compass
                qtbot.mouseClick(compass, Qt.MouseButton.LeftButton,
                                 pos=compass.point_for_heading(180, 0.7).toPoint())
                await until(lambda: live.calls("rotate"), what="the rotate request")
                assert live.calls("rotate") == [(2, 180.0)]
                await until(lambda: "\u2192 180\u00b0" in panel.heading_label.text(),
                            what="the target shown while turning")
                qtbot.mouseClick(panel.stop_button, Qt.MouseButton.LeftButton)
                await until(lambda: live.calls("stop"), what="the stop request")
                assert live.calls("stop") == [(2,)]
                await until(lambda: panel.heading_label.text() == "45\u00b0")

                live.backend.set_rotator_online(2, False)
                await until(lambda: not panel.stop_button.isEnabled(), what="going offline")
                qtbot.mouseClick(compass, Qt.MouseButton.LeftButton,
                                 pos=compass.point_for_heading(90, 0.7).toPoint())
                assert live.calls("rotate") == [(2, 180.0)]
            finally:
                await window.aclose()
                window.close()

    run_on_qt(qapp, scenario())


def test_the_panel_follows_the_transmit_rotator_until_the_user_picks_one(qtbot: Any) -> None:
    panel = CompassPanel()
    qtbot.addWidget(panel)
    one, two = (CompassTarget(RotatorView(i, f"R{i}", heading=0.0)) for i in (1, 2))
    panel.show_targets((one, two), prefer=1)
    assert panel.current is one
    panel.show_targets((one, two), prefer=2)
    assert panel.current is two
    assert panel.choose(1)
    panel.show_targets((one, two), prefer=2)
    assert panel.current is one
    panel.show_targets((two,), prefer=None)
    assert panel.current is two
    panel.show_targets((one, two), prefer=2)
    assert panel.choose(1)
    panel.show_targets((one, two), prefer=1)
    panel.show_targets((one, two), prefer=2)  # another antenna in use: the chooser follows it
    assert panel.current is two


def test_an_electrical_system_shows_its_directions_and_the_one_in_use(qtbot: Any) -> None:
    compass = CompassWidget()
    qtbot.addWidget(compass)
    compass.resize(300, 300)
    target = compass_targets(SNAPSHOT, RadioView(1, 1, 3700.0, tx=11, rx=11), None)[0]
    assert target.rotator.electrical and [d.active for d in target.directions] == [True, False]
    compass.show_target(target)
    assert close(colour_at(compass, 45, 0.72), Colours.DIRECTION)
    assert not close(colour_at(compass, 225, 0.72), Colours.DIRECTION)  # hollow: not in use
    assert not close(colour_at(compass, 135, 0.72), Colours.DIRECTION)
