"""Screenshots of a hold where operators look (docs/antenna-genius.md, "Hold"), offscreen.

Runs the server (small-station example, its built-in emulated switch) in this process,
lets a program speaking the Antenna Genius API hold radio 1 and go away, and saves:

- ``server-window-hold.png``: the server window at 1024x600 with the hold's line and
  its Release;
- ``client-window-hold.png``: the built-in client at 1024x600 showing who holds the
  radio since when, with Release;
- ``web-phone-hold.png``: the web page at a phone's size (390x844) in Debian's
  Chromium (headless), the same hold and its Release.

Usage: QT_QPA_PLATFORM=offscreen .venv/bin/python scripts/screenshot_holds.py [FOLDER]
(default docs/images)
"""

from __future__ import annotations

import asyncio
import socket
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import qasync

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine.operations import SetFrequency
from moas_gui.ui.client_window import open_builtin_client
from moas_gui.ui.qt import QSettings
from moas_gui.ui.server_window import ServerWindow, ensure_application
from tests.ag_client import AgClient
from tests.web_station import browser_missing, chrome, viewport


async def until(condition: Callable[[], object], seconds: float = 15.0) -> None:
    for _ in range(int(seconds / 0.05)):
        if condition():
            return
        await asyncio.sleep(0.05)
    raise RuntimeError("screenshot_holds: what was waited for never showed")


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


async def web_shot(web_port: int, out: Path) -> None:
    missing = browser_missing()
    if missing is not None:
        print(f"screenshot_holds: no web screenshot: {missing}")
        return
    with tempfile.TemporaryDirectory() as profile:
        driver: Any = await asyncio.to_thread(chrome, Path(profile), 390, 844)
        try:
            await asyncio.to_thread(viewport, driver, 390, 844)
            await asyncio.to_thread(driver.get,
                                    f"http://127.0.0.1:{web_port}/?station=1&radio=1")
            script = ("return !document.querySelector('.radio[data-radio=\"1\"] .release')"
                      ".hidden")
            for _ in range(200):
                if await asyncio.to_thread(driver.execute_script, script):
                    break
                await asyncio.sleep(0.05)
            await asyncio.sleep(0.5)
            await asyncio.to_thread(driver.save_screenshot, str(out / "web-phone-hold.png"))
            await asyncio.to_thread(driver.get, "about:blank")
        finally:
            await asyncio.to_thread(driver.quit)


async def shoot(out: Path) -> None:
    web_port = free_port()
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     ag_port=0, web_port=web_port))
    with tempfile.TemporaryDirectory() as scratch:
        window = ServerWindow(server, QSettings(str(Path(scratch) / "s.ini"),
                                                QSettings.Format.IniFormat), lambda: None)
        window.resize(1024, 600)
        window.show()
        window.open_file(str(ROOT / "examples" / "small-station.moas"))
        await window.idle()
        server.act(SetFrequency(1, 1, 14025.0))
        server.act(SetFrequency(1, 2, 7025.0))
        program = await AgClient.connect(server.ag_ports[0], local="127.0.0.1")
        answer = await program.ask("port set 1 auto=0 txant=4 rxant=4")
        assert answer.code == 0, answer
        await program.close()  # the program goes away; the hold stays
        await until(lambda: not window.holds_bar.isHidden())
        await asyncio.sleep(0.5)
        window.grab().save(str(out / "server-window-hold.png"))
        client = open_builtin_client(server)
        client.resize(1024, 600)
        await until(lambda: client.grid.buttons and not client.release_button.isHidden())
        await asyncio.sleep(0.6)
        client.grab().save(str(out / "client-window-hold.png"))
        await web_shot(web_port, out)
        await client.aclose()
        client.close()
        window.shutdown()
        window.close()
        await server.close()
    print(f"screenshot_holds: wrote server-window-hold.png, client-window-hold.png and "
          f"web-phone-hold.png in {out}")


def main() -> int:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "docs" / "images")
    out.mkdir(parents=True, exist_ok=True)
    app = ensure_application()
    loop = qasync.QEventLoop(app)
    asyncio.set_event_loop(loop)
    with loop:
        loop.run_until_complete(shoot(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
