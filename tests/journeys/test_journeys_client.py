"""Journeys through the transitions, seen in both clients at once: the desktop client
window (in this process, on a qasync loop) and the web page (Debian's Chromium), both
on the real ``moas-server`` process with its window (driven through its control hook,
as in test_journeys_server.py).

What a person would see is checked after each step: the selection moving (the
relative list and the rotator chooser follow it), the switches stopped (no antenna
shown selected anywhere, a press answered with the reason), started again, the
server gone (everything greyed, nothing selected, a press answered "not connected"),
and the server back (everything live again)."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

import pytest
from client_support import LOOPBACK, run_on_qt
from helpers import free_port, until
from test_journeys_server import Server, normal
from web_station import blank, browser_missing, wait_in_page

from moas_gui.client import Backoff, ButtonState, ButtonType, ClientConnection, LinkState
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.qt import QApplication, Qt

MISSING = browser_missing()
pytestmark = [
    pytest.mark.realtime,
    pytest.mark.shared("chromium"),
    pytest.mark.skipif(sys.platform == "win32", reason="the journeys run on POSIX"),
    pytest.mark.skipif(MISSING is not None, reason=f"no browser to test with: {MISSING}"),
]

FAST = Backoff(first=0.05, factor=2.0, most=0.3)
PATIENCE = 30.0
"""Seconds any one step may take on a loaded machine before it is taken as not happening."""
THREE_EL, NW, YAGI_ROTATOR, FOUR_SQUARE = 30, 34, 1, 12
"""big-station: the 40 m 3 element Yagi on rotator 1, the 40 m 4-square's NW on system 12."""


class Page:
    """The web page in Chromium, its calls run in a thread (they block)."""

    def __init__(self, driver: Any) -> None:
        self.driver = driver

    async def js(self, script: str) -> Any:
        return await asyncio.to_thread(self.driver.execute_script, script)

    async def until(self, script: str, what: str, timeout: float = PATIENCE) -> Any:
        """The page looks itself (one call to the browser a wait, not one every 50 ms)."""
        return await wait_in_page(self.driver, script, timeout, what)

    async def tap(self, css: str) -> None:
        """A tap where a finger puts it: the pointer there at once (not Selenium's 250 ms glide)."""
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By

        def do() -> None:
            element = self.driver.find_element(By.CSS_SELECTOR, css)
            ActionChains(self.driver, duration=0).move_to_element(element).click().perform()
        await asyncio.to_thread(do)

    async def selected(self) -> list[str]:
        return await self.js(  # type: ignore[no-any-return]
            "return [...document.querySelectorAll('.radio[data-radio=\"1\"] .grid "
            "button[data-state=\"selected\"]')].map(b => b.dataset.id)")

    async def message(self) -> str:
        return await self.js(  # type: ignore[no-any-return]
            "return document.querySelector('.radio[data-radio=\"1\"] .message').textContent")


def shown_selected(window: ClientWindow) -> list[int]:
    return [b.view.id for b in window.grid.buttons if b.shown_state is ButtonState.SELECTED]


def an_antenna_button(window: ClientWindow) -> Any:
    return next(b for b in window.grid.buttons if b.view.type is ButtonType.ANTENNA)


