"""Opens the server window (with its built-in client and its station plan window), the
standalone client (with its Sources menu) and the emulator window as the programs do, on whatever screen Qt is
given, and prints one JSON line: each window's frame and the screen's available
area.  Run by tests/ui/test_screen_fit.py under Qt's offscreen platform with a screen
size and scale of its choice."""

from __future__ import annotations

import asyncio
import json
import socket
import sys
from pathlib import Path

import qasync  # type: ignore[import-untyped]

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.client.connection import ClientConnection
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.ui.client_sources import ClientSources
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.emulator_window import EmulatorWindow
from moas_gui.ui.qt import QApplication, QSettings, QWidget
from moas_gui.ui.server_window import ServerWindow


def frame(window: QWidget) -> list[int]:
    box = window.frameGeometry()
    return [box.x(), box.y(), box.width(), box.height()]


async def probe(settings_dir: str) -> dict[str, object]:
    closed = socket.socket()
    closed.bind(("127.0.0.1", 0))
    port = closed.getsockname()[1]
    closed.close()  # nobody listens: the standalone client keeps trying, as on a real start
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False))
    settings = QSettings(str(Path(settings_dir) / "settings.ini"), QSettings.Format.IniFormat)
    server = ServerWindow(app, settings, lambda: None)
    server.show()
    server.open_file(sys.argv[2])
    await server.idle()
    server.action_client.trigger()
    (builtin,) = server.client_windows
    server.action_plan.trigger()
    await server.idle()
    plan_window = server.plan_window
    assert plan_window is not None
    standalone = ClientWindow(ClientConnection("127.0.0.1", port, name="probe"))
    sources = ClientSources(standalone, settings)
    standalone.show()
    box = EmulatedBox()
    emulator = EmulatorWindow(box, port="/dev/pts/99")
    emulator.show()
    for _ in range(20):  # the loop runs Qt's events meanwhile: the windows are laid out
        await asyncio.sleep(0.01)
    screen = QApplication.primaryScreen()
    area = screen.availableGeometry()
    bar = emulator.scroll_area.horizontalScrollBar()
    result = {
        "area": [area.x(), area.y(), area.width(), area.height()],
        "scale": screen.devicePixelRatio(),
        "windows": {"server": frame(server), "built-in client": frame(builtin),
                    "standalone client": frame(standalone), "emulator": frame(emulator),
                    "station plan": frame(plan_window)},
        "emulator relays hidden": bar.maximum(),
        "emulator relays width": emulator.scroll_area.widget().sizeHint().width(),
    }
    await sources.aclose()
    for window in (builtin, standalone):
        window.close()
        await window.aclose()
    emulator.close()
    plan_window.close()
    await app.close()
    server.shutdown()
    return result


def main() -> None:
    application = QApplication([sys.argv[0]])
    application.setQuitOnLastWindowClosed(False)
    loop = qasync.QEventLoop(application)
    asyncio.set_event_loop(loop)
    with loop:
        result = loop.run_until_complete(probe(sys.argv[1]))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
