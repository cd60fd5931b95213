"""A rule walked through the real windows: no two items of one menu share a mnemonic.

Alt+F, A must restart, not move the highlight between two items on A.  Every menu of
the server window (its menu bar, the submenus, the tray's menu), of the built-in client
window (its menu bar and its Why? menu) and of the other windows the server opens is
walked; an item's mnemonic is the letter after its single ``&``.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from client_support import LOOPBACK, LiveServer, run_on_qt
from helpers import until
from test_server_window import Harness, running

from moas_gui.client import ClientConnection
from moas_gui.ui.client_sources import ClientSources
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.qt import QApplication, QMainWindow, QMenu, QSettings, QWidget


def mnemonic(text: str) -> str | None:
    """The letter after the single ``&`` of ``text`` (``&&`` is a literal ampersand)."""
    plain = text.replace("&&", "")
    at = plain.find("&")
    if at < 0 or at + 1 >= len(plain):
        return None
    return plain[at + 1].lower()


def clashes(menu_name: str, texts: Iterable[str]) -> list[str]:
    """Every pair of ``texts`` on one letter, described for a failure message."""
    seen: dict[str, str] = {}
    found: list[str] = []
    for text in texts:
        letter = mnemonic(text)
        if letter is None:
            continue
        if letter in seen:
            found.append(f"{menu_name}: {seen[letter]!r} and {text!r} both on {letter!r}")
        else:
            seen[letter] = text
    return found


def every_menu(window: QWidget) -> list[tuple[str, list[str]]]:
    """Each menu of ``window`` (the bar's, its submenus, any context menu it owns) with the
    texts of its items, in order."""
    menus: list[tuple[str, list[str]]] = []
    if isinstance(window, QMainWindow):
        bar = window.menuBar()
        menus.append((f"{type(window).__name__} menu bar",
                      [a.text() for a in bar.actions() if not a.isSeparator()]))
    for menu in window.findChildren(QMenu):
        name = menu.title().replace("&", "") or menu.objectName() or "a context menu"
        menus.append((f"{type(window).__name__} > {name}",
                      [a.text() for a in menu.actions() if not a.isSeparator()]))
    return menus


def test_the_rule_catches_two_items_on_one_letter() -> None:
    assert clashes("File", ["&Open", "Keep an &Antenna Log", "Rest&art"]) == [
        "File: 'Keep an &Antenna Log' and 'Rest&art' both on 'a'"]
    assert clashes("File", ["&Open", "Save && &Quit", "E&xit"]) == []
    assert mnemonic("Save && &Quit") == "q" and mnemonic("Plain") is None


def test_no_menu_of_the_server_window_or_its_tray_has_two_items_on_one_letter(
        qapp: Any, tmp_path: Path) -> None:
    harness = Harness(tmp_path)

    async def scenario() -> None:
        window, _app = await running(harness)
        window.open_plan()
        await window.idle()
        menus = every_menu(window)
        for top in QApplication.topLevelWidgets():
            if top is not window and top.isVisible():
                menus += every_menu(top)
        names = {name for name, _texts in menus}
        assert {"ServerWindow > File", "ServerWindow > View", "ServerWindow > Help",
                "ServerWindow > Emulator", "ServerWindow > Recent Files"} <= names
        assert any(texts and "Exit" in texts for _name, texts in menus), "the tray's menu"
        found = [clash for name, texts in menus for clash in clashes(name, texts)]
        assert found == []
        file_texts = dict(menus)["ServerWindow > File"]
        restart = next(text for text in file_texts if text.replace("&", "") == "Restart")
        assert [t for t in file_texts if mnemonic(t) == mnemonic(restart)] == [restart]
        await harness.close()
    run_on_qt(qapp, scenario())


def test_no_menu_of_the_client_window_has_two_items_on_one_letter(
        qapp: Any, tmp_path: Path) -> None:
    async def scenario() -> None:
        async with LiveServer() as live:
            window = ClientWindow(ClientConnection(LOOPBACK, live.port, timeout=2.0))
            settings = QSettings(str(tmp_path / "client.ini"), QSettings.Format.IniFormat)
            sources = ClientSources(window, settings)  # as moas-client attaches it
            window.start()
            window.show()
            try:
                await until(lambda: bool(window.grid.buttons), what="the client's buttons")
                menus = every_menu(window)
                assert any(name.endswith("Sources") for name, _ in menus)
                found = [clash for name, texts in menus for clash in clashes(name, texts)]
                assert found == []
            finally:
                await sources.aclose()
                await window.aclose()
                window.close()
                window.deleteLater()
    run_on_qt(qapp, scenario())