def test_both_clients_tell_the_truth_through_stop_start_loss_and_return(
        qapp: QApplication, qtbot: Any, tmp_path: Path, chromium: Any) -> None:
    web_port = free_port()
    server = Server(tmp_path)
    server.start("big-station.moas", "--web-port", str(web_port))
    driver = chromium  # the worker's (tests/conftest.py), clean, at 1280 x 800
    blank(driver, 1280, 800)
    page = Page(driver)

    async def scenario() -> None:
        await asyncio.to_thread(server.shows, normal("big-station.moas"), "big-station running")
        window = ClientWindow(ClientConnection(LOOPBACK, server.tcp, backoff=FAST, timeout=3.0),
                              station=1, radio=1)
        window.start()
        window.show()
        try:
            await asyncio.to_thread(driver.get, f"http://127.0.0.1:{web_port}/?station=1&radio=1")
            assert server.client({"cmd": "frequency", "station": 1, "radio": 1,
                                  "khz": 7025.0})["ok"]

            # the selection moves: the relative list and the rotator chooser follow it
            moves = ((NW, FOUR_SQUARE), (THREE_EL, YAGI_ROTATOR), (NW, FOUR_SQUARE))
            for antenna, rotator in moves:
                assert server.client({"cmd": "select", "station": 1, "radio": 1,
                                      "antenna": antenna, "exclusive": True})["ok"]
                await until(lambda a=antenna: shown_selected(window) == [a],  # type: ignore[misc]
                            timeout=PATIENCE, what=f"antenna {antenna} selected (desktop)")
                await until(lambda: window.compass_panel.current is not None, timeout=PATIENCE,
                            what=f"the compass on antenna {antenna}'s rotator (desktop)")
                assert window.relative_box.currentText().startswith("\u2714 "), \
                    window.relative_box.currentText()
                assert window.compass_panel.current.rotator.id == rotator
                await page.until(f"return document.querySelector('.radio[data-radio=\"1\"] "
                                 f".rotator').value === '{rotator}'",
                                 f"the web chooser on rotator {rotator}")
                # the buttons come with the layout event, which may follow the radio's
                await page.until(f"return [...document.querySelectorAll('.radio[data-radio="
                                 f"\"1\"] .grid button[data-state=\"selected\"]')]"
                                 f".map(b => b.dataset.id).join() === '{antenna}'",
                                 f"antenna {antenna} selected on the page")
            assert "\u25b8NW" in await page.js("return document.querySelector("
                                               "'.radio[data-radio=\"1\"] .rel-list').textContent")

            # the switches stop: no antenna is shown selected anywhere; a press is answered
            server.click("File", "Stop Switches")
            await until(lambda: window.switches_stopped, timeout=PATIENCE,
                        what="the stop in the desktop client")
            assert shown_selected(window) == [] and window.grid.greyed
            assert window.display.text() == "Switches stopped: no antenna is connected"
            assert not any("\u2714" in window.relative_box.itemText(i)
                           for i in range(window.relative_box.count()))
            qtbot.mouseClick(an_antenna_button(window), Qt.MouseButton.LeftButton)
            assert "the switches are stopped" in window.status_text()
            await page.until("return document.body.dataset.screen === 'switches stopped'",
                             "the stop on the page")
            assert await page.selected() == []
            await page.tap('.radio[data-radio="1"] .grid button[data-type="Antenna"]')
            assert "the switches are stopped" in await page.message()

            # started again: the selection is back on both
            server.click("File", "Start Switches")
            await until(lambda: shown_selected(window) == [NW], timeout=PATIENCE,
                        what="NW back on the desktop")
            await page.until(f"return document.querySelector('.radio[data-radio=\"1\"] .grid "
                             f"button[data-id=\"{NW}\"]').dataset.state === 'selected'",
                             "NW back on the page")

            # the server goes: greyed, nothing selected, no heading, a press answered
            server.click("Tray", "Exit")
            assert await asyncio.to_thread(server.ends) == 0
            await until(lambda: window.link_state is LinkState.RECONNECTING,
                        timeout=PATIENCE, what="the desktop client noticing")
            assert shown_selected(window) == [] and window.grid.greyed
            assert window.compass_panel.compass.greyed
            assert window.compass_panel.heading_label.text() == "not connected"
            qtbot.mouseClick(an_antenna_button(window), Qt.MouseButton.LeftButton)
            assert "not connected to the server" in window.status_text()
            await page.until("return document.body.dataset.link === 'not-connected'",
                             "not connected on the page")
            assert await page.selected() == []
            assert await page.js("return document.querySelector('.radio[data-radio=\"1\"] "
                                 ".freq').textContent") == ("Not connected: the antennas in "
                                                            "use are not known")
            assert await page.js("return document.querySelectorAll('.radio[data-radio=\"1\"] "
                                 ".compass .needle').length") == 0, "no heading drawn"
            await page.tap('.radio[data-radio="1"] .grid button[data-type="Antenna"]')
            assert "not connected" in await page.message()

            # the server comes back: both are live again by themselves
            await asyncio.to_thread(server.start, "big-station.moas", "--web-port", str(web_port))
            await until(lambda: window.link_state is LinkState.CONNECTED
                        and not window.grid.greyed, timeout=PATIENCE, what="the desktop client back")
            await page.until("return document.body.dataset.screen === 'connected'",
                             "the page back")
            assert window.status_text() == ""
        finally:
            await window.aclose()
            window.close()
            window.deleteLater()

    try:
        run_on_qt(qapp, scenario(), timeout=240)
    finally:
        try:
            blank(driver)  # the page leaves, and the next test finds the browser clean
        finally:
            server.stop()
