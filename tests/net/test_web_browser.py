"""The browser client in a real browser: Debian's Chromium, headless, driven by Selenium,
against ``moas-server --headless`` and an emulated switch on a pseudo-terminal.

Selenium's calls block, so each runs in a thread: the emulator in this process keeps
answering the server meanwhile."""

from __future__ import annotations

import asyncio
import re
import sys
from collections.abc import AsyncIterator, Callable
from pathlib import Path
from typing import Any

import pytest
import pytest_asyncio
from web_station import (
    FakeWeb,
    Protocol,
    Station,
    browser_missing,
    until,
    viewport,
    wait_in_page,
)

MISSING = browser_missing()
pytestmark = [
    pytest.mark.realtime,
    pytest.mark.shared("chromium"),
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
    pytest.mark.skipif(MISSING is not None, reason=f"no browser to test with: {MISSING}"),
]

NOW = "return performance.timeOrigin + performance.now();"


async def run(call: Callable[..., Any], *args: Any) -> Any:
    return await asyncio.to_thread(call, *args)


async def js(driver: Any, script: str, *args: Any) -> Any:
    return await asyncio.to_thread(driver.execute_script, script, *args)


async def page_until(driver: Any, script: str, timeout: float = 10.0, what: str = "") -> Any:
    return await wait_in_page(driver, script, timeout, what)


def button(radio: int, antenna: int) -> str:
    return (f"document.querySelector('.radio[data-radio=\"{radio}\"] "
            f".grid button[data-type=\"Antenna\"][data-id=\"{antenna}\"]')")


async def tap(driver: Any, css: str, dx: int = 0, dy: int = 0) -> None:
    """A real pointer tap (pointerdown and pointerup) where a finger would put it.  The
    pointer gets there at once, as a finger does (Selenium's default glides there over
    250 ms, a quarter of a second of waiting a tap)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    def do() -> None:
        element = driver.find_element(By.CSS_SELECTOR, css)
        ActionChains(driver, duration=0).move_to_element_with_offset(element, dx, dy).click().perform()

    await run(do)


async def hold(driver: Any, css: str, seconds: float = 0.9) -> None:
    """A long press: the pointer goes down, stays, and comes up."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    def do() -> None:
        element = driver.find_element(By.CSS_SELECTOR, css)
        ActionChains(driver, duration=0).click_and_hold(element).pause(seconds).release().perform()

    await run(do)


class SharedStation(Station):
    """The station of :func:`started`: its server serves an Antenna Genius port too."""

    def __init__(self, tmp: Path) -> None:
        from web_station import free_port

        super().__init__(tmp)
        self.ag_port = free_port()

    async def start_server(self, *extra: str) -> None:
        await super().start_server("--ag-port", str(self.ag_port), *extra)


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def started(tmp_path_factory: pytest.TempPathFactory) -> AsyncIterator[SharedStation]:
    """One station (the emulated switch and the server process) for the tests of this
    module that take :func:`station`: each only sets frequencies, taps and holds (and
    releases what it held), and each sets what it looks at first; the one that stops the
    server comes last of them."""
    made = SharedStation(tmp_path_factory.mktemp("station"))
    try:
        await made.start_server()
        yield made
    finally:
        await made.close()


