"""Holds where operators look (issue 40): the desktop client window and the server window
show a hold with who set it and since when, and offer Release to whoever may release it.
Real windows under pytest-qt (offscreen) on a qasync loop; the real server in process with
its switch in the built-in emulator, an Antenna Genius program over real TCP."""

from __future__ import annotations

import contextlib
import logging
import time
from collections.abc import AsyncIterator
from datetime import datetime
from pathlib import Path
from typing import Any

import pytest
from ag_client import AgClient
from client_support import LOOPBACK, LiveServer, run_on_qt
from helpers import EXAMPLES, until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.client import Backoff, ClientConnection
from moas_gui.engine.operations import Hold, SetFrequency
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.operators import OperatorBook, Role
from moas_gui.status import ServerState
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.qt import QApplication, QSettings, Qt
from moas_gui.ui.server_window import ServerWindow

FAST_LINK = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)
FAST = Backoff(first=0.02, factor=2.0, most=0.1)


def server_app() -> ServerApp:
    return ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                   udp_bind="127.0.0.1", start_rotator_program=False,
                                   switch_timing=FAST_LINK, ag_port=0))


@contextlib.asynccontextmanager
async def client_window(port: int, token: str | None = None) -> AsyncIterator[ClientWindow]:
    connection = ClientConnection(LOOPBACK, port, backoff=FAST, timeout=2.0, token=token)
    window = ClientWindow(connection, station=1, radio=1)
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


def test_the_client_window_shows_since_when_and_release_frees_the_radio(
        qapp: QApplication, qtbot: Any) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, client_window(live.port) as window:
            assert window.release_button.isHidden()
            live.backend.set_held(1, 1, "Log4YM at 192.168.1.20", "2026-11-29T08:14:03Z")
            await until(lambda: not window.note_label.isHidden(), what="the hold")
            shown = datetime.fromisoformat("2026-11-29T08:14:03Z").astimezone()
            clock = shown.strftime("%H:%M" if shown.date() == datetime.now().date()
                                   else "%Y-%m-%d %H:%M")
            assert window.note_label.text() == (f"Held by Log4YM at 192.168.1.20 since {clock}:"
                                                " the antennas do not follow the frequency")
            assert not window.release_button.isHidden()  # this computer may release
            qtbot.mouseClick(window.release_button, Qt.MouseButton.LeftButton)
            await until(lambda: window.note_label.isHidden(), what="the hold released")
            assert live.calls("release") == [(1, 1)]
            assert window.release_button.isHidden()

    run_on_qt(qapp, scenario())


def test_release_is_offered_to_the_operator_whose_role_covers_the_radio_only(
        qapp: QApplication, qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    book = OperatorBook()
    ann = book.add("Ann", Role.OPERATE, frozenset({(1, 1)}))[1]
    bob = book.add("Bob", Role.OPERATE, frozenset({(1, 2)}))[1]
    vic = book.add("Vic", Role.VIEW)[1]

    async def scenario() -> None:
        app = server_app()
        try:
            assert (await app.open(EXAMPLES / "small-station.moas")).ok
            await until(lambda: app.status.state is ServerState.NORMAL)
            app.act(SetFrequency(1, 1, 14025.0))
            program = await AgClient.connect(app.ag_ports[0])
            assert (await program.ask("port set 1 auto=0 txant=4 rxant=4")).code == 0
            await program.close()  # the program goes away; its hold stays
            address = app.client_address
            assert address is not None
            async with client_window(address[1], ann) as mine, \
                    client_window(address[1], bob) as others, \
                    client_window(address[1], vic) as looking:
                for window in (mine, others, looking):
                    await until(lambda w=window: not w.note_label.isHidden(), what="the hold")
                    assert window.note_label.text().startswith(
                        "Held by an Antenna Genius client at 127.0.0.1 since ")
                assert not mine.release_button.isHidden()
                assert others.release_button.isHidden()  # not its radio
                assert looking.release_button.isHidden()  # the view role
                qtbot.mouseClick(mine.release_button, Qt.MouseButton.LeftButton)
                engine = app.engine
                assert engine is not None
                await until(lambda: engine.radio_view(1, 1).held_by is None, what="released")
                for window in (mine, others, looking):
                    await until(lambda w=window: w.note_label.isHidden(), what="no hold shown")
                    assert window.release_button.isHidden()
        finally:
            await app.close()

    run_on_qt(qapp, scenario())


def test_the_server_window_lists_holds_and_its_release_frees_the_radio(
        qapp: QApplication, qtbot: Any, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)

    async def scenario() -> None:
        app = server_app()
        window = ServerWindow(app, QSettings(str(tmp_path / "s.ini"),
                                             QSettings.Format.IniFormat), lambda: None)
        try:
            window.resize(1024, 600)
            window.show()
            assert (await app.open(EXAMPLES / "small-station.moas")).ok
            await until(lambda: app.status.state is ServerState.NORMAL)
            assert window.holds_bar.isHidden()
            app.act(Hold(1, 2, "AetherSDR at 192.168.1.20", since=time.time()))
            await until(lambda: not window.holds_bar.isHidden(), what="the holds bar")
            (line,) = window.holds_bar.lines
            assert line.text().startswith("\u26a0 Station 1 radio 2: held by AetherSDR at "
                                          "192.168.1.20 since ")
            assert line.text().endswith("; its antennas do not follow its frequency")
            qtbot.mouseClick(window.holds_bar.buttons[0], Qt.MouseButton.LeftButton)
            await until(lambda: window.holds_bar.isHidden(), what="the bar gone")
            engine = app.engine
            assert engine is not None and engine.radio_view(1, 2).held_by is None
            assert any("The server window released the hold of radio 1/2 (held by AetherSDR "
                       "at 192.168.1.20)" in r.getMessage() for r in caplog.records)
        finally:
            await window.idle()
            window.shutdown()
            window.close()
            await app.close()

    run_on_qt(qapp, scenario())
