"""The server window under pytest-qt (offscreen): every menu action, the log levels,
the status bar, and the status icon in each state."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from client_support import run_on_qt
from helpers import until

from moas_gui import __version__
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.status import ServerState
from moas_gui.ui.icons import status_icon
from moas_gui.ui.log_view import LogLevel
from moas_gui.ui.qt import QSettings
from moas_gui.ui.server_window import ServerWindow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


class Harness:
    def __init__(self, tmp_path: Path) -> None:
        self.tmp_path = tmp_path
        self.settings_path = tmp_path / "settings.ini"
        self.quit_requests = 0
        self.answers: list[bool] = []
        self.questions: list[str] = []
        self.files: list[str] = []
        self.app: ServerApp | None = None
        self.window: ServerWindow | None = None

    def settings(self) -> QSettings:
        return QSettings(str(self.settings_path), QSettings.Format.IniFormat)

    def make(self) -> ServerWindow:
        self.app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                           udp_bind="127.0.0.1", start_rotator_program=False,
                                           switch_timing=FAST))
        window = ServerWindow(self.app, self.settings(), self._quit)
        window.ask = self._ask
        window.choose_file = lambda title, saving, chosen: chosen(self.files.pop(0))
        self.window = window
        return window

    def _quit(self) -> None:
        self.quit_requests += 1

    def _ask(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        self.questions.append(text)
        answered(self.answers.pop(0))

    async def close(self) -> None:
        if self.window is not None:
            await self.window.idle()
            self.window.shutdown()
            self.window.close()
        if self.app is not None:
            await self.app.close()


@pytest.fixture
def harness(tmp_path: Path) -> Iterator[Harness]:
    yield Harness(tmp_path)


def icon_is(window: ServerWindow, state: ServerState) -> bool:
    return window.windowIcon().cacheKey() == status_icon(state).cacheKey() \
        and window.tray.icon().cacheKey() == status_icon(state).cacheKey()


async def running(harness: Harness, name: str = "small-station") -> tuple[ServerWindow, ServerApp]:
    """A window that has opened example ``name``."""
    window = harness.make()
    window.open_file(str(EXAMPLES / f"{name}.moas"))
    await window.idle()
    assert harness.app is not None
    return window, harness.app


async def running_with_an_antenna(harness: Harness, khz: float) -> tuple[ServerWindow, Any]:
    """A window running small-station whose radio 1 is tuned to ``khz``; returns the
    window and the built-in switch once it holds that antenna's relays."""
    window, app = await running(harness)
    await until(lambda: app.status.state is ServerState.NORMAL)
    app.apply_changes(app.engine.set_frequency(1, 1, khz))
    box = app.emulators()[1]
    await until(lambda: bool(box.view().relays))
    return window, box


