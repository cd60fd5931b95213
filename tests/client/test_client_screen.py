"""The one table of screen states (moas_gui/client/screen.py) and the desktop pieces
that follow it: the relative list marks and follows the antenna in use, the
compass marks no 4-square direction while the switches are stopped, and a
greyed button shows no state."""

from __future__ import annotations

import pytest

from moas_gui.client import (
    AntennaView,
    ButtonState,
    ButtonType,
    ButtonView,
    LinkState,
    RadioView,
    RotatorView,
    Snapshot,
    SwitchView,
)
from moas_gui.client.screen import Screen, screen_state
from moas_gui.ui.button_grid import LayoutButton
from moas_gui.ui.client_panels import RelativeStrip
from moas_gui.ui.compass import compass_targets
from moas_gui.ui.qt import QApplication

ANTENNAS = (AntennaView(1, "3el", "40 m 3 element"), AntennaView(2, "NW", "4-square NW", 9, 315),
            AntennaView(3, "SE", "4-square SE", 9, 135))
ROTATORS = (RotatorView(9, "4sq", electrical=True),)


def snapshot(*statuses: str, config: str = "station.moas") -> Snapshot:
    radio = RadioView(1, 1, khz=7025.0, tx=2, rx=2, relative=(1, 2, 3))
    return Snapshot(config=config, radios=(radio,), antennas=ANTENNAS, rotators=ROTATORS,
                    switches=tuple(SwitchView(i + 1, s) for i, s in enumerate(statuses)))


@pytest.mark.parametrize(("link", "snap", "screen", "selected", "selects", "turns"), [
    (LinkState.CONNECTED, snapshot("ok"), Screen.CONNECTED, True, True, True),
    (LinkState.RECONNECTING, snapshot("ok"), Screen.RECONNECTING, False, False, False),
    (LinkState.CONNECTING, None, Screen.RECONNECTING, False, False, False),
    (LinkState.CLOSED, snapshot("ok"), Screen.RECONNECTING, False, False, False),
    (LinkState.CONNECTED, snapshot(config=""), Screen.NO_CONFIGURATION, False, False, False),
    (LinkState.CONNECTED, snapshot("stopped", "stopped"), Screen.STOPPED, False, False, True),
    (LinkState.CONNECTED, snapshot("ok", "unresponsive"), Screen.UNRESPONSIVE, True, True, True),
])
def test_the_table_of_screen_states(link: LinkState, snap: Snapshot | None, screen: Screen,
                                    selected: bool, selects: bool, turns: bool) -> None:
    state = screen_state(link, snap)
    assert state.screen is screen
    assert (state.shows_selection, state.can_select, state.can_turn) == (selected, selects, turns)
    assert bool(state.refusal) is not selects
    assert "None" not in state.refusal


def test_unresponsive_names_the_switches() -> None:
    assert screen_state(LinkState.CONNECTED, snapshot("ok", "connecting", "unresponsive")
                        ).unresponsive == (2, 3)


def test_the_relative_list_marks_and_follows_the_antenna_in_use(qapp: QApplication) -> None:
    strip = RelativeStrip()
    snap = snapshot("ok")
    radio = snap.radios[0]
    strip.show_list(radio, snap)
    assert strip.list_box.currentText() == "\u2714 2. 4-square NW"
    strip.list_box.setCurrentIndex(2)  # the operator looks further down the list
    strip.show_list(radio, snap)       # a frequency report: same antenna in use
    assert strip.list_box.currentIndex() == 2
    moved = RadioView(1, 1, khz=7025.0, tx=1, rx=1, relative=(1, 2, 3))
    strip.show_list(moved, snap)
    assert strip.list_box.currentText() == "\u2714 1. 40 m 3 element"
    strip.show_list(moved, snap, mark=False)  # stopped: nothing is in use
    assert not any("\u2714" in strip.list_box.itemText(i) for i in range(3))


def test_no_direction_is_in_use_while_the_switches_are_stopped() -> None:
    snap = snapshot("ok")
    live = compass_targets(snap, snap.radios[0], None)
    assert [d.active for d in live[0].directions] == [True, False]
    stopped = compass_targets(snap, snap.radios[0], None, selection_known=False)
    assert [d.active for d in stopped[0].directions] == [False, False]


def test_a_greyed_button_shows_no_state_and_can_be_pressed(qapp: QApplication) -> None:
    button = LayoutButton(ButtonView(0, 0, ButtonType.ANTENNA, 7, "Beam", ButtonState.SELECTED))
    assert button.shown_state is ButtonState.SELECTED
    button.set_greyed("not connected to the server")
    assert button.shown_state is None and button.isEnabled()
    assert button.toolTip() == "Beam (antenna 7): not connected to the server"
    button.show_view(ButtonView(0, 0, ButtonType.ANTENNA, 7, "Beam", ButtonState.UNAVAILABLE))
    assert button.isEnabled(), "greyed, even an unavailable button answers a press"
    button.set_greyed("")
    assert button.shown_state is ButtonState.UNAVAILABLE
    assert button.toolTip() == "Beam (antenna 7): unavailable"
