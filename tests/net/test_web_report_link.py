"""The operating page's Report link, in Debian's Chromium at a phone's size (390x844):
where the station needs a token, a browser paired by a pairing link opens the contest
report with the token it already has (sent in the Authorization header, never in an
address), is answered 200, and shows the numbers and the four charts with nothing cut;
the Back button returns to the antennas on the same connection."""

from __future__ import annotations

import asyncio
import logging
import os
import sys
from pathlib import Path
from typing import Any

import pytest
from antenna_log_support import contest_journal
from web_station import browser_missing, viewport, wait_in_page

from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer
from moas_gui.operators import OperatorBook, Role
from moas_gui.testing.fake_backend import FakeBackend

MISSING = browser_missing()
pytestmark = [
    pytest.mark.realtime,
    pytest.mark.shared("chromium"),
    pytest.mark.skipif(sys.platform == "win32", reason="Debian's Chromium"),
    pytest.mark.skipif(MISSING is not None, reason=f"no browser to test with: {MISSING}"),
]

SCREENSHOTS = os.environ.get("MOAS_SCREENSHOTS")
CONNECTED = "return document.querySelector('#link').classList.contains('up')"
CHARTS_SHOWN = ("return [...document.querySelectorAll('#report-body figure img')]"
                ".filter(i => i.complete && i.naturalWidth > 100).length === 4")
NOTHING_CUT = """
const view = document.querySelector('#report');
const wide = [...view.querySelectorAll('img, table, .numbers, h2, p')]
  .filter(e => e.getBoundingClientRect().right > window.innerWidth + 0.5);
const table = view.querySelector('.numbers');
return {viewCut: view.scrollWidth > view.clientWidth, wide: wide.map(e => e.tagName),
        tableCut: table.scrollWidth > table.clientWidth};
"""


async def js(driver: Any, script: str) -> Any:
    return await asyncio.to_thread(driver.execute_script, script)


async def page_until(driver: Any, script: str, what: str, timeout: float = 30.0) -> Any:
    return await wait_in_page(driver, script, timeout, what)


async def click(driver: Any, css: str) -> None:
    from selenium.webdriver.common.by import By

    await asyncio.to_thread(lambda: driver.find_element(By.CSS_SELECTOR, css).click())


@pytest.mark.asyncio
async def test_a_paired_phone_opens_the_report_with_its_token(
        browser: Any, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG)
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("phone", Role.VIEW)
    backend = FakeBackend()
    clients = ClientServer(backend, host="127.0.0.1", port=0, require_token=True,
                           operators=book)
    clients.local_addresses = ()  # the browser's 127.0.0.1 plays a phone on the LAN
    backend.attach(clients)
    await clients.start()
    journal = contest_journal()
    web = WebServer(clients, host="127.0.0.1", port=0, journal=lambda: journal)
    await web.start()
    try:
        await asyncio.to_thread(viewport, browser, 390, 844)
        await asyncio.to_thread(browser.get, f"http://127.0.0.1:{web.port}/#token={token}")
        await page_until(browser, CONNECTED, "a paired connection")
        assert await js(browser, "return location.hash") == ""
        link = await js(browser, "const r = document.querySelector('#report-link')"
                                 ".getBoundingClientRect(); return [r.right, r.bottom, "
                                 "r.width]")
        assert 0 < link[2] and link[0] <= 390  # the link is on the page, in view
        if SCREENSHOTS:
            await asyncio.to_thread(browser.save_screenshot,
                                    str(Path(SCREENSHOTS) / "web-phone-report-link.png"))
        await click(browser, "#report-link")
        await page_until(browser, CHARTS_SHOWN, "the report's four charts")
        rows = await js(browser, "return [...document.querySelectorAll('#report-body tr')]"
                                 ".map(r => [...r.cells].map(c => c.textContent))")
        assert rows[0] == ["Antenna", "QSOs", "40m", "20m", "Minutes transmitted"]
        assert ["Yagi 20", "7", "0", "7", "10.0"] in rows
        cut = await js(browser, NOTHING_CUT)
        assert cut == {"viewCut": False, "wide": [], "tableCut": False}, cut
        assert await js(browser, "return document.querySelector('#report-body').textContent"
                                 ".includes('15 QSOs')")
        asked = await js(browser, "return performance.getEntriesByType('resource')"
                                  ".map(e => e.name)")
        assert any(name.endswith("/report") for name in asked)
        assert not any(token in name for name in asked)  # never in an address
        shot = tmp_path / "report.png"
        await asyncio.to_thread(browser.save_screenshot, str(shot))
        if SCREENSHOTS:
            await asyncio.to_thread(browser.save_screenshot,
                                    str(Path(SCREENSHOTS) / "web-phone-report.png"))
            await js(browser, "document.querySelector('#report-rate').scrollIntoView(); "
                              "document.querySelector('#report').scrollBy(0, -60)")
            await asyncio.to_thread(browser.save_screenshot,
                                    str(Path(SCREENSHOTS) / "web-phone-report-rate.png"))
        await click(browser, "#report-back")
        assert await js(browser, "return document.querySelector('#report').hidden") is True
        assert await js(browser, CONNECTED)  # the same connection, still up
    finally:
        await web.close()
        await clients.close()
    said = " ".join(r.getMessage() for r in caplog.records if r.name.startswith("moas_gui"))
    assert "Refused the contest report" not in said  # no 401 on the way
    assert token.rsplit(".", 1)[1][:10] not in said


@pytest.mark.asyncio
async def test_a_refused_report_is_said_in_words(browser: Any, tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("phone", Role.VIEW)
    backend = FakeBackend()
    clients = ClientServer(backend, host="127.0.0.1", port=0, require_token=True,
                           operators=book)
    clients.local_addresses = ()
    backend.attach(clients)
    await clients.start()
    web = WebServer(clients, host="127.0.0.1", port=0, journal=contest_journal)
    await web.start()
    try:
        await asyncio.to_thread(browser.get, f"http://127.0.0.1:{web.port}/#token={token}")
        await page_until(browser, CONNECTED, "a paired connection")
        book.remove("phone")  # the admin removes it: the report is refused, in words
        await js(browser, "document.querySelector('#report-link').click()")
        await page_until(browser, "return document.querySelector('#report-body').textContent"
                                  ".includes('did not take that token')", "the refusal")
    finally:
        await web.close()
        await clients.close()