@pytest_asyncio.fixture(loop_scope="module")
async def station(started: SharedStation) -> AsyncIterator[SharedStation]:
    """The module's station, its server running and no page of a test before connected."""
    if started.process is None:
        await started.start_server()
    await until(lambda: started.pages() == 0, 10, "the pages of the test before gone")
    since = len(started.log)
    yield started
    print("the server's log:\n" + "".join(started.log[since:]))  # shown when a test fails


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_tapping_the_display_line_shows_why_the_radio_has_its_antennas(
        station: Station, browser: Any) -> None:
    tcp = await Protocol.connect(station.tcp)
    try:
        await tcp.call("frequency", station=1, radio=1, khz=7025.0)
        await run(browser.get, station.url + "?station=1&radio=1")
        display = '.radio[data-radio="1"] .display'
        why = "document.querySelector('.radio[data-radio=\"1\"] .why')"
        # the page is built from the server's first state: until then there is no display
        await page_until(browser, "const d = document.querySelector('.radio[data-radio=\"1\"] "
                         ".display'); return d !== null && d.textContent.includes('7025.0 kHz')",
                         what="radio 1")
        assert await js(browser, f"return {why}.hidden") is True
        await tap(browser, display)
        await page_until(browser, f"return !{why}.hidden", what="the reason after a tap")
        text = await js(browser, f"return {why}.textContent")
        assert text.startswith("Lowest-numbered antenna covering 7025 kHz")
        # antennas that merely do not cover the frequency decide nothing: left out
        assert "does not cover" not in text
        await tap(browser, display)
        await page_until(browser, f"return {why}.hidden", what="the reason hidden again")
    finally:
        await tcp.close()


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_taps_select_antennas_a_second_page_follows_and_frequencies_move_the_selection(
        station: Station, browser: Any) -> None:
    tcp = await Protocol.connect(station.tcp)
    try:
        await tcp.call("frequency", station=1, radio=1, khz=14025.0)
        await tcp.call("frequency", station=1, radio=2, khz=7025.0)
        tribander, vertical = 0, 3
        await until(lambda: station.relays_of(tribander, 14025.0) <= station.relays(), 15,
                    "the switch has the tribander for radio 1")

        await run(browser.get, station.url + "?station=1&radio=1&radio2=2")
        await page_until(browser, "return document.body.dataset.link === 'connected' && "
                         f"{button(1, vertical)} !== null", what="the buttons of radio 1")
        assert await js(browser, f"return {button(1, tribander)}.dataset.state") == "selected"
        assert "14025.0 kHz" in await js(
            browser, "return document.querySelector('.radio[data-radio=\"1\"] .display').textContent")

        # A tap on the vertical: the emulated switch's relays follow.
        before = station.relays()
        await tap(browser, f'.radio[data-radio="1"] .grid button[data-id="{vertical}"]')
        await until(lambda: station.relays_of(vertical, 14025.0) <= station.relays(), 5,
                    "a tap changes the relays")
        assert station.relays() != before
        await page_until(browser, f"return {button(1, vertical)}.dataset.state === 'selected'")

        # A second page sees a tap on the first (how soon: benchmarks/bench_web.py).
        first = browser.current_window_handle
        await run(browser.switch_to.new_window, "window")
        second = browser.current_window_handle
        await run(browser.get, station.url + "?station=1&radio=1")
        await page_until(browser, f"return {button(1, tribander)} !== null")
        assert await js(browser, f"return {button(1, tribander)}.dataset.state") == "available"
        await run(browser.switch_to.window, first)
        await tap(browser, f'.radio[data-radio="1"] .grid button[data-id="{tribander}"]')
        await run(browser.switch_to.window, second)
        await page_until(browser, f"return {button(1, tribander)}.dataset.state === 'selected'",
                         what="the tap of page 1 on page 2")
        await until(lambda: station.relays_of(tribander, 14025.0) <= station.relays(), 5)
        await run(browser.close)
        await run(browser.switch_to.window, first)

        # A frequency change (a logger's report) moves the selection on the page.
        await tcp.call("frequency", station=1, radio=1, khz=3520.0)
        await page_until(browser, "return document.querySelector("
                         "'.radio[data-radio=\"1\"] .display').textContent.includes('3520.0 kHz')")
        dipole = 2
        await page_until(browser, f"return {button(1, dipole)} !== null && "
                         f"{button(1, dipole)}.dataset.state === 'selected' && "
                         f"{button(1, tribander)} === null", what="the 80 m dipole selected")
        await until(lambda: station.relays_of(dipole, 3520.0) <= station.relays(), 5)
        text = await js(browser, "return document.querySelector('.radio[data-radio=\"1\"] "
                        ".display').textContent")
        assert "TX 80 m dipole" in text and "RX 80 m dipole" in text

        # A long press selects alone: one request, however long the finger stays.
        await js(browser, "window.sent = []; const send = WebSocket.prototype.send; "
                 "WebSocket.prototype.send = function (m) { window.sent.push(JSON.parse(m)); "
                 "return send.call(this, m); };")
        await hold(browser, f'.radio[data-radio="1"] .grid button[data-id="{vertical}"]')
        await page_until(browser, f"return {button(1, vertical)}.dataset.state === 'selected'")
        sent = await js(browser, "return window.sent.filter(m => m.cmd === 'select')")
        assert [(m["antenna"], m["exclusive"]) for m in sent] == [(vertical, True)]
    finally:
        await tcp.close()


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_the_page_fits_a_phone_and_a_tablet_both_ways(
        station: Station, browser: Any) -> None:
    tcp = await Protocol.connect(station.tcp)
    await tcp.call("frequency", station=1, radio=1, khz=14025.0)
    await tcp.call("frequency", station=1, radio=2, khz=7025.0)
    await tcp.close()
    for width, height, side_by_side in ((1024, 600, True), (600, 1024, False),
                                        (360, 740, False)):
        await run(viewport, browser, width, height)
        await run(browser.get, station.url + "?station=1&radio=1&radio2=2")
        await page_until(browser, f"return {button(1, 0)} !== null")
        overflow = await js(browser, "return document.documentElement.scrollWidth - innerWidth")
        assert overflow <= 0, f"{width}x{height}: the page is {overflow} px too wide"
        boxes = await js(browser, "return [...document.querySelectorAll('.radio')]"
                         ".filter(r => r.offsetParent !== null).map(r => r.getBoundingClientRect().left)")
        assert (len(boxes) == 2) == side_by_side, f"{width}x{height}: {boxes}"
        if not side_by_side:  # one radio at a time, chosen by a tab
            await tap(browser, "#tabs button:last-child")
            await page_until(browser, "return document.querySelector('.radio[data-radio=\"2\"]')"
                             ".offsetParent !== null", what="radio 2 after its tab")
        small = await js(browser, "return Math.min(...[...document.querySelectorAll("
                         "'.grid button')].filter(b => b.offsetParent).map(b => b.offsetHeight))")
        assert small >= 44, f"{width}x{height}: a button is {small} px high, too small to tap"
    # a page left for another (and kept for the Back button) does not stay connected
    assert station.pages() == 1
    await run(browser.get, "about:blank")
    await until(lambda: station.pages() == 0, 5, "the page left disconnecting")


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_an_antenna_genius_hold_is_shown_on_the_page_with_who_holds_it(
        station: SharedStation, browser: Any) -> None:
    from ag_client import AgClient

    ag_port = station.ag_port
    ag: AgClient | None = None
    try:
        await run(browser.get, station.url + "?station=1&radio=1")
        note = "document.querySelector('.radio[data-radio=\"1\"] .note')"
        await page_until(browser, f"return {note} !== null", what="radio 1")
        ag = await AgClient.connect(ag_port)
        assert (await ag.ask("port set 1 band=6")).code == 0  # 14175 kHz, no note
        await page_until(browser, f"return {note}.hidden", what="radio 1 on 20 m")
        release = "document.querySelector('.radio[data-radio=\"1\"] .release')"
        assert await js(browser, f"return {release}.hidden")
        assert (await ag.ask("port set 1 auto=0")).code == 0
        await page_until(browser, f"return !{note}.hidden", what="the hold")
        text = await js(browser, f"return {note}.textContent")
        assert re.fullmatch(r"Held by an Antenna Genius client at 127\.0\.0\.1 since "
                            r"\d\d:\d\d: the antennas do not follow the frequency", text), text
        assert (await ag.ask("port set 1 auto=1")).code == 0
        await page_until(browser, f"return {note}.hidden", what="the hold released")
        # the program holds again and goes away: the page releases the radio it pinned
        assert (await ag.ask("port set 1 auto=0")).code == 0
        await ag.close()
        ag = None
        await page_until(browser, f"return !{release}.hidden", what="Release offered")
        await tap(browser, '.radio[data-radio="1"] .release')
        await page_until(browser, f"return {note}.hidden && {release}.hidden",
                         what="the hold released from the page")
        ag = await AgClient.connect(ag_port)
        port = (await ag.ask("port get 1", listing=True)).message
        assert " auto=1 " in port, port
    finally:
        if ag is not None:
            await ag.close()


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_the_compass_turns_a_test_rotator_and_a_stopped_server_shows_not_connected(
        station: Station, browser: Any) -> None:
    tcp = await Protocol.connect(station.tcp)
    await tcp.call("frequency", station=1, radio=1, khz=14025.0)
    state = await tcp.call("state")
    await tcp.close()
    rotator = next(r for r in state["rotators"] if r["id"] == 1)
    start = float(rotator["heading"] or 0.0)

    await run(browser.get, station.url + "?station=1&radio=1")
    svg = '.radio[data-radio="1"] svg.compass'
    await page_until(browser, f"return document.querySelector('{svg}') !== null && "
                     f"!document.querySelector('{svg}').closest('.compass-box').hidden",
                     what="the compass")
    # a dead zone or stop is drawn for a rotator with limits
    assert await js(browser, f"return document.querySelectorAll('{svg} .stopline').length") == 1
    # tap 60 degrees clockwise of where it points, two thirds out from the centre
    import math
    wanted = (start + 60) % 360
    size = await js(browser, f"return document.querySelector('{svg}').getBoundingClientRect().width")
    radius = size / 2 * 100 / 120 * 0.66
    dx = round(radius * math.sin(math.radians(wanted)))
    dy = round(-radius * math.cos(math.radians(wanted)))
    await tap(browser, svg, dx, dy)
    heading_text = "return document.querySelector('.radio[data-radio=\"1\"] .heading').textContent"
    shown = await page_until(browser, f"{heading_text.replace('return ', 'const t = ')}; "
                             "return t.includes('\u2192') ? t : null", what="the turn")
    target = float(shown.split("\u2192")[1].strip().rstrip("\u00b0"))
    assert abs((target - wanted + 180) % 360 - 180) <= 3, shown
    first = shown.split("\u2192")[0].strip().rstrip("\u00b0")
    await page_until(browser, f"{heading_text.replace('return ', 'const t = ')}; "
                     f"return !t.startsWith('{first}')", what="the heading moving")
    await tap(browser, '.radio[data-radio="1"] .stop')
    await page_until(browser, f"{heading_text.replace('return ', 'const t = ')}; "
                     "return !t.includes('\u2192')", what="the rotator stopped")

    # The server stops: the page says so; it comes back: the page recovers by itself.
    await station.stop_server()
    link = "return document.getElementById('link').textContent"
    await page_until(browser, f"{link.replace('return ', 'const t = ')}; "
                     "return t.toLowerCase().includes('not connected')", what="not connected")
    assert await js(browser, "return document.body.classList.contains('offline')")
    # nothing is shown as true any more: no antenna selected, no heading; a tap is answered
    await page_until(browser, "return document.querySelectorAll('.radio[data-radio=\"1\"] "
                     ".grid button[data-state=\"selected\"]').length === 0",
                     what="no antenna shown selected")
    assert await js(browser, heading_text) == "not connected"
    await tap(browser, '.radio[data-radio="1"] .grid button[data-id="3"]')
    message = "return document.querySelector('.radio[data-radio=\"1\"] .message').textContent"
    assert "not connected" in await page_until(browser, message, what="the tap answered")
    await tap(browser, svg, 10, 10)
    assert (await js(browser, message)).startswith("\u26a0 Turn: not connected")
    await station.start_server()
    await page_until(browser, f"{link.replace('return ', 'const t = ')}; "
                     "return t.includes('Connected') && !t.includes('Not')", 15, "reconnected")
    # the page draws the new server's state: the display line and the buttons again
    await page_until(browser, "return !document.body.classList.contains('offline') && "
                     "document.querySelectorAll('.radio[data-radio=\"1\"] .grid button').length"
                     " > 0 && document.querySelector('.radio[data-radio=\"1\"] .freq')"
                     ".textContent !== 'no radio'", what="the new server's state")


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_stopped_switches_show_no_antenna_selected_and_a_tap_is_answered(
        browser: Any) -> None:
    page = await FakeWeb.start()
    backend = page.backend
    selected = ("return document.querySelectorAll('.radio[data-radio=\"1\"] "
                ".grid button[data-state=\"selected\"]').length")
    message = "return document.querySelector('.radio[data-radio=\"1\"] .message').textContent"
    try:
        await run(browser.get, page.url())
        await page_until(browser, selected, what="an antenna selected")
        backend.stop_switches()
        await page_until(browser, "return document.getElementById('link').textContent"
                         ".includes('Switches stopped')", what="the stop in the top bar")
        await page_until(browser, f"{selected.replace('return ', 'return 0 === ')}",
                         what="no antenna shown selected")
        assert await js(browser, "return document.body.dataset.screen") == "switches stopped"
        # no button is hatched or titled as if its state held now: each says why
        states = await js(browser, "return [...document.querySelectorAll('.radio[data-radio="
                          "\"1\"] .grid button')].map(b => b.dataset.state + '|' + b.title)")
        assert states and all(s.startswith("available|") and s.endswith(
            "the switches are stopped; start them on the server (File > Start Switches)")
            for s in states), states
        freq = "return document.querySelector('.radio[data-radio=\"1\"] .freq').textContent"
        assert await js(browser, freq) == "Switches stopped: no antenna is connected"
        assert "\u25b8" not in await js(browser, "return document.querySelector("
                                        "'.radio[data-radio=\"1\"] .rel-list').textContent")
        selects = len([c for c in backend.calls if c[0] == "select"])
        await tap(browser, '.radio[data-radio="1"] .grid button[data-type="Antenna"]')
        assert "the switches are stopped" in await page_until(browser, message,
                                                              what="the tap answered")
        assert len([c for c in backend.calls if c[0] == "select"]) == selects
        backend.start_switches()
        await page_until(browser, selected, what="the selection shown again after Start")
        assert await js(browser, "return document.body.dataset.screen") == "connected"
    finally:
        await page.close(browser)


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_a_station_with_one_radio_shows_no_second_radio_selector(
        tmp_path: Path, browser: Any) -> None:
    """Issue 30: the "and –" selector for a second radio is left out where the station
    has no second radio, and shown where it has one."""
    made = Station(tmp_path, "two-op-shared-tx.moas")  # station 1: two radios; 2: one
    try:
        await made.start_server()
        shown = ("return !document.getElementById('radioB').closest('label').hidden")
        await run(browser.get, made.url + "?station=2&radio=1")
        await page_until(browser, f"return {button(1, 0)} !== null")
        assert await js(browser, shown) is False
        await run(browser.get, made.url + "?station=1&radio=1")
        await page_until(browser, shown, what="the second radio's selector on station 1")
    finally:
        await run(browser.get, "about:blank")
        await made.close()