def test_a_new_window_shows_no_configuration(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        assert icon_is(window, ServerState.NO_CONFIG)
        assert window.statusBar().currentMessage() == "No configuration open"
        assert not window.action_stop_start.isEnabled()
        assert not window.emulator_menu.menuAction().isVisible()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_file_open_runs_the_file_shows_it_and_remembers_it(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        path = str(EXAMPLES / "small-station.moas")
        harness.files.append(path)
        window.action_open.trigger()
        await window.idle()
        await until(lambda: icon_is(window, ServerState.NORMAL))
        message = window.statusBar().currentMessage()
        assert "small-station.moas" in message and "switch 1 ok" in message and "0 clients" in message
        assert window.windowTitle() == "small-station.moas - MOAS Server"
        assert window.tray.toolTip().startswith("MOAS Server: small-station.moas")
        assert window.recent_files() == [str(Path(path).resolve())]
        assert [a.text() for a in window.recent_menu.actions()] == [f"&1 {Path(path).resolve()}"]
        assert any("Opened small-station.moas" in line for line in window.log_view.shown_lines())
        assert window.emulator_menu.menuAction().isVisible()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_recent_files_keep_the_last_four_and_survive_a_restart(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        names = ["2x6", "small-station", "big-station", "triplexer", "ms-one-amp"]
        for number, name in enumerate(names):
            if number:
                harness.answers.append(True)  # "Stop the running file and open this one?"
            window.open_file(str(EXAMPLES / f"{name}.moas"))
            await window.idle()
        assert [Path(p).stem for p in window.recent_files()] == \
            ["ms-one-amp", "triplexer", "big-station", "small-station"]
        await harness.close()
        again = harness.make()
        assert [Path(p).stem for p in again.recent_files()] == \
            ["ms-one-amp", "triplexer", "big-station", "small-station"]
        harness.questions.clear()
        again.recent_menu.actions()[2].trigger()
        assert harness.questions == []  # nothing runs in the new window: no question
        await again.idle()
        assert harness.app is not None and harness.app.status.file == "big-station.moas"
        await harness.close()
    run_on_qt(qapp, scenario(), timeout=60)


def test_opening_a_second_file_asks_and_no_keeps_the_first(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        harness.answers.append(False)
        window.open_file(str(EXAMPLES / "2x6.moas"))
        await window.idle()
        assert "Stop small-station.moas and open 2x6.moas?" in harness.questions[0]
        assert harness.app is not None and harness.app.status.file == "small-station.moas"
        harness.answers.append(True)
        window.open_file(str(EXAMPLES / "2x6.moas"))
        await window.idle()
        assert harness.app.status.file == "2x6.moas"
        await harness.close()
    run_on_qt(qapp, scenario())


def test_a_broken_file_shows_its_errors_and_the_running_file_carries_on(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        broken = harness.tmp_path / "broken.moas"
        broken.write_text('{\n  "Switches": [{"ID": 1, "Port": "emulator"}]\n  "TCPPort": 1\n}\n')
        harness.answers.append(True)
        window.open_file(str(broken))
        await window.idle()
        assert window.last_dialog is not None
        text = window.last_dialog.text()
        assert str(broken) in text and "running configuration carries on" in text
        assert "line 2, column 46: missing comma" in window.last_dialog.informativeText()
        assert any("broken.moas:2:46" in line for line in window.log_view.shown_lines())
        assert harness.app is not None and harness.app.status.file == "small-station.moas"
        assert str(broken.resolve()) not in window.recent_files()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_log_levels_filter_the_log_and_are_remembered(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.level_actions[LogLevel.ERRORS].trigger()
        assert not any("Opened" in line for line in window.log_view.shown_lines())
        window.level_actions[LogLevel.DEBUG].trigger()
        lines = window.log_view.shown_lines()
        assert any("Opened" in line for line in lines)
        assert any(" debug " in line for line in lines), "debug lines appear at Debug"
        window.level_actions[LogLevel.INFO].trigger()
        assert not any(" debug " in line for line in window.log_view.shown_lines())
        window.level_actions[LogLevel.ERRORS].trigger()
        await harness.close()
        again = harness.make()
        assert again.log_view.level is LogLevel.ERRORS
        assert again.level_actions[LogLevel.ERRORS].isChecked()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_status_bar_can_be_hidden_and_stays_hidden(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.show()
        window.action_status_bar.trigger()
        assert not window.statusBar().isVisible()
        await harness.close()
        again = harness.make()
        again.show()
        assert not again.statusBar().isVisible() and not again.action_status_bar.isChecked()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_stop_and_start_switches_turn_relays_off_and_back_with_icon_and_menu(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, box = await running_with_an_antenna(harness, 14025.0)
        held = box.view().relays
        window.action_stop_start.trigger()
        assert icon_is(window, ServerState.STOPPED)
        assert window.action_stop_start.text() == "S&tart Switches"
        assert window.tray_stop_start.text() == "Start Switches"
        await until(lambda: box.view().relays == frozenset())
        window.tray_stop_start.trigger()
        await until(lambda: box.view().relays == held)
        await until(lambda: icon_is(window, ServerState.NORMAL))
        assert window.action_stop_start.text() == "S&top Switches"
        await harness.close()
    run_on_qt(qapp, scenario())


def test_reset_switches_resets_the_box_and_sets_the_antennas_again(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, box = await running_with_an_antenna(harness, 7025.0)
        held = box.view().relays
        received: list[bytes] = []
        box.add_listener(lambda kind, data=b"": received.append(data) if isinstance(data, bytes) else None)
        window.action_reset.trigger()
        await until(lambda: any(b"*0;" in chunk for chunk in received))
        await until(lambda: box.view().relays == held and box.view().active)
        assert any("Resetting the switches" in line for line in window.log_view.shown_lines())
        await harness.close()
    run_on_qt(qapp, scenario())


def test_save_switch_data_writes_the_chosen_file(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, app = await running(harness)
        await until(lambda: app.status.state is ServerState.NORMAL)
        target = harness.tmp_path / "switch-data.txt"
        harness.files.append(str(target))
        window.action_save_data.trigger()
        await window.idle()
        assert "MOAS II switch 1" in target.read_text()
        assert any("Switch data saved" in line for line in window.log_view.shown_lines())
        await harness.close()
    run_on_qt(qapp, scenario())


def test_restart_reopens_the_same_file(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, app = await running(harness)
        first_engine = app.engine
        window.action_restart.trigger()
        await window.idle()
        assert app.engine is not None and app.engine is not first_engine
        assert app.status.file == "small-station.moas"
        await harness.close()
    run_on_qt(qapp, scenario())


def test_about_names_the_version_and_exit_asks_to_quit(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.action_about.trigger()
        assert window.last_dialog is not None and __version__ in window.last_dialog.text()
        window.action_exit.trigger()
        assert harness.quit_requests == 1
        await harness.close()
    run_on_qt(qapp, scenario())


def test_closing_the_window_without_a_tray_exits(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.show()
        assert not window.tray.isVisible()  # offscreen has no system tray
        window.close()
        assert harness.quit_requests == 1
        await harness.close()
    run_on_qt(qapp, scenario())


def test_view_client_opens_a_client_connected_to_this_server(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.action_client.trigger()  # nothing open yet: a log line, no window
        assert window.client_windows == []
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        app = harness.app
        assert app is not None
        window.action_client.trigger()
        (client,) = window.client_windows
        await until(lambda: client.snapshot is not None, timeout=10)
        assert client.snapshot is not None and len(client.snapshot.radios) == 2
        await until(lambda: "1 client" in window.statusBar().currentMessage())
        client.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_view_emulator_opens_the_built_in_switch(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "big-station.moas"))
        await window.idle()
        actions = window.emulator_menu.actions()
        assert [a.text() for a in actions] == ["Switch 1", "Switch 2"]
        actions[1].trigger()
        emulator_window = window.emulator_windows[2]
        assert emulator_window.isVisible() and "switch 2" in emulator_window.windowTitle()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_a_switch_that_stops_answering_changes_the_icon_and_back(
        qapp: Any, harness: Harness, tmp_path: Path) -> None:
    async def scenario() -> None:
        import asyncio

        link = tmp_path / "moas1"
        box = EmulatedBox()
        endpoint = PtyEndpoint()
        serve(box, endpoint, asyncio.get_running_loop())
        make_link(endpoint.path, link)
        data = json.loads((EXAMPLES / "small-station.moas").read_text())
        data["Switches"][0]["Port"] = str(link)
        config = tmp_path / "pty.moas"
        config.write_text(json.dumps(data))
        window = harness.make()
        window.open_file(str(config))
        await window.idle()
        await until(lambda: icon_is(window, ServerState.NORMAL), timeout=10)
        link.unlink()
        endpoint.close()
        await until(lambda: icon_is(window, ServerState.UNRESPONSIVE), timeout=10)
        assert "switch 1 unresponsive" in window.statusBar().currentMessage()
        again = PtyEndpoint()
        serve(EmulatedBox(), again, asyncio.get_running_loop())
        make_link(again.path, link)
        await until(lambda: icon_is(window, ServerState.NORMAL), timeout=15)
        await harness.close()
        again.close()
    run_on_qt(qapp, scenario(), timeout=60)


def test_built_in_clients_follow_a_new_client_port(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.action_client.trigger()
        (first,) = window.client_windows
        app = harness.app
        assert app is not None and app.client_address is not None
        old_port = app.client_address[1]
        harness.answers.append(True)
        window.open_file(str(EXAMPLES / "2x6.moas"))  # port 0: the system picks another
        await window.idle()
        assert app.client_address is not None and app.client_address[1] != old_port
        (second,) = window.client_windows
        assert second is not first and not first.isVisible()
        assert second.connection.port == app.client_address[1]
        await until(lambda: second.snapshot is not None and second.snapshot.config == "2x6.moas",
                    timeout=10)
        second.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_stop_switches_while_a_station_transmits_asks_first_naming_it(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, box = await running_with_an_antenna(harness, 14025.0)
        app = harness.app
        assert app is not None
        held = box.view().relays
        box.set_tr(1, True)
        await until(lambda: app.keyed_radios() == ["station 1 radio 1 (switch 1 port 1)"])
        harness.answers.append(False)
        window.action_stop_start.trigger()
        assert "Transmitting now:\n  station 1 radio 1 (switch 1 port 1)" in harness.questions[-1]
        assert not app.switches_stopped and box.view().relays == held  # cancelled: nothing
        harness.answers.append(True)
        window.tray_stop_start.trigger()  # the tray asks the same
        assert len(harness.questions) == 2
        assert app.switches_stopped
        await until(lambda: box.view().relays == frozenset())
        assert any("Stop Switches while station 1 radio 1 (switch 1 port 1) transmits, "
                   "confirmed by the operator" in line for line in window.log_view.shown_lines())
        await harness.close()
    run_on_qt(qapp, scenario())


def test_reset_switches_while_a_station_transmits_asks_first_and_a_no_resets_nothing(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, box = await running_with_an_antenna(harness, 14025.0)
        app = harness.app
        assert app is not None
        box.set_tr(1, True)
        await until(lambda: bool(app.keyed_radios()))
        resets = box.record.written
        harness.answers.append(False)
        window.action_reset.trigger()
        assert "Reset Switches resets every switch" in harness.questions[-1]
        await window.idle()
        assert not any(e.event.value == "reset" for e in box.record.after(resets))
        box.set_tr(1, False)
        await until(lambda: app.keyed_radios() == [])
        window.action_reset.trigger()  # nobody transmits: no question, the reset goes
        assert len(harness.questions) == 1
        await until(lambda: any(e.event.value == "reset" for e in box.record.after(resets)))
        await harness.close()
    run_on_qt(qapp, scenario())


def test_a_station_keyed_while_the_question_is_open_is_asked_about_before_anything_happens(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window, box = await running_with_an_antenna(harness, 14025.0)
        app = harness.app
        assert app is not None
        pending: list[tuple[str, Callable[[bool], None]]] = []
        window.ask = lambda title, text, answered: pending.append((text, answered))
        box.set_tr(1, True)
        await until(lambda: len(app.keyed_radios()) == 1)
        window.action_stop_start.trigger()
        text, answered = pending.pop()
        assert "station 1 radio 1" in text and "station 2" not in text
        box.set_tr(2, True)  # the second radio keys while the operator reads
        await until(lambda: len(app.keyed_radios()) == 2)
        answered(True)
        assert not app.switches_stopped  # asked again first
        text, answered = pending.pop()
        assert "station 1 radio 2 (switch 1 port 2)" in text
        answered(True)
        assert app.switches_stopped
        await harness.close()
    run_on_qt(qapp, scenario())


def test_restart_on_a_file_with_a_typo_keeps_the_station_running_and_shows_why(
        qapp: Any, harness: Harness, tmp_path: Path) -> None:
    """File > Restart checks the file first: a typo is shown in a dialog with its line
    and column and the file's path, and the running configuration, its client port and
    band-following carry on (issue 30, point 1)."""
    async def scenario() -> None:
        path = tmp_path / "station.moas"
        path.write_text((EXAMPLES / "small-station.moas").read_text())
        window = harness.make()
        window.open_file(str(path))
        await window.idle()
        app = harness.app
        assert app is not None
        await until(lambda: app.status.state is ServerState.NORMAL)
        address = app.client_address
        data = json.loads(path.read_text())
        data["Antennas"][0]["ID"] = "zero"  # the typo
        path.write_text(json.dumps(data, indent=2))
        window.action_restart.trigger()
        await window.idle()
        dialog = window.last_dialog
        assert dialog is not None and dialog.isVisible()
        assert dialog.windowTitle() == "Not restarted: the file has errors"
        assert str(path) in dialog.text() and "carries on" in dialog.text()
        assert 'line 115, column 13: "ID" of this antenna' in dialog.informativeText()
        assert any(b.text() == "Open Folder" for b in dialog.buttons())
        assert app.config is not None and app.client_address == address
        assert app.status.state is ServerState.NORMAL
        box = app.emulators()[1]
        app.apply_changes(app.engine.set_frequency(1, 1, 14025.0))  # still following
        await until(lambda: bool(box.view().relays))
        await harness.close()
    run_on_qt(qapp, scenario())
