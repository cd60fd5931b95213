"""The emulator window (offscreen Qt), and the switch link running on the Qt
event loop through qasync, as it does under the server's window."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from pathlib import Path

import pytest
import qasync  # type: ignore[import-untyped]
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QApplication, QGroupBox

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, serve
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink
from moas_gui.ui.emulator_window import EmulatorWindow


@pytest.fixture
def box() -> Iterator[EmulatedBox]:
    loop = asyncio.new_event_loop()
    emulated = EmulatedBox(EmulatorModel(unit_id=3), loop=loop)
    yield emulated
    emulated.close()
    loop.close()


@pytest.fixture
def window(qtbot, box: EmulatedBox) -> EmulatorWindow:  # type: ignore[no-untyped-def]
    shown = EmulatorWindow(box, port="/dev/pts/99")
    qtbot.addWidget(shown)
    shown.show()
    return shown


def test_window_shows_64_relays_in_eight_groups_of_eight(window: EmulatorWindow) -> None:
    assert len(window.relay_labels) == 64
    titles = [g.title() for g in window.findChildren(QGroupBox)]
    for group in range(8):
        assert f"{group * 8}-{group * 8 + 7}" in titles
    assert "/dev/pts/99" in window.windowTitle()
    assert "inactive" in window.header.text() and "unit 3" in window.header.text()


def test_window_follows_the_relays_the_box_closes(qtbot, window: EmulatorWindow,  # type: ignore[no-untyped-def]
                                                  box: EmulatedBox) -> None:
    box.receive(b"*1;&1;!1B112;!2B2z;")
    qtbot.waitUntil(lambda: window.relay_shown_closed(61))
    assert [r for r in range(64) if window.relay_shown_closed(r)] == [1, 2, 61]
    assert window.station_cells[1]["TX"].text() == "1 [1, 2]"
    assert "active" in window.header.text()


def test_tx_checkbox_keys_the_station(qtbot, window: EmulatorWindow,  # type: ignore[no-untyped-def]
                                     box: EmulatedBox) -> None:
    box.receive(b"*1;&F12;!1T11;!1R22;")
    qtbot.waitUntil(lambda: window.relay_shown_closed(2))
    key = window.key_boxes[1]
    qtbot.mouseClick(key, Qt.MouseButton.LeftButton, pos=QPoint(6, key.height() // 2))
    assert box.view().station(1).key
    qtbot.waitUntil(lambda: window.relay_shown_closed(1))
    assert not window.relay_shown_closed(2)
    assert window.station_cells[1]["State"].text().startswith("TX")
    window.key_boxes[1].setChecked(False)
    assert not box.view().station(1).key


def test_window_shows_inhibits_and_a_key_changed_elsewhere(qtbot, window: EmulatorWindow,  # type: ignore[no-untyped-def]
                                                          box: EmulatedBox) -> None:
    box.receive(b"*1;(2;~13;")
    box.set_tr(1, True)
    qtbot.waitUntil(lambda: window.key_boxes[1].isChecked())
    assert window.station_cells[2]["Inhibit"].text().startswith("yes: command")
    assert "by 1" in window.station_cells[3]["Inhibit"].text()
    assert window.station_cells[4]["Inhibit"].text().startswith("no")


def test_window_logs_the_bytes_received_and_sent(qtbot, window: EmulatorWindow,  # type: ignore[no-untyped-def]
                                                box: EmulatedBox) -> None:
    box.receive(b"';\x01")
    text = window.log.toPlainText()
    assert "in  ';\\x01" in text
    assert "out .;" in text


def test_closing_the_window_stops_listening(qtbot, window: EmulatorWindow,  # type: ignore[no-untyped-def]
                                           box: EmulatedBox) -> None:
    with qtbot.waitSignal(window.closed, timeout=1000):
        window.close()
    before = window.log.toPlainText()
    box.receive(b"';")
    assert window.log.toPlainText() == before


@pytest.mark.realtime  # a link to the emulator on a pseudo-terminal, on the real clock
def test_switch_link_runs_on_the_qt_event_loop(qapp: QApplication, tmp_path: Path) -> None:
    loop = qasync.QEventLoop(qapp)
    timing = LinkTiming(ping_interval=0.05, answer_timeout=1.0, retry_first=0.05, retry_max=0.2)
    state = SwitchState(stations=(
        StationAntennas(tx=1, tx_relays=frozenset({4}), rx=1, rx_relays=frozenset({4})),
        *(StationAntennas(),) * 5,
    ))

    async def scenario() -> frozenset[int] | None:
        box = EmulatedBox()
        endpoint = PtyEndpoint()
        serve(box, endpoint, asyncio.get_running_loop())
        link = SwitchLink(1, endpoint.path, options=LinkOptions(timing=timing))
        link.apply(state)
        link.connect()
        try:
            for _ in range(800):
                if link.status is LinkStatus.OK:
                    break
                await asyncio.sleep(0.01)
            return await link.ask_relays()
        finally:
            await link.close()
            box.close()
            endpoint.close()

    try:
        assert loop.run_until_complete(scenario()) == {4}
    finally:
        loop.close()


def test_pings_and_their_answers_stay_out_of_the_log_unless_asked(
        qtbot, window: EmulatorWindow, box: EmulatedBox) -> None:  # type: ignore[no-untyped-def]
    box.receive(b"';")
    box.receive(b'"B;')
    text = window.log.toPlainText()
    assert "';" not in text and 'in  "B;' in text
    assert len(text.splitlines()) == 2, "the status request and its answer only"
    window.show_pings.setChecked(True)
    box.receive(b"';")
    assert "in  ';" in window.log.toPlainText()
