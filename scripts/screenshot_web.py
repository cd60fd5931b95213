"""Screenshots of the web page for docs/web-client.md: the switches stopped, and the
server gone.

Serves the page from the project's client server over its fake backend (the demo
station) on 127.0.0.1, opens it in Debian's Chromium (headless, 1024x600, as a
7-inch tablet in landscape), and saves:

- ``web-stopped.png``: the switches stopped, no antenna shown selected, a tap
  answered with the reason;
- ``web-disconnected.png``: the server gone, the page greyed and trying again,
  a tap answered "not connected";
- ``web-why.png``: a tap on an unavailable button answered with its reason;
- ``web-phone-answer.png``: the same at a phone's size (390x844), the answer in view.

Usage: .venv/bin/python scripts/screenshot_web.py [FOLDER]   (default docs/images)
"""

from __future__ import annotations

import asyncio
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests.web_station import FakeWeb, browser_missing, chrome


async def until(driver: Any, script: str) -> None:
    for _ in range(200):
        if await asyncio.to_thread(driver.execute_script, script):
            return
        await asyncio.sleep(0.05)
    raise RuntimeError(f"screenshot_web: the page never showed {script}")


async def tap_a_button(driver: Any, css: str = '.grid button[data-type="Antenna"]') -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    def do() -> None:
        button = driver.find_element(By.CSS_SELECTOR, css)
        ActionChains(driver).move_to_element(button).click().perform()
    await asyncio.to_thread(do)


UNAVAILABLE = '.grid button[data-state="unavailable"]'
SELECTED = "return document.querySelector('.grid button[data-state=\"selected\"]')"


async def why_shots(driver: Any, out: Path) -> None:
    """A tap on an unavailable button, answered: at 1024x600, then at a phone's size."""
    from tests.web_station import viewport

    await tap_a_button(driver, UNAVAILABLE)
    await until(driver, "return document.querySelector('.message').textContent !== ''")
    await asyncio.to_thread(driver.save_screenshot, str(out / "web-why.png"))
    await asyncio.to_thread(viewport, driver, 390, 844)
    await asyncio.to_thread(driver.refresh)
    await until(driver, f"return document.querySelector('{UNAVAILABLE}')")
    await tap_a_button(driver, UNAVAILABLE)
    await until(driver, "return document.querySelector('.message').textContent !== ''")
    await asyncio.sleep(0.3)
    await asyncio.to_thread(driver.save_screenshot, str(out / "web-phone-answer.png"))
    await asyncio.to_thread(viewport, driver, 1024, 600)


async def shoot(out: Path) -> None:
    page = await FakeWeb.start()
    backend = page.backend
    with tempfile.TemporaryDirectory() as profile:
        driver = await asyncio.to_thread(chrome, Path(profile), 1024, 600)
        try:
            await asyncio.to_thread(driver.get, page.url())
            await until(driver, SELECTED)
            await why_shots(driver, out)
            await asyncio.to_thread(driver.refresh)
            await until(driver, SELECTED)
            backend.stop_switches()
            await until(driver, "return document.body.dataset.screen === 'switches stopped'")
            await tap_a_button(driver)
            await asyncio.sleep(0.3)
            await asyncio.to_thread(driver.save_screenshot, str(out / "web-stopped.png"))
            backend.start_switches()
            await until(driver, "return document.body.dataset.screen === 'connected'")
            await page.stop_serving()
            await until(driver, "return document.body.dataset.link === 'not-connected'")
            await asyncio.sleep(0.3)
            await tap_a_button(driver)
            await asyncio.sleep(0.3)
            await asyncio.to_thread(driver.save_screenshot, str(out / "web-disconnected.png"))
            await page.serve()
        finally:
            await page.close(driver)
            await asyncio.to_thread(driver.quit)
    print(f"screenshot_web: wrote web-why.png, web-phone-answer.png, web-stopped.png and "
          f"web-disconnected.png in {out}")


def main() -> int:
    missing = browser_missing()
    if missing:
        print(f"screenshot_web: {missing}", file=sys.stderr)
        return 1
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "docs" / "images")
    out.mkdir(parents=True, exist_ok=True)
    asyncio.run(shoot(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
