"""The client window against the real protocol server (fake backend) on 127.0.0.1.

Each test runs on a qasync loop (``run_on_qt``): clicks go through pytest-qt's
``qtbot``, and the test then waits for what the server answers to show up.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import AsyncIterator
from typing import Any

from client_support import LOOPBACK, LiveServer, run_on_qt
from helpers import until

from moas_gui.client import Backoff, ButtonState, ButtonType, ClientConnection, LinkState
from moas_gui.ui.button_grid import LayoutButton
from moas_gui.ui.client_window import ClientWindow, loopback_for, open_builtin_client
from moas_gui.ui.qt import QApplication, QContextMenuEvent, Qt

FAST = Backoff(first=0.02, factor=2.0, most=0.1)


@contextlib.asynccontextmanager
async def open_window(live: LiveServer, **kwargs: Any) -> AsyncIterator[ClientWindow]:
    connection = ClientConnection(LOOPBACK, live.port, backoff=FAST, timeout=2.0)
    window = ClientWindow(connection, **kwargs)
    window.start()
    window.show()
    try:
        await until(lambda: window.grid.buttons and not window.grid.greyed,
                    what="the window connecting and showing its buttons")
        yield window
    finally:
        await window.aclose()
        window.close()
        window.deleteLater()


def button(window: ClientWindow, label: str) -> LayoutButton:
    for candidate in window.grid.buttons:
        if candidate.view.label == label:
            return candidate
    raise AssertionError(f"no button {label!r}; the grid has "
                         f"{[b.view.label for b in window.grid.buttons]}")


def states(window: ClientWindow) -> dict[str, str]:
    return {b.view.label: b.view.state.value for b in window.grid.buttons}


def test_the_window_connects_and_shows_the_radios(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert window.link_state is LinkState.CONNECTED
            assert "Connected to 127.0.0.1" in window.link_label.text()
            assert [window.station_box.itemText(i) for i in range(window.station_box.count())] \
                == ["1", "2"]
            assert window.radio_box.count() == 1 and window.radio == 1
            assert window.config_label.text() == "fake two-station.moas"
            text = window.display.text()
            assert "14025.0 kHz" in text and "TX  20m stack all" in text
            assert "RX  20m stack all" in text
            assert window.khz_box.value() == 14025.0
            assert live.calls("layout")[-1] == (1, 1, 4, 3)

            window.station_box.setCurrentIndex(1)
            await until(lambda: "7025.0 kHz" in window.display.text(), what="station 2")
            assert "40m 2-element Yagi" in window.display.text()
            await until(lambda: "40 Beam" in states(window), what="station 2's buttons")

    run_on_qt(qapp, scenario())


def test_the_grid_shows_the_layout_buttons_with_their_states(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert states(window) == {"20 Stack": "selected", "Tribander": "available",
                                      "Swap": "unavailable", "RX=TX": "unavailable"}
            assert [(b.view.row, b.view.column) for b in window.grid.buttons] == [
                (0, 0), (0, 1), (3, 0), (3, 1)]
            assert button(window, "Swap").toolTip().startswith(
                "Swap (function 0): unavailable: Swap is not available")
            assert button(window, "Swap").view.type is ButtonType.FUNCTION
            assert (window.grid.rows, window.grid.columns) == (4, 3)

            window.rows_box.setValue(1)
            window.columns_box.setValue(10)
            await until(lambda: "Swap" not in states(window), what="the 1 x 10 layout")
            assert live.calls("layout")[-1] == (1, 1, 1, 10)
            assert states(window) == {"20 Stack": "selected", "Tribander": "available"}

    run_on_qt(qapp, scenario())


def test_clicking_a_button_sends_select_and_the_new_state_shows(qapp: QApplication,
                                                                 qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            await until(lambda: states(window)["Tribander"] == "selected",
                        what="the Tribander button turning selected")
            assert live.calls("select") == [(1, 1, 1, "both", False)]
            assert states(window)["20 Stack"] == "available"
            assert "TX  TH6 tribander" in window.display.text()
            assert window.status_text() == ""

    run_on_qt(qapp, scenario())


def test_an_unavailable_button_answers_a_click_with_its_reason_and_sends_nothing(
        qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            swap = button(window, "Swap")
            assert swap.view.state is ButtonState.UNAVAILABLE
            qtbot.mouseClick(swap, Qt.MouseButton.LeftButton)
            qtbot.mouseDClick(swap, Qt.MouseButton.LeftButton)
            await until(lambda: window.pending == 0)
            assert live.calls("function") == []
            assert live.calls("select") == []
            # the answer is the reason, as an answer (not a warning), whole
            assert window.status_text() == f"\u2139 Swap: {swap.view.reason}"
            assert window.message is not None and window.message.tone.value == "info"
            assert window.status_line.property("tone") == "info"
            assert window.last_error == ""

    run_on_qt(qapp, scenario())


def _why_by_right_click(qtbot: Any, window: ClientWindow, target: LayoutButton) -> None:
    """A right-click on ``target``, then Why? in the menu that opens (no nested loop)."""
    centre = target.rect().center()
    QApplication.sendEvent(target, QContextMenuEvent(QContextMenuEvent.Reason.Mouse, centre,
                                                     target.mapToGlobal(centre)))
    menu = QApplication.activePopupWidget()
    assert menu is not None, "the right-click opened a menu"
    assert [a.text() for a in menu.actions()] == ["Why?"]
    menu.actions()[0].trigger()
    menu.close()


def test_why_on_any_button_enabled_or_not_answers_with_the_deciding_reason(
        qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            swap = button(window, "Swap")
            _why_by_right_click(qtbot, window, swap)
            assert window.status_text() == f"\u2139 Swap: {swap.view.reason}"
            _why_by_right_click(qtbot, window, button(window, "Tribander"))
            assert window.status_text() == "\u2139 Tribander: available; a click selects it"
            _why_by_right_click(qtbot, window, button(window, "20 Stack"))
            assert window.status_text().startswith("\u2139 20 Stack: in use by this radio")
            # greyed by a stop: every button answers with what greys it
            live.backend.stop_switches()
            await until(lambda: window.switches_stopped)
            _why_by_right_click(qtbot, window, swap)
            assert window.status_text() == ("\u2139 Swap: the switches are stopped; start "
                                            "them on the server (File > Start Switches)")
            assert live.calls("function") == [] and live.calls("select") == []

    run_on_qt(qapp, scenario())


def test_every_status_message_goes_with_the_state_and_radio_it_was_shown_in(
        qapp: QApplication, qtbot: Any) -> None:
    """The status line's table (docs/client.md): each message, what shows it, and each
    transition that clears it, walked in the real window against a real server."""
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            backend = live.backend

            async def refused_by_server() -> None:
                window.relative_box.setCurrentIndex(5)
                qtbot.mouseClick(window.relative_go, Qt.MouseButton.LeftButton)
                await until(lambda: "there is no index 5" in window.status_text(),
                            what="the server's refusal")
                assert window.status_text().startswith("\u26a0 Relative:")

            # connected: a server's refusal; cleared by the next press
            await refused_by_server()
            qtbot.mouseClick(button(window, "Swap"), Qt.MouseButton.LeftButton)
            assert window.status_text().startswith("\u2139 Swap:"), "replaced by the answer"
            # ... by the switches stopping; a press then answers "stopped"
            await refused_by_server()
            backend.stop_switches()
            await until(lambda: window.switches_stopped)
            assert window.status_text() == ""
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            assert "the switches are stopped" in window.status_text()
            # ... which Start clears
            backend.start_switches()
            await until(lambda: not window.grid.greyed)
            assert window.status_text() == ""
            # a switch not answering: a refusal shown before it goes, and one shown
            # while it lasts goes when it answers again
            await refused_by_server()
            backend.set_switch_status(1, "unresponsive")
            await until(lambda: "not answering" in window.link_label.text())
            assert window.status_text() == ""
            await refused_by_server()
            backend.set_switch_status(1, "connected")
            await until(lambda: "not answering" not in window.link_label.text())
            assert window.status_text() == ""
            # no configuration: a press answers so; a configuration opening clears it
            backend.close_configuration()
            await until(lambda: window.screen_now.screen.value == "no configuration")
            qtbot.mouseClick(window.next_button, Qt.MouseButton.LeftButton)
            assert window.status_text() == ("\u26a0 Relative: the server has no "
                                            "configuration open")
            backend.load()
            await until(lambda: window.screen_now.screen.value == "connected")
            assert window.status_text() == ""
            await until(lambda: window.grid.buttons and not window.grid.greyed)
            # another radio: an answer about this one goes
            await refused_by_server()
            window.station_box.setCurrentIndex(1)
            await until(lambda: window.station == 2)
            assert window.status_text() == ""
            # not connected: a press answers "not connected"; connecting again clears it
            await live.stop()
            await until(lambda: window.link_state is LinkState.RECONNECTING)
            qtbot.mouseClick(window.next_button, Qt.MouseButton.LeftButton)
            assert "Relative: not connected" in window.status_text()
            await live.start()
            await until(lambda: window.link_state is LinkState.CONNECTED)
            await until(lambda: window.status_text() == "",
                        what="the not-connected answer gone once connected")

    run_on_qt(qapp, scenario())


def test_double_click_asks_for_the_exclusive_selection(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            qtbot.mouseDClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            await until(lambda: (1, 1, 1, "both", True) in live.calls("select"),
                        what="the exclusive select")
            assert live.calls("select")[-1] == (1, 1, 1, "both", True)
            await until(lambda: states(window)["Tribander"] == "selected")

    run_on_qt(qapp, scenario())


def test_rx_only_picks_a_different_receive_antenna(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            window.khz_box.setValue(7150.0)
            qtbot.mouseClick(window.frequency_button, Qt.MouseButton.LeftButton)
            await until(lambda: "Bev NE" in states(window), what="the 40 m buttons")
            assert live.calls("frequency") == [(1, 1, 7150.0, None)]
            assert states(window)["40 Beam"] == "unavailable"  # station 2 has it

            qtbot.mouseClick(window.target_buttons["rx"], Qt.MouseButton.LeftButton)
            assert window.target == "rx"
            qtbot.mouseClick(button(window, "Bev NE"), Qt.MouseButton.LeftButton)
            await until(lambda: "RX  Beverage north-east" in window.display.text(),
                        what="the receive antenna changing")
            assert live.calls("select") == [(1, 1, 6, "rx", False)]
            assert "TX  40m inverted V" in window.display.text()
            assert states(window)["Bev NE"] == "selected"
            assert states(window)["40 Dipole"] == "selected"

    run_on_qt(qapp, scenario())


def test_function_buttons_run_their_function(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            qtbot.mouseClick(window.target_buttons["tx"], Qt.MouseButton.LeftButton)
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            await until(lambda: states(window)["RX=TX"] == "available",
                        what="RX=TX becoming available once TX and RX differ")
            assert "RX  20m stack all" in window.display.text()
            qtbot.mouseClick(button(window, "RX=TX"), Qt.MouseButton.LeftButton)
            await until(lambda: "RX  TH6 tribander" in window.display.text(),
                        what="RX=TX taking effect")
            assert live.calls("function") == [(1, 1, 1)]

    run_on_qt(qapp, scenario())


def test_relative_strip_steps_and_picks_by_index(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            qtbot.mouseClick(window.next_button, Qt.MouseButton.LeftButton)
            await until(lambda: "TX  TH6 tribander" in window.display.text(), what="next")
            qtbot.mouseClick(window.previous_button, Qt.MouseButton.LeftButton)
            await until(lambda: "TX  20m stack all" in window.display.text(), what="previous")
            window.relative_box.setCurrentIndex(1)
            qtbot.mouseClick(window.relative_go, Qt.MouseButton.LeftButton)
            await until(lambda: "TX  TH6 tribander" in window.display.text(), what="index 1")
            assert live.calls("relative") == [(1, 1, 1, None), (1, 1, -1, None),
                                              (1, 1, None, 1)]

    run_on_qt(qapp, scenario())


def test_frequency_box_sends_split_frequencies(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            window.khz_box.setValue(14100.0)
            qtbot.mouseClick(window.split_box, Qt.MouseButton.LeftButton)
            assert window.tx_khz_box.isEnabled()
            window.tx_khz_box.setValue(14150.5)
            qtbot.mouseClick(window.frequency_button, Qt.MouseButton.LeftButton)
            await until(lambda: "RX 14100.0  TX 14150.5 kHz" in window.display.text(),
                        what="the split frequency showing")
            assert live.calls("frequency") == [(1, 1, 14100.0, 14150.5)]

    run_on_qt(qapp, scenario())


def test_transmitting_and_inhibited_are_shown_with_the_reason(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert window.badge_tx.isHidden() and window.badge_inhibit.isHidden()
            live.backend.set_transmitting(1, 1, True)
            await until(lambda: not window.badge_tx.isHidden(), what="the TX badge")
            live.backend.set_transmitting(1, 1, False)
            await until(lambda: window.badge_tx.isHidden(), what="the TX badge going")

            await window.connection.frequency(1, 1, 50100.0)
            await until(lambda: not window.badge_inhibit.isHidden(), what="the inhibit badge")
            assert window.note_label.text() == "no free antenna covers 50100 kHz"
            assert not window.note_label.isHidden()
            assert "TX  none" in window.display.text()

    run_on_qt(qapp, scenario())


def test_a_hold_is_shown_with_who_holds_it_and_goes_when_released(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert window.note_label.isHidden()
            live.backend.set_held(1, 1, "an Antenna Genius client at 192.168.1.20")
            await until(lambda: not window.note_label.isHidden(), what="the hold")
            assert window.note_label.text() == ("Held by an Antenna Genius client at "
                                                "192.168.1.20: the antennas do not follow "
                                                "the frequency")
            live.backend.set_held(1, 1, None)
            await until(lambda: window.note_label.isHidden(), what="the hold released")

    run_on_qt(qapp, scenario())


def test_server_errors_are_shown_in_the_status_line(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            window.relative_box.setCurrentIndex(5)
            qtbot.mouseClick(window.relative_go, Qt.MouseButton.LeftButton)
            await until(lambda: window.status_text(), what="the refusal in the status line")
            assert "Relative: the relative list of station 1 radio 1" in window.status_text()
            assert "there is no index 5" in window.status_text()

            live.backend.stop_switches()
            await until(lambda: window.switches_stopped, what="the switches shown stopped")
            assert window.status_text() == "", "the old refusal is gone"
            window._pressed(button(window, "Tribander").view, False)  # a click racing the stop
            await until(lambda: "switches are stopped" in window.status_text())
            assert window.status_text().startswith("\u26a0 Select Tribander:")
            assert window.isVisible()

    run_on_qt(qapp, scenario())


def test_stopped_switches_show_no_antenna_and_start_clears_the_refusal(
        qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert "Connected" in window.link_label.text()
            live.backend.stop_switches()
            await until(lambda: "Switches stopped" in window.link_label.text(),
                        what="the stop in the link line")
            assert "Connected" not in window.link_label.text()
            assert window.display.text() == "Switches stopped: no antenna is connected"
            assert "TX" not in window.display.text()
            # no antenna is shown selected anywhere: not the buttons, not the relative list
            assert all(b.shown_state is None for b in window.grid.buttons)
            assert "switches are stopped" in button(window, "20 Stack").toolTip()
            assert not any("\u2714" in window.relative_box.itemText(i)
                           for i in range(window.relative_box.count()))
            selects = len(live.calls("select"))
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            await until(lambda: "switches are stopped" in window.status_text(),
                        what="the click answered, not dropped")
            assert window.status_text().startswith("\u26a0 Select Tribander: the switches")
            assert len(live.calls("select")) == selects, "nothing was sent"
            qtbot.mouseClick(window.frequency_button, Qt.MouseButton.LeftButton)
            assert "Frequency: the switches are stopped" in window.status_text()
            window._pressed(button(window, "Tribander").view, False)  # a click racing the stop
            await until(lambda: "switches are stopped" in window.status_text())
            live.backend.start_switches()
            await until(lambda: not window.grid.greyed, what="the grid usable again")
            assert window.status_text() == "", "the refusal is gone after Start"
            assert "Connected" in window.link_label.text()
            assert "TX" in window.display.text()

    run_on_qt(qapp, scenario())


def test_reconnects_after_the_server_restarts(qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            await live.stop()
            await until(lambda: window.link_state is LinkState.RECONNECTING,
                        what="the window noticing the loss")
            assert "trying again in" in window.link_label.text()
            # greyed, nothing shown selected, the compass greyed, a click answered
            assert window.grid.greyed and all(b.shown_state is None
                                              for b in window.grid.buttons)
            assert window.display.text() == "Not connected: the antennas in use are not known"
            assert window.compass_panel.compass.greyed
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            assert window.status_text() == ("\u26a0 Select Tribander: not connected to the "
                                            "server; the window keeps trying")
            qtbot.mouseClick(window.next_button, Qt.MouseButton.LeftButton)
            assert "Relative: not connected" in window.status_text()
            layouts_before = len(live.calls("layout"))

            await live.start()
            await until(lambda: window.link_state is LinkState.CONNECTED,
                        what="the window reconnecting")
            await until(lambda: len(live.calls("layout")) > layouts_before,
                        what="the layout asked again")
            await until(lambda: not window.grid.greyed)
            assert window.status_text() == "", "the local answer is gone once connected"
            qtbot.mouseClick(button(window, "Tribander"), Qt.MouseButton.LeftButton)
            await until(lambda: states(window)["Tribander"] == "selected",
                        what="a press after reconnecting")

    run_on_qt(qapp, scenario())


def test_open_builtin_client_connects_over_loopback(qapp: QApplication) -> None:
    class ServerAppStandIn:
        def __init__(self, port: int) -> None:
            self.client_address = ("0.0.0.0", port)
            self.client_fingerprint = None  # no TLS

    async def scenario() -> None:
        async with LiveServer() as live:
            window = open_builtin_client(ServerAppStandIn(live.port))
            try:
                assert window.isVisible()
                assert window.connection.host == "127.0.0.1"
                await until(lambda: window.grid.buttons, what="the built-in client's buttons")
                assert any(info.name == "built-in client"
                           for info in live.server.clients())  # type: ignore[union-attr]
            finally:
                await window.aclose()
                window.close()

    run_on_qt(qapp, scenario())
    assert loopback_for("::") == "::1" and loopback_for("10.0.0.5") == "10.0.0.5"


def test_a_refusal_clears_when_another_configuration_arrives(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            live.backend.stop_switches()
            await until(lambda: window.switches_stopped)
            window._pressed(button(window, "Tribander").view, False)
            await until(lambda: "switches are stopped" in window.status_text())
            live.backend.load()  # the server opens a configuration: a new state for everyone
            await until(lambda: window.status_text() == "", what="the old refusal gone")

    run_on_qt(qapp, scenario())


def test_a_request_cancelled_before_it_starts_leaves_no_unawaited_coroutine(
        qapp: QApplication) -> None:
    import gc
    import warnings

    async def asked() -> None:
        await asyncio.sleep(0)

    async def scenario() -> None:
        async with LiveServer() as live:
            connection = ClientConnection(LOOPBACK, live.port, backoff=FAST, timeout=2.0)
            window = ClientWindow(connection)
            window.start()
            window._spawn(asked(), "Layout")  # and the window closes before it runs
            await window.aclose()
            window.close()
            window.deleteLater()

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        run_on_qt(qapp, scenario())
        gc.collect()
    assert not [w for w in seen if "never awaited" in str(w.message)], [str(w.message) for w in seen]
