"""Screenshots for docs/security.md: what a phone user sees and taps after scanning a
station's pairing code, in Debian's Chromium at a phone's size (390x844).

Serves the page over TLS from the project's client and web servers (over the fake
backend, the demo station) on 127.0.0.1, with a self-signed certificate made as
``moas-server --tls`` makes it (naming the address listened on) and an operator added
as View > Pair a device adds one; where a token is needed (127.0.0.1 plays a phone on
the LAN).  Then opens the pairing link in a Chromium that does not know the
certificate, and saves:

- ``phone-pair-warning.png``: the browser's warning about the unknown certificate;
- ``phone-pair-advanced.png``: after tapping *Advanced*, the link to go on;
- ``phone-pair-signed-in.png``: after tapping it, the page signed in by the link's
  token (the token gone from the address);
- ``phone-token-asked.png``: the page opened without the link: it asks for a token.

Usage: .venv/bin/python scripts/screenshot_pairing.py [FOLDER]   (default docs/images)
"""

from __future__ import annotations

import asyncio
import contextlib
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from tests.web_station import browser_missing, chrome


async def until(driver: Any, script: str, what: str) -> None:
    for _ in range(300):
        with contextlib.suppress(Exception):  # the page may change under the script
            if await asyncio.to_thread(driver.execute_script, script):
                return
        await asyncio.sleep(0.05)
    raise RuntimeError(f"screenshot_pairing: the page never showed {what}")


async def tap(driver: Any, element_id: str) -> None:
    from selenium.webdriver.common.by import By

    await asyncio.to_thread(lambda: driver.find_element(By.ID, element_id).click())


async def shoot(out: Path, work: Path) -> None:
    from moas_gui.net.server import ClientServer
    from moas_gui.net.web import WebServer
    from moas_gui.operators import OperatorBook, Role
    from moas_gui.testing.fake_backend import FakeBackend
    from moas_gui.tls import Certificate, make_self_signed, server_context

    where = Certificate(work / "cert.pem", work / "key.pem")
    make_self_signed(where, "shack-pc", ["127.0.0.1"])
    book = OperatorBook(work / "operators.json")
    _operator, token = book.add("phone-40m", Role.OPERATE)
    backend = FakeBackend()
    clients = ClientServer(backend, host="127.0.0.1", port=0, require_token=True,
                           operators=book, tls=server_context(where))
    clients.local_addresses = ()
    backend.attach(clients)
    await clients.start()
    web = WebServer(clients, host="127.0.0.1", port=0)
    await web.start()
    driver = await asyncio.to_thread(chrome, work / "profile", 390, 844)
    base = f"https://127.0.0.1:{web.port}/"
    try:
        await asyncio.to_thread(driver.get, base + "?station=1&radio=1#token=" + token)
        await until(driver, "return document.querySelector('#details-button')",
                    "the certificate warning")
        await asyncio.to_thread(driver.save_screenshot, str(out / "phone-pair-warning.png"))
        await tap(driver, "details-button")
        await until(driver, "const p = document.querySelector('#proceed-link'); "
                            "return p && p.offsetParent !== null", "the link to go on")
        await asyncio.to_thread(driver.execute_script, "window.scrollTo(0, 10000)")
        await asyncio.to_thread(driver.save_screenshot, str(out / "phone-pair-advanced.png"))
        await tap(driver, "proceed-link")
        await until(driver, "return document.querySelector('#link') && "
                            "document.querySelector('#link').classList.contains('up')",
                    "the signed-in page")
        await until(driver, "return location.hash === ''", "the token gone from the address")
        await asyncio.sleep(0.3)
        await asyncio.to_thread(driver.save_screenshot, str(out / "phone-pair-signed-in.png"))
        await asyncio.to_thread(driver.execute_script, "localStorage.clear()")
        await asyncio.to_thread(driver.get, base + "?station=1&radio=1")
        await until(driver, "return !document.querySelector('#signin').hidden",
                    "the token prompt")
        await asyncio.to_thread(driver.save_screenshot, str(out / "phone-token-asked.png"))
    finally:
        await asyncio.to_thread(driver.quit)
        await web.close()
        await clients.close()


def main() -> int:
    missing = browser_missing()
    if missing is not None:
        print(f"screenshot_pairing: no browser: {missing}", file=sys.stderr)
        return 1
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images"
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="moas-pairing-") as work:
        asyncio.run(shoot(out, Path(work)))
    print(f"screenshot_pairing: wrote phone-pair-warning.png, phone-pair-advanced.png, "
          f"phone-pair-signed-in.png and phone-token-asked.png to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
