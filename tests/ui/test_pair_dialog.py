"""View > Pair a device on a real server window (offscreen): the dialog asks a name and a
role, adds the operator, and shows the page's https address with the token in the
fragment as a QR code; the window's status bar says the LAN is open and shows the TLS
fingerprint."""

from __future__ import annotations

import asyncio
import logging
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from client_support import run_on_qt
from helpers import until
from test_server_window import EXAMPLES, FAST

from moas_gui.addresses import WebPage
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.operators import OperatorBook, Role
from moas_gui.tls import default_paths, fingerprint
from moas_gui.ui.pair_dialog import PairDialog, fingerprint_lines, pairing_url, qr_pixmap
from moas_gui.ui.qt import QSettings
from moas_gui.ui.server_window import ServerWindow

SCREENSHOTS = os.environ.get("MOAS_SCREENSHOTS")


@pytest.fixture(autouse=True)
def own_config(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "cfg"))


def test_pairing_adds_an_operator_and_shows_its_token_only_in_the_code(
        qapp: Any, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG)

    async def scenario() -> None:
        app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, web_port=0,
                                      udp_bind="127.0.0.1", start_rotator_program=False,
                                      switch_timing=FAST, tls=True))
        window = ServerWindow(app, QSettings(str(tmp_path / "s.ini"),
                                             QSettings.Format.IniFormat), lambda: None)
        window.show()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        await until(lambda: app.web_address is not None)
        seen = fingerprint(default_paths())
        assert "LAN open" in window.security_label.text()
        assert seen in window.security_label.toolTip()
        window.action_pair.trigger()
        dialog = window.pair_dialog
        assert dialog.isVisible()
        await asyncio.sleep(0.05)  # the loop runs on: the dialog was opened, not exec()ed
        # bound to loopback: no code a phone cannot reach; said, with how to open it
        assert "127.0.0.1 only" in dialog.message.text()
        assert "--bind 0.0.0.0" in dialog.message.text()
        assert not dialog.create_button.isEnabled() and dialog.address_box.count() == 0
        assert dialog.fingerprint.text().replace("\n", ":") == seen
        assert app.options.bind == "127.0.0.1"  # nothing changed the bind
        if SCREENSHOTS:
            dialog.grab().save(str(Path(SCREENSHOTS) / "pair-loopback-only.png"))
        dialog.close()
        page = app.web_page
        assert page is not None and page.fingerprint == seen and page.tls
        # the same page as a station listening on its LAN address would serve it
        dialog = PairDialog(window, replace(page, bind="192.0.2.5"))
        dialog.open()
        assert dialog.create_button.isEnabled() and dialog.address_box.currentText() == "192.0.2.5"
        dialog.name.setText("tablet 40m")
        dialog.role.setCurrentIndex(dialog.role.findData(Role.OPERATE.value))
        dialog.create_button.click()
        url = dialog.url
        assert url is not None and url.startswith(f"https://192.0.2.5:{page.port}/#token=")
        assert seen.split(":")[0] in dialog.fingerprint.text()
        token = url.split("#token=", 1)[1]
        operator = OperatorBook().check(token)
        assert operator is not None and operator.name == "tablet 40m"
        assert operator.role is Role.OPERATE
        assert not dialog.code.pixmap().isNull() and dialog.code.pixmap().width() > 150
        dialog.adjustSize()
        assert dialog.width() <= 1024 and dialog.height() <= 600  # a small station laptop
        dialog.grab().save(str(tmp_path / "pair.png"))
        if SCREENSHOTS:
            dialog.grab().save(str(Path(SCREENSHOTS) / "pair-a-device.png"))
        window.grab().save(str(tmp_path / "window.png"))
        dialog.close()
        window.action_client.trigger()  # the built-in client: TLS, pinned to this server
        client = window.client_windows[-1]
        await until(lambda: client.connection.connects > 0)
        assert client.connection.fingerprint == seen
        window.shutdown()
        await window.idle()
        window.close()
        await app.close()
        said = " ".join(r.getMessage() for r in caplog.records)
        assert 'operator "tablet 40m" (operate) added' in said
        assert token.rsplit(".", 1)[1][:10] not in said

    run_on_qt(qapp, scenario())


def test_a_name_already_taken_is_said_in_the_dialog(qapp: Any, tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "ops.json")
    book.add("phone", Role.VIEW)
    dialog = PairDialog(None, WebPage("192.0.2.5", 8080, False), book)
    assert "without TLS" in dialog.message.text()
    dialog.name.setText("Phone")
    dialog.create_button.click()
    assert "already an operator" in dialog.message.text() and dialog.url is None
    dialog.close()
    none = PairDialog(None, None, book)
    assert not none.create_button.isEnabled() and "WebPort" in none.message.text()
    none.close()


def test_the_code_and_address_are_what_a_phone_needs() -> None:
    assert pairing_url("fe80::1", 8080, True, "moas1.x.y") == "https://[fe80::1]:8080/#token=moas1.x.y"
    small, large = qr_pixmap("http://a/", 2), qr_pixmap("http://a/" + "x" * 200, 2)
    assert small.width() == small.height() and large.width() > small.width()


def test_several_lan_addresses_are_a_choice_and_the_code_follows_it(qapp: Any,
                                                                   tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "ops.json")
    pin = ":".join(["AB"] * 32)
    dialog = PairDialog(None, WebPage("192.0.2.5", 8443, True, pin), book)
    dialog.addresses = ["192.0.2.5", "fd00::5"]  # as a station on two networks lists them
    dialog.address_box.addItem("fd00::5")
    assert fingerprint_lines(pin).count("\n") == 1
    dialog.name.setText("phone")
    dialog.create_button.click()
    first = dialog.url
    assert first is not None and first.startswith("https://192.0.2.5:8443/#token=")
    dialog.address_box.setCurrentIndex(1)
    assert dialog.url == first.replace("192.0.2.5", "[fd00::5]")  # the same token
    assert "fingerprint must be the one above" in dialog.address.text()
    dialog.close()
