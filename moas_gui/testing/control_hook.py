"""Remote hands for journey tests: a person's clicks, sent over a socket.

The product never imports this module.  A journey test starts ``moas-server``
with ``MOAS_GUI_CONTROL_HOOK=moas_gui.testing.control_hook`` (the window's
generic hook seam, :mod:`moas_gui.ui.control_hook`, then imports it and calls
:func:`start`) and ``MOAS_GUI_CONTROL_SOCKET`` naming a Unix socket path, where
the window then listens (mode 0600, in the test's own directory).  Each
request is one JSON line, each reply one JSON line:

``{"do": "look"}``
    what a person sees: the title, the status bar, the tray tooltip and menu,
    open dialogs (title, text, buttons) and the visible windows; for each open
    emulator window, the relays it shows closed.
``{"do": "menu", "path": ["File", "Stop Switches"]}``
    triggers a real menu item (``"Tray"`` is the tray icon's menu; a path
    ending in a submenu item such as ``["View", "Emulator", "Switch 1"]`` works
    too), as a click does: from the Qt event loop, after this reply.
``{"do": "answer", "button": "Yes"}``
    clicks a button of the open question dialog.
``{"do": "choose", "path": "/path/station.moas"}``
    picks a file in the open file dialog (File > Open, Save Switch Data).
``{"do": "close"}``
    closes the server window, as its title bar's close button does.

Nothing here runs, or is even imported, in a normal launch.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import sys
from pathlib import Path
from typing import Any

from moas_gui.ui.qt import (
    QAction,
    QApplication,
    QFileDialog,
    QLineEdit,
    QMenu,
    QMessageBox,
    QTimer,
    QWidget,
)

ENVIRONMENT = "MOAS_GUI_CONTROL_SOCKET"


def _plain(text: str) -> str:
    return text.replace("&", "").strip()


class ControlHook:
    """Serves the requests above for one server window."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self._server: asyncio.AbstractServer | None = None
        self._connections: dict[asyncio.StreamWriter, asyncio.Task[Any] | None] = {}

    async def start(self, path: str) -> None:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
        if sys.platform == "win32":
            raise OSError("the control hook listens on a Unix socket: not on Windows")
        self._server = await asyncio.start_unix_server(self._serve, path=path)
        os.chmod(path, 0o600)

    async def close(self) -> None:
        if self._server is not None:
            self._server.close()
            self._server = None
        tasks = [t for t in self._connections.values() if t is not None]
        for writer in list(self._connections):
            writer.close()  # the reader sees the end and the connection's task ends
        await asyncio.wait_for(asyncio.gather(*tasks, return_exceptions=True), 2)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._connections[writer] = asyncio.current_task()
        try:
            while line := await reader.readline():
                try:
                    reply = self.handle(json.loads(line))
                except Exception as exc:  # noqa: BLE001 - the test reads the reason
                    reply = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
                writer.write(json.dumps(reply).encode() + b"\n")
                await writer.drain()
        except ConnectionError:
            pass
        finally:
            self._connections.pop(writer, None)
            writer.close()

    def handle(self, request: dict[str, Any]) -> dict[str, Any]:
        kind = request.get("do")
        if kind == "look":
            return {"ok": True, **self.look()}
        if kind == "menu":
            action = self._find(list(request["path"]))
            if not action.isEnabled():
                return {"ok": False, "error": f"{' > '.join(request['path'])} is disabled"}
            QTimer.singleShot(0, action.trigger)
            return {"ok": True}
        if kind == "choose":
            dialogs = [w for w in QApplication.topLevelWidgets()
                       if isinstance(w, QFileDialog) and w.isVisible()]
            if not dialogs:
                return {"ok": False, "error": "no file dialog is open"}
            name = dialogs[0].findChild(QLineEdit, "fileNameEdit")
            if name is None:
                return {"ok": False, "error": "the file dialog has no file name field"}
            name.setText(str(request["path"]))  # typed, as a person does, then Open
            QTimer.singleShot(0, dialogs[0].accept)
            return {"ok": True}
        if kind == "close":
            QTimer.singleShot(0, self.window.close)  # the title bar's close button
            return {"ok": True}
        if kind == "answer":
            for box in self._dialogs():
                for button in box.buttons():
                    if _plain(button.text()) == request["button"]:
                        QTimer.singleShot(0, button.click)
                        return {"ok": True}
            return {"ok": False, "error": f"no open dialog has a {request['button']!r} button"}
        return {"ok": False, "error": f"unknown request {kind!r}"}

    def _find(self, path: list[str]) -> QAction:
        window = self.window
        actions: list[QAction]
        if path[0] == "Tray":
            actions, path = window.tray_menu.actions(), path[1:]
        else:
            actions = window.menuBar().actions()
        for step, name in enumerate(path):
            found: list[QAction] = [a for a in actions if _plain(a.text()) == name and a.isVisible()]
            if not found:
                shown = [_plain(a.text()) for a in actions if a.text()]
                raise LookupError(f"no menu item {name!r} in {shown}")
            if step == len(path) - 1:
                return found[0]
            menu = found[0].menu()
            if not isinstance(menu, QMenu):
                raise TypeError(f"{name!r} is not a menu")
            actions = menu.actions()
        raise LookupError("empty menu path")

    def _dialogs(self) -> list[QMessageBox]:
        return [w for w in QApplication.topLevelWidgets()
                if isinstance(w, QMessageBox) and w.isVisible()]

    def look(self) -> dict[str, Any]:
        window = self.window
        tops: list[QWidget] = [w for w in QApplication.topLevelWidgets() if w.isVisible()]
        emulators = {}
        for switch_id, emulator_window in window.emulator_windows.items():
            if emulator_window.isVisible():
                emulators[str(switch_id)] = [
                    relay for relay in range(len(emulator_window.relay_labels))
                    if emulator_window.relay_shown_closed(relay)]
        return {
            "title": window.windowTitle(),
            "status": window.statusBar().currentMessage(),
            "tray_tooltip": window.tray.toolTip(),
            "tray_visible": window.tray.isVisible(),
            "window_visible": window.isVisible(),
            "tray_menu": [_plain(a.text()) for a in window.tray_menu.actions() if a.text()],
            "dialogs": [{"title": b.windowTitle(), "text": b.text(),
                         "buttons": [_plain(x.text()) for x in b.buttons()]}
                        for b in self._dialogs()],
            "windows": [w.windowTitle() for w in tops],
            "emulators": emulators,
            "log": window.log_view.shown_lines()[-40:],
        }


async def start(window: Any) -> ControlHook:
    """Listen for a journey test's requests on the socket ``MOAS_GUI_CONTROL_SOCKET`` names."""
    path = os.environ.get(ENVIRONMENT)
    if not path:
        raise OSError(f"{ENVIRONMENT} names no socket path for the control hook to listen on")
    hook = ControlHook(window)
    await hook.start(str(Path(path)))
    return hook


__all__ = ["ENVIRONMENT", "ControlHook", "start"]
