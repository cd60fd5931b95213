"""Screenshots of the client window for docs/client.md, offscreen.

Runs the server (big-station example, built-in emulated switches) and the
built-in client in one process, tunes station 1 radio 1 to 20 m, and saves:

- ``client-window.png`` at the window's usual size;
- ``client-window-laptop.png`` at 1240x720, what fits a 1280x800 laptop screen;
- ``client-window-stopped.png`` after File > Stop Switches: no antenna shown
  selected, the buttons greyed;
- ``client-window-disconnected.png`` after the server has gone: everything
  greyed, the compass too, and a press answered "not connected";
- ``client-window-why.png`` at 1024x600: a click on an unavailable button (another
  station uses the antenna) answered with its reason in the status line.

Usage: QT_QPA_PLATFORM=offscreen .venv/bin/python scripts/screenshot_client.py [FOLDER]
(or on an X display: ``xvfb-run -s "-screen 0 1280x800x24" .venv/bin/python ...``)
"""

from __future__ import annotations

import asyncio
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import qasync

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.ui.client_window import open_builtin_client
from moas_gui.ui.qt import QSettings
from moas_gui.ui.server_window import ServerWindow, ensure_application

ROOT = Path(__file__).resolve().parent.parent


async def settle(seconds: float = 0.6) -> None:
    await asyncio.sleep(seconds)


async def until(condition: Callable[[], object], seconds: float = 10.0) -> None:
    for _ in range(int(seconds / 0.05)):
        if condition():
            return
        await asyncio.sleep(0.05)
    raise RuntimeError("screenshot_client: the window never showed what was waited for")


async def shoot(out: Path) -> None:
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False))
    with tempfile.TemporaryDirectory() as scratch:
        window = ServerWindow(server, QSettings(str(Path(scratch) / "s.ini"),
                                                QSettings.Format.IniFormat), lambda: None)
        window.open_file(str(ROOT / "examples" / "big-station.moas"))
        await window.idle()
        server.apply_changes(server.engine.set_frequency(1, 1, 14025.0))
        client = open_builtin_client(server)
        for _ in range(200):
            if client.grid.buttons:
                break
            await asyncio.sleep(0.05)
        client.resize(1060, 700)
        await settle()
        client.grab().save(str(out / "client-window.png"))
        client.resize(1240, 720)
        await settle()
        client.grab().save(str(out / "client-window-laptop.png"))
        # another station takes an antenna of this radio's layout: a click on it answers why
        server.apply_changes(server.engine.set_frequency(2, 1, 14030.0))
        await until(lambda: any(b.view.state.value == "unavailable" and b.view.reason
                                and b.view.type.value == "Antenna" for b in client.grid.buttons))
        client.resize(1024, 600)
        taken = next(b for b in client.grid.buttons
                     if b.view.state.value == "unavailable" and b.view.type.value == "Antenna")
        taken.click()
        await settle()
        client.grab().save(str(out / "client-window-why.png"))
        client.resize(1060, 700)
        server.stop_switches()
        await until(lambda: client.switches_stopped)
        client._pressed(client.grid.buttons[0].view, False)  # what a press answers
        await settle()
        client.grab().save(str(out / "client-window-stopped.png"))
        server.start_switches()
        await until(lambda: not client.grid.greyed)
        window.shutdown()
        await server.close()  # the server goes: the window keeps trying
        await until(lambda: client.grid.greyed)
        client._pressed(client.grid.buttons[0].view, False)
        await settle()
        client.grab().save(str(out / "client-window-disconnected.png"))
        print(f"screenshot_client: wrote client-window.png, client-window-laptop.png, "
              f"client-window-why.png, client-window-stopped.png and "
              f"client-window-disconnected.png in {out}")
        await client.aclose()
        client.close()


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
