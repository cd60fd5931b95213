"""The client window's Sources menu lists the FlexRadios heard on the network (the test
radio's discovery datagrams over real UDP), reads the one chosen over real TCP and tells
the protocol server on 127.0.0.1; the radio gone is shown in words in the menu."""

from __future__ import annotations

import asyncio
import socket
from pathlib import Path

from client_support import LiveServer, run_on_qt
from helpers import free_port, until
from test_client_window import open_window

from moas_gui.testing.flex_radio import FlexRadio
from moas_gui.ui.client_sources import ClientSources
from moas_gui.ui.qt import QApplication, QSettings


def test_a_flexradio_heard_is_listed_chosen_read_and_shown_offline(qapp: QApplication,
                                                                   tmp_path: Path) -> None:
    settings = QSettings(str(tmp_path / "client.ini"), QSettings.Format.IniFormat)
    udp = free_port(socket.SOCK_DGRAM)

    async def scenario() -> None:
        radio = FlexRadio(nickname="Contest")
        await radio.start()
        radio.set_slice(0, RF_frequency=14.025, tx=1)
        radio.set_slice(1, RF_frequency=7.0125)
        async with LiveServer() as live, open_window(live) as window:
            sources = ClientSources(window, settings, flex_port=udp)
            try:
                sources.show_flex()
                [none] = sources.flex_actions
                assert none.text().startswith("No FlexRadio heard") and not none.isEnabled()
                def heard() -> bool:
                    radio.announce(("127.0.0.1", udp))  # as a radio does, again and again
                    return bool(sources.flex_discovery.radios())

                await until(heard, what="the radio heard", every=0.1)
                sources.show_flex()
                [action] = sources.flex_actions
                assert action.text() == ('FLEX-6600 "Contest" (serial 1234-5678-9012-3456, '
                                         f"127.0.0.1:{radio.port})")
                action.trigger()
                # the demo station's station 1 has one radio: the other slice is not used
                assert [s.text() for s in sources.specs] == [
                    f"flex:127.0.0.1:{radio.port},radio2=0"]
                await until(lambda: (1, 1, 14025.0, None) in live.calls("frequency"),
                            what="the transmitting slice told to the server")
                await until(lambda: ("Reading flex:127.0.0.1:"
                                     f"{radio.port},radio2=0: connected, API 1.4.0.0")
                            in _listed(sources), what="the menu saying it reads the radio")
                assert _listed(sources)[1:] == [
                    "    station 1 radio 1: slice A 14,025.000 kHz CW, RX ANT1, TX ANT1"]
                radio.set_slice(1, tx=1)  # the transmitter moves to slice B: radio 1 follows
                await until(lambda: (1, 1, 7012.5, None) in live.calls("frequency"),
                            what="slice B, now transmitting, told as radio 1")
                assert not any(c[1] == 2 for c in live.calls("frequency"))
                await radio.stop()
                await until(lambda: any(": offline (" in t for t in _listed(sources)),
                            what="the menu saying the radio is offline")
            finally:
                await sources.aclose()
                await radio.stop()

    run_on_qt(qapp, scenario())


def _listed(sources: ClientSources) -> list[str]:
    sources._show_list()
    return [a.text() for a in sources._listed]


def test_a_port_that_cannot_be_listened_on_is_said_in_the_menu(qapp: QApplication,
                                                               tmp_path: Path) -> None:
    settings = QSettings(str(tmp_path / "client.ini"), QSettings.Format.IniFormat)

    async def scenario() -> None:
        holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # no SO_REUSEADDR
        holder.bind(("0.0.0.0", 0))
        port = holder.getsockname()[1]
        try:
            async with LiveServer() as live, open_window(live) as window:
                sources = ClientSources(window, settings, flex_port=port)
                try:
                    await until(lambda: sources.flex_problem, what="the bind refused")
                    sources.show_flex()
                    [said] = sources.flex_actions
                    assert said.text().startswith(f"Cannot listen on UDP {port}: ")
                    await asyncio.sleep(0)
                finally:
                    await sources.aclose()
        finally:
            holder.close()

    run_on_qt(qapp, scenario())
