"""The client window's Sources menu: a real rigctld (Hamlib's dummy rig) read by the window,
told to the protocol server on 127.0.0.1, the choice kept in the settings, the window's
active/focus badges from the server's radio entries."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from client_support import LiveServer, run_on_qt
from helpers import free_port, until
from rig_support import rigctl, start_rigctld
from test_client_window import open_window

from moas_gui.ui.client_sources import SETTINGS_KEY, ClientSources
from moas_gui.ui.qt import QApplication, QSettings


@pytest.mark.skipif(shutil.which("rigctld") is None, reason="Hamlib's rigctld")
def test_a_source_chosen_in_the_menu_is_read_told_and_remembered(qapp: QApplication,
                                                                  tmp_path: Path) -> None:
    port = free_port()
    rigctld = start_rigctld(port)
    settings = QSettings(str(tmp_path / "client.ini"), QSettings.Format.IniFormat)

    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            sources = ClientSources(window, settings)
            try:
                assert "Sources" in [a.text().replace("&", "")
                                     for a in window.menuBar().actions()]
                assert not sources.choose("omnirig")
                assert "is not a source" in window.status_text()
                assert sources.choose(f"rigctld:{port},rate=20")
                await until(lambda: (1, 1, 145000.0, None) in live.calls("frequency"),
                            what="the rig's frequency at the server")
                await rigctl(port, "F", "21025000")
                await until(lambda: (1, 1, 21025.0, None) in live.calls("frequency"),
                            what="rigctl's change at the server")
                assert [a.text() for a in sources._listed] == [f"Reading rigctld:{port},rate=20"]
                window.station_box.setCurrentIndex(1)  # the window now shows station 2
                await until(lambda: any(c[0] == 2 for c in live.calls("frequency")),
                            what="the rig told as station 2's radio")
            finally:
                await sources.aclose()
            assert settings.value(SETTINGS_KEY) == [f"rigctld:{port},rate=20"]
            again = ClientSources(window, settings)
            assert [s.text() for s in again.specs] == [f"rigctld:{port},rate=20"]
            again.stop_all()
            await again.aclose()
            assert not settings.value(SETTINGS_KEY)

    try:
        run_on_qt(qapp, scenario())
    finally:
        rigctld.terminate()
        rigctld.wait(5)


def test_the_transmit_and_receive_focus_badges(qapp: QApplication) -> None:
    async def scenario() -> None:
        async with LiveServer() as live, open_window(live) as window:
            assert window.badge_active.isHidden() and window.badge_focus.isHidden()
            await window.connection.active(1, 1)
            await until(lambda: not window.badge_active.isHidden(), what="the TX focus badge")
            assert window.badge_focus.isHidden()
            await window.connection.focus(1, 1)
            await until(lambda: not window.badge_focus.isHidden(), what="the RX focus badge")
            assert live.calls("set_focus") == [(1, 1, "active"), (1, 1, "focus")]

    run_on_qt(qapp, scenario())