@pytest.mark.asyncio(loop_scope="module")
@pytest.mark.timeout(120)
async def test_release_is_offered_on_the_page_only_to_an_operator_whose_role_covers_the_radio(
        tmp_path: Path, browser: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 40: a paired page acts as its operator; a view operator's page shows the hold
    but no Release, an operate operator's page for that radio offers it."""
    from ag_client import AgClient
    from web_station import free_port

    from moas_gui.operators import OperatorBook, Role

    made = Station(tmp_path)
    monkeypatch.setenv("XDG_CONFIG_HOME", made.env["XDG_CONFIG_HOME"])
    book = OperatorBook()
    tokens = {"Vic": book.add("Vic", Role.VIEW)[1],
              "Ann": book.add("Ann", Role.OPERATE, frozenset({(1, 1)}))[1]}
    ag_port = free_port()
    ag: AgClient | None = None
    note = "document.querySelector('.radio[data-radio=\"1\"] .note')"
    release = "document.querySelector('.radio[data-radio=\"1\"] .release')"
    try:
        await made.start_server("--ag-port", str(ag_port))
        ag = await AgClient.connect(ag_port)
        assert (await ag.ask("port set 1 band=6 auto=0")).code == 0
        for name, offered in (("Vic", False), ("Ann", True)):
            await run(browser.get, "about:blank")  # a new page each time, not a new fragment
            await run(browser.get, made.url + f"?station=1&radio=1#token={tokens[name]}")
            await page_until(browser, f"return {note} !== null && !{note}.hidden",
                             what=f"the hold on {name}'s page")
            await asyncio.sleep(0.3)  # the hello's result has come with the state
            assert await js(browser, f"return {release}.hidden") is (not offered), name
        await tap(browser, '.radio[data-radio="1"] .release')
        await page_until(browser, f"return {note}.hidden", what="released by Ann")
        assert " auto=1 " in (await ag.ask("port get 1", listing=True)).message
        assert any("Ann at 127.0.0.1:" in line and "releasing the hold of radio 1/1" in line
                   for line in made.log)
    finally:
        if ag is not None:
            await ag.close()
        await made.close()
