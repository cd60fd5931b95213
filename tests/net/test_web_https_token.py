"""The browser page over HTTPS with the server's self-signed certificate, where a token is
needed: Debian's Chromium (accepting that certificate) asks for the token once, keeps it,
and takes one from a pairing link's fragment.  The page connects from 127.0.0.1, so the
test makes that address count as the LAN (``ClientServer.local_addresses``).  The
worker's one Chromium (tests/conftest.py) is told to accept any certificate for the test's
length, instead of a second Chromium started for it."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

import pytest
from web_station import browser_missing, wait_in_page

from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer
from moas_gui.operators import OperatorBook, Role
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.tls import Certificate, make_self_signed, server_context

MISSING = browser_missing()
pytestmark = [
    pytest.mark.realtime,
    pytest.mark.shared("chromium"),
    pytest.mark.skipif(sys.platform == "win32", reason="Debian's Chromium"),
    pytest.mark.skipif(MISSING is not None, reason=f"no browser to test with: {MISSING}"),
]

def trust_any_certificate(driver: Any, trust: bool) -> None:
    """The worker's Chromium accepting a self-signed certificate or not (what a user does
    by clicking through the warning once, or by trusting the fingerprint)."""
    driver.execute_cdp_cmd("Security.setIgnoreCertificateErrors", {"ignore": trust})


async def js(driver: Any, script: str) -> Any:
    return await asyncio.to_thread(driver.execute_script, script)


async def page_until(driver: Any, script: str, what: str, timeout: float = 15.0) -> Any:
    return await wait_in_page(driver, script, timeout, what)


async def type_token(driver: Any, token: str) -> None:
    from selenium.webdriver.common.by import By

    def do() -> None:
        field = driver.find_element(By.ID, "token")
        field.clear()
        field.send_keys(token)
        driver.find_element(By.ID, "token-go").click()
    await asyncio.to_thread(do)


CONNECTED = "return document.querySelector('#link').classList.contains('up')"
ASKING = "return !document.querySelector('#signin').hidden"


@pytest.mark.asyncio
async def test_the_page_over_https_asks_for_a_token_once_and_keeps_it(tmp_path: Path,
                                                                    browser: Any) -> None:
    where = Certificate(tmp_path / "cert.pem", tmp_path / "key.pem")
    make_self_signed(where, "localhost")
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("tablet", Role.OPERATE)
    _op2, paired = book.add("phone", Role.VIEW)
    backend = FakeBackend()
    clients = ClientServer(backend, host="127.0.0.1", port=0, require_token=True,
                           operators=book, tls=server_context(where))
    clients.local_addresses = ()  # the browser's 127.0.0.1 plays a computer on the LAN
    backend.attach(clients)
    await clients.start()
    web = WebServer(clients, host="127.0.0.1", port=0)
    await web.start()
    url = f"https://127.0.0.1:{web.port}/"
    driver = browser  # the worker's Chromium (tests/conftest.py), trusting the certificate
    await asyncio.to_thread(trust_any_certificate, driver, True)
    try:
        await asyncio.to_thread(driver.get, url)
        await page_until(driver, ASKING, "the token prompt")
        asked = await js(driver, "return document.querySelector('#signin .why').textContent")
        assert asked.startswith("This station asks for an operator's token: ask its admin, "
                                "or scan its pairing code")
        assert "hello" not in asked and "forbidden" not in asked
        await asyncio.to_thread(driver.save_screenshot, str(tmp_path / "web-token.png"))
        assert (tmp_path / "web-token.png").stat().st_size > 0
        await type_token(driver, token[:-3] + "xyz")  # a wrong one: asked again
        await page_until(driver, ASKING + " && document.querySelector('#signin .why')"
                         ".textContent.includes('did not take that token')", "the refusal")
        await type_token(driver, f"https://192.168.1.5:8443/#token={token}")  # a pasted link
        await page_until(driver, CONNECTED, "a connection")
        assert await js(driver, "return localStorage.getItem('moas-token')") == token
        names = {c.name for c in clients.clients()}
        assert any(n and n.startswith("browser") for n in names)
        await asyncio.to_thread(driver.refresh)  # kept: not asked again
        await page_until(driver, CONNECTED, "a connection after a reload")
        assert await js(driver, ASKING) is False
        await js(driver, "localStorage.clear()")
        await asyncio.to_thread(driver.get, url + "#token=" + paired)  # a pairing QR code
        await page_until(driver, CONNECTED, "a paired connection")
        assert await js(driver, "return location.hash") == ""
        assert await js(driver, "return localStorage.getItem('moas-token')") == paired
        assert any(c.identity.operator is not None and c.identity.operator.name == "phone"
                   for c in clients._connections)
    finally:
        await asyncio.to_thread(trust_any_certificate, driver, False)
        # the page leaves first, as a person closes the tab before the server stops
        await asyncio.to_thread(driver.get, "about:blank")
        await web.close()
        await clients.close()
