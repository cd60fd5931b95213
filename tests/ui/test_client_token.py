"""The desktop client's token request against a real ``moas-server --require-token``:
the client connects from 127.0.0.2 (which the server counts as the LAN), so the
station asks for an operator's token.  The window opens its request (with open()),
says a wrong token is not taken in an operator's words, takes the token from a
pasted pairing link, keeps it once the station took it, and forgets it on request
(the station then asks again); a token typed into the field signs in too."""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from client_support import run_on_qt
from helpers import free_port, until

from moas_gui.client.connection import ClientConnection
from moas_gui.client.events import LinkState, TokenWanted
from moas_gui.client.keys import ClientKeys
from moas_gui.ui.client_window import ClientWindow
from moas_gui.ui.qt import QApplication, QDialogButtonBox
from moas_gui.ui.token_dialog import token_from_text

pytestmark = pytest.mark.realtime

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SCREENSHOTS = os.environ.get("MOAS_SCREENSHOTS")


def _environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
                XDG_STATE_HOME=str(tmp_path / "state"), PYTHONUNBUFFERED="1",
                QT_QPA_PLATFORM="offscreen")


def _add_operator(env: dict[str, str], name: str) -> str:
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--add-operator", name,
                           "--role", "operate"], env=env, capture_output=True, text=True,
                          check=True, timeout=60)
    return done.stdout.splitlines()[-1]


def test_pairing_link_and_token_links() -> None:
    assert token_from_text(" https://192.168.1.5:8080/#token=moas1.abc.def ") == "moas1.abc.def"
    assert token_from_text("https://[fd00::5]:8080/?station=1#token=moas1.x") == "moas1.x"
    assert token_from_text("moas1.plain") == "moas1.plain"
    assert token_from_text("https://host:1/#other=1") == ""


def test_the_window_asks_for_a_token_checks_keeps_and_forgets_it(
        qapp: Any, tmp_path: Path, runtime_dir: Path) -> None:
    env = _environment(tmp_path, runtime_dir)
    token = _add_operator(env, "laptop")
    tcp = free_port(socket.SOCK_STREAM)
    server = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
         "--headless", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--no-rotator-program", "--require-token", "--new-instance"],
        env=env, stderr=subprocess.PIPE, text=True)
    keys = ClientKeys(tmp_path / "client", use_keyring=False)
    station = f"127.0.0.1:{tcp}"

    async def scenario() -> None:
        connection = ClientConnection("127.0.0.1", tcp, local_host="127.0.0.2",
                                      connect_timeout=10)
        window = ClientWindow(connection, keys=keys)
        window.resize(1024, 600)
        window.show()
        window.start()
        tokens = window.tokens
        assert tokens is not None
        await until(lambda: tokens.dialog is not None and tokens.dialog.isVisible(),
                    timeout=60, what="the token request")
        dialog = tokens.dialog
        assert dialog is not None
        await asyncio.sleep(0.05)  # the loop runs on: opened, not exec()ed
        said = dialog.message.text()
        assert "asks for an operator's token: ask its admin, or scan its pairing code" in said
        assert "hello" not in said and "forbidden" not in said
        assert "asks for an operator's token" in window.link_label.text()
        assert dialog.width() <= 1024 and dialog.height() <= 600
        dialog.grab().save(str(tmp_path / "token-request.png"))
        if SCREENSHOTS:
            dialog.grab().save(str(Path(SCREENSHOTS) / "client-token-request.png"))

        dialog.field.setText("moas1.not.a-real-token")  # a wrong token: said in words
        dialog.sign_in.click()
        assert dialog.is_checking and not dialog.field.isEnabled()
        await until(lambda: "did not take that token" in dialog.message.text(), timeout=30,
                    what="the wrong token's answer")
        assert dialog.isVisible() and dialog.field.isEnabled() and dialog.field.text() == ""
        assert connection.link is not LinkState.CONNECTED and keys.token(station) is None
        assert "forbidden" not in dialog.message.text()
        if SCREENSHOTS:
            dialog.grab().save(str(Path(SCREENSHOTS) / "client-token-refused.png"))

        clipboard = QApplication.clipboard()
        clipboard.setText(f"https://192.168.1.5:8443/#token={token}")
        dialog.paste_button.click()  # a pasted pairing link: its token is taken
        assert dialog.field.text() == token
        dialog.sign_in.click()
        await until(lambda: connection.link is LinkState.CONNECTED, timeout=30,
                    what="the signed-in connection")
        await until(lambda: not dialog.isVisible())
        assert keys.token(station) == token
        await until(lambda: "Signed in; the token is kept in" in window.status_text(),
                    what="where the token is kept, in the status line")
        assert window.snapshot is not None

        tokens.forget_action.trigger()  # forgotten: the station asks again
        assert keys.token(station) is None and connection.token is None
        await until(lambda: dialog.isVisible(), timeout=30, what="the request again")
        assert "asks for an operator's token" in dialog.message.text()

        asked: list[TokenWanted] = []
        connection.subscribe(lambda e: asked.append(e) if isinstance(e, TokenWanted) else None)
        dialog.buttons.button(QDialogButtonBox.StandardButton.Cancel).click()  # not now
        assert not dialog.isVisible()
        await until(lambda: len(asked) >= 1, timeout=30, what="the station asking again")
        await asyncio.sleep(0.05)
        assert not dialog.isVisible()  # cancelled: not opened again by itself
        assert "asks for an operator's token" in window.link_label.text()
        tokens.give_action.trigger()  # Operator > Give a Token...
        assert dialog.isVisible() and dialog.field.isEnabled()

        dialog.field.setText(token)  # typed
        dialog.field.returnPressed.emit()
        await until(lambda: connection.link is LinkState.CONNECTED, timeout=30,
                    what="the connection with the typed token")
        assert keys.token(station) == token
        window.close()
        await window.aclose()

    try:
        run_on_qt(qapp, scenario(), timeout=120)
    finally:
        server.terminate()
        _, stderr = server.communicate(timeout=15)
    assert 'operator "laptop"' in stderr
    assert token.rsplit(".", 1)[1][:10] not in stderr
