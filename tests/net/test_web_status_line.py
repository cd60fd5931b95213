"""The web page's status line follows the table of docs/client.md ("The status line"),
walked in real Chromium against the real protocol and web servers (fake backend):
every message with what shows it and each transition that clears it; an unavailable
button's tap and a right-click's Why? answered on the page, sending nothing; the reply
to a phone's tap in view."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

import pytest
from test_web_browser import js, page_until, run, tap
from web_station import FakeWeb, Protocol, Station, browser_missing, viewport

MISSING = browser_missing()
pytestmark = [
    pytest.mark.realtime,
    pytest.mark.shared("chromium"),
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
    pytest.mark.skipif(MISSING is not None, reason=f"no browser to test with: {MISSING}"),
]

PANEL = '.radio[data-radio="1"]'
MESSAGE = f"document.querySelector('{PANEL} .message')"


def antenna(label: str) -> str:
    return f"{PANEL} .grid button[data-id]:not([data-type=\"Function\"])[title^=\"{label} \"]"


def function(label: str) -> str:
    return f"{PANEL} .grid button[data-type=\"Function\"][title^=\"{label} \"]"


async def message(driver: Any) -> str:
    return str(await js(driver, f"return {MESSAGE}.textContent"))


async def shows(driver: Any, text: str, what: str) -> str:
    return str(await page_until(
        driver, f"const t = {MESSAGE}.textContent; return t.includes({text!r}) && t", what=what))


async def cleared(driver: Any, what: str) -> None:
    await page_until(driver, f"return {MESSAGE}.textContent === ''", what=what)


async def screen(driver: Any, name: str) -> None:
    await page_until(driver, f"return document.body.dataset.screen === {name!r}",
                     what=f"the page in state {name}")


@pytest.mark.asyncio
@pytest.mark.timeout(150)
async def test_every_status_message_goes_with_the_state_and_radio_it_was_shown_in(
        browser: Any) -> None:
    page = await FakeWeb.start()
    backend, sent = page.backend, page.sent
    try:
        await run(browser.get, page.url())
        await page_until(browser, f"return document.querySelector('{function('Swap')}')",
                         what="the buttons")
        # an unavailable button: its title and a tap say why, as an answer; nothing sent
        title = await js(browser, f"return document.querySelector('{function('Swap')}').title")
        assert title.startswith("Swap (function 0): unavailable: Swap is not available")
        await tap(browser, function("Swap"))
        text = await shows(browser, "Swap is not available", "the tap on Swap answered")
        assert text.startswith("\u2139 Swap: ")
        assert await js(browser, f"return {MESSAGE}.dataset.tone") == "info"
        assert sent("function") == 0
        # Why? by a right-click on any button: an available one says what a click does
        await run(lambda: __import__("selenium.webdriver.common.action_chains",
                                     fromlist=["ActionChains"]).ActionChains(browser, duration=0)
                  .context_click(browser.find_element("css selector", antenna("Tribander")))
                  .perform())
        assert await shows(browser, "available; a click selects it", "Why? answered") \
            == "\u2139 Tribander: available; a click selects it"

        async def refused_by_server() -> None:
            backend.set_transmitting(1, 1, True)
            await tap(browser, antenna("Tribander"))
            got = await shows(browser, "transmitting", "the server's refusal")
            assert got.startswith("\u26a0 Select Tribander: ")
            assert await js(browser, f"return {MESSAGE}.dataset.tone") == "warning"
            backend.set_transmitting(1, 1, False)

        # connected: the server's refusal goes with the next press...
        await refused_by_server()
        await tap(browser, function("Swap"))
        await shows(browser, "\u2139 Swap", "replaced by the next press's answer")
        # ... and with the switches stopping; a tap then answers "stopped"; Start clears it
        await refused_by_server()
        backend.stop_switches()
        await screen(browser, "switches stopped")
        await cleared(browser, "the refusal gone when the switches stopped")
        selects = sent("select")
        await tap(browser, antenna("Tribander"))
        assert (await shows(browser, "switches are stopped", "the tap answered")).startswith(
            "\u26a0 Select Tribander: the switches are stopped")
        assert sent("select") == selects
        backend.start_switches()
        await screen(browser, "connected")
        await cleared(browser, "the stopped answer gone after Start")
        # a switch not answering, and answering again
        await refused_by_server()
        backend.set_switch_status(1, "unresponsive")
        await screen(browser, "switch unresponsive")
        await cleared(browser, "the refusal gone when the switch stopped answering")
        await refused_by_server()
        backend.set_switch_status(1, "ok")
        await screen(browser, "connected")
        await cleared(browser, "the refusal gone when the switch answered again")
        # no configuration open: the page has no radio to press for (the top bar says so);
        # an answer shown before is not shown again when a configuration opens
        await refused_by_server()
        backend.close_configuration()
        await screen(browser, "no configuration")
        assert "no configuration open" in await js(
            browser, "return document.getElementById('link').textContent")
        backend.load()
        await screen(browser, "connected")
        await cleared(browser, "the answer gone when a configuration opened")
        # not connected: a press answers so ("stopped" is never blamed); connecting clears it
        await page_until(browser, f"return document.querySelector('{antenna('Tribander')}')",
                         what="the buttons again")
        backend.stop_switches()
        await screen(browser, "switches stopped")
        await tap(browser, antenna("Tribander"))
        await shows(browser, "switches are stopped", "the stopped answer")
        await page.stop_serving()
        await screen(browser, "reconnecting")
        await cleared(browser, "the stopped answer gone with the connection")
        await tap(browser, antenna("Tribander"))
        got = await shows(browser, "not connected", "the press answered while disconnected")
        assert got == ("\u26a0 Select Tribander: not connected to the server; "
                       "the page keeps trying"), "never blamed on the stopped switches"
        backend.start_switches()
        await page.serve()
        await screen(browser, "connected")
        await cleared(browser, "the not-connected answer gone once connected")
        assert "Connected" in await js(browser, "return document.getElementById('link')"
                                                ".textContent")
        # another radio chosen: an answer about the first one goes
        await page_until(browser, f"return document.querySelector('{function('Swap')}')",
                         what="the buttons after reconnecting")
        await tap(browser, function("Swap"))
        await shows(browser, "\u2139 Swap", "an answer")
        await js(browser, "const s = document.getElementById('station'); s.value = '2';"
                          "s.dispatchEvent(new Event('change'));")
        await page_until(browser, "return document.querySelector('.radio .title')"
                         ".textContent.startsWith('Station 2')", what="station 2 shown")
        assert await js(browser, "return document.querySelector('.radio .message')"
                                 ".textContent") == ""
    finally:
        await page.close(browser)


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_prev_and_next_without_a_relative_list_say_why_and_send_nothing(
        browser: Any, tmp_path: Path) -> None:
    station = Station(tmp_path)  # the real headless server: its entries carry `relative`
    await station.start_server()
    tcp = await Protocol.connect(station.tcp)
    try:
        await tcp.call("frequency", station=1, radio=1, khz=18100.0)  # 17 m: no list there
        await run(browser.get, station.url + "?station=1&radio=1")
        await page_until(browser, f"return document.querySelector('{PANEL} .next') && "
                                  f"document.querySelector('{PANEL} .next')"
                                  ".getAttribute('aria-disabled') === 'true'",
                         what="Next shown unavailable")
        await tap(browser, f"{PANEL} .next")
        text = await shows(browser, "no relative antenna list", "the tap answered")
        assert text == "\u2139 Relative: there is no relative antenna list at 18100.0 kHz"
        await tcp.call("frequency", station=1, radio=1, khz=14025.0)  # 20 m has one
        await page_until(browser, f"return document.querySelector('{PANEL} .next')"
                                  ".getAttribute('aria-disabled') === 'false'",
                         what="Next usable again")
        before = (await tcp.call("state"))["radios"][0]["tx"]
        await tap(browser, f"{PANEL} .next")

        async def moved() -> bool:
            return (await tcp.call("state"))["radios"][0]["tx"] != before
        for _ in range(100):
            if await moved():
                break
            await asyncio.sleep(0.05)
        else:
            raise AssertionError("Next did not step to the next antenna")
    finally:
        await tcp.close()
        await run(browser.get, "about:blank")
        await station.close()


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_the_answer_to_a_phone_tap_is_in_view(browser: Any) -> None:
    page = await FakeWeb.start()
    try:
        await run(viewport, browser, 390, 844)
        await run(browser.get, page.url())
        await page_until(browser, f"return document.querySelector('{function('Swap')}')",
                         what="the buttons")
        await tap(browser, function("Swap"))
        await shows(browser, "Swap is not available", "the tap answered")
        box = await js(browser, f"const r = {MESSAGE}.getBoundingClientRect();"
                                "return [r.top, r.bottom, innerHeight]")
        top, bottom, height = box
        assert 0 <= top and bottom <= height, f"the answer is out of view: {box}"
    finally:
        await page.close(browser)
