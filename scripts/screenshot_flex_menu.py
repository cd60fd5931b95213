"""The client window's Sources menu showing a FlexRadio, offscreen, for docs/client.md.

Runs the client protocol server over the fake backend and the test FlexRadio
(:mod:`moas_gui.testing.flex_radio`, two slices) on 127.0.0.1, opens the client
window with its Sources menu, lets the radio announce itself (UDP, a free port),
reads it as the menu's *FlexRadios on the network* entry does, then draws the
window with the Sources menu and its FlexRadio submenu open into
``client-sources-flex.png``.

Usage: QT_QPA_PLATFORM=offscreen .venv/bin/python scripts/screenshot_flex_menu.py [FOLDER]
"""

from __future__ import annotations

import asyncio
import socket
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import qasync

from moas_gui.client.connection import ClientConnection
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.testing.fake_station import DEMO_STATION
from moas_gui.testing.flex_radio import FlexRadio
from moas_gui.ui.client_sources import ClientSources
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.qt import QPainter, QPixmap, QPoint, QSettings
from moas_gui.ui.server_window import ensure_application

ROOT = Path(__file__).resolve().parent.parent


async def until(condition: Callable[[], object], seconds: float = 10.0) -> None:
    for _ in range(int(seconds / 0.05)):
        if condition():
            return
        await asyncio.sleep(0.05)
    raise RuntimeError("screenshot_flex_menu: the window never showed what was waited for")


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


async def shoot(out: Path) -> None:
    backend = FakeBackend(DEMO_STATION)
    server = ClientServer(backend, host="127.0.0.1", port=0)
    backend.attach(server)
    port = await server.start()
    radio = FlexRadio(nickname="Contest", model="FLEX-6600M", serial="0621-1104-6601-2233")
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1, active=1, rxant="ANT1", txant="ANT1")
    radio.set_slice(1, RF_frequency=7.0125, mode="USB", rxant="RX_A", txant="ANT2")
    udp = free_udp_port()
    window = ClientWindow(ClientConnection("127.0.0.1", port, name="screenshot"))
    window.start()
    window.show()
    with tempfile.TemporaryDirectory() as scratch:
        settings = QSettings(str(Path(scratch) / "c.ini"), QSettings.Format.IniFormat)
        sources = ClientSources(window, settings, flex_port=udp)
        try:
            await until(lambda: window.grid.buttons and not window.grid.greyed)

            def heard() -> bool:
                radio.announce(("127.0.0.1", udp))
                return bool(sources.flex_discovery.radios())

            await until(heard)
            sources.show_flex()
            sources.flex_actions[0].trigger()
            def reading() -> bool:  # the Flex source the menu started reads both slices
                words = " ".join(line for s in sources.running
                                 for line in s.describe())  # type: ignore[attr-defined]
                return "connected" in words and "slice A" in words

            await until(reading)
            window.resize(1060, 640)
            await asyncio.sleep(0.5)
            picture = grab_with_menus(window, sources)
            picture.save(str(out / "client-sources-flex.png"))
            print(f"screenshot_flex_menu: wrote client-sources-flex.png in {out}")
        finally:
            await sources.aclose()
            await window.aclose()
            window.close()
            await radio.stop()
            await server.close()


def grab_with_menus(window: ClientWindow, sources: ClientSources) -> QPixmap:
    """The window with the Sources menu open below its title and the FlexRadio submenu
    beside it (each menu drawn where it would pop up)."""
    bar = window.menuBar()
    action = sources.menu.menuAction()
    at = bar.mapTo(window, bar.actionGeometry(action).bottomLeft())
    sources._show_list()
    sources.menu.adjustSize()
    sources.show_flex()
    sources.flex_menu.adjustSize()
    sub = sources.menu.actionGeometry(sources.flex_menu.menuAction())
    picture = window.grab()
    painter = QPainter(picture)
    menu = sources.menu.grab()
    painter.drawPixmap(at, menu)
    painter.drawPixmap(QPoint(at.x() + menu.width() - 4, at.y() + sub.top()),
                       sources.flex_menu.grab())
    painter.end()
    return picture


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
