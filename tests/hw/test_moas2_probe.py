"""``moas-server --probe PORT`` against an emulated box on a real pseudo-terminal: the
report an owner reads, questions only (no relay moves), a port a link holds refused,
a silent port, and the command line with its recording."""

from __future__ import annotations

import asyncio
import os
import pty
import sys
import tty
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until
from switch_support import Cable

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink
from moas_gui.hw.moas2.messages import SetState, StateOp
from moas_gui.hw.moas2.probe import PROBE_QUESTIONS, ProbeRefused, probe
from moas_gui.hw.moas2.recording import read_recording, text_bytes

pytestmark = pytest.mark.realtime

FAST = LinkTiming(ping_interval=0.05, answer_timeout=2.0, retry_first=0.05, retry_max=0.2)
QUESTION_BYTES = b"';" + b":;" + b'"B;' + b'"I;' + b"|;"
LOADED = SwitchState(stations=(
    StationAntennas(tx=1, tx_relays=frozenset({1, 2}), rx=1, rx_relays=frozenset({1, 2})),
    StationAntennas(tx=2, tx_relays=frozenset({8}), rx=2, rx_relays=frozenset({8})),
    *(StationAntennas() for _ in range(4))), conflicts=frozenset({(1, 1), (2, 2)}))


class Box:
    """An emulated box on a pseudo-terminal, with what it received."""

    def __init__(self, cable: Cable, box: EmulatedBox) -> None:
        self.cable = cable
        self.box = box
        self.received = bytearray()
        box.add_listener(self._heard)

    def _heard(self, kind: Traffic, data: bytes) -> None:
        if kind is Traffic.RECEIVED:
            self.received += data

    @property
    def path(self) -> str:
        return str(self.cable.link)


@pytest_asyncio.fixture
async def box(tmp_path: Path) -> AsyncIterator[Box]:
    cable = Cable(tmp_path / "moas")
    served = Box(cable, cable.plug())
    yield served
    cable.unplug()


async def load(box: Box) -> None:
    """A server's link loads the box, then lets the port go (the relays stay)."""
    link = SwitchLink(1, box.path, options=LinkOptions(timing=FAST))
    link.apply(LOADED)
    link.connect()
    try:
        await until(lambda: box.box.view().relays == {1, 2, 8} and link.status is LinkStatus.OK)
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_the_probe_reports_a_loaded_box_and_moves_no_relay(box: Box) -> None:
    await load(box)
    box.received.clear()
    report = await probe(box.path)
    assert bytes(box.received) == QUESTION_BYTES
    assert box.box.view().relays == {1, 2, 8}
    text = report.text()
    assert "the box is ACTIVE" in text
    assert "Unit id: 0" in text and "Firmware: V1.00" in text
    assert "Closed relays (3 of 64): 1, 2, 8" in text
    assert "station 1: receiving" in text and "TX    1  RX    1" in text
    assert "no relay can have moved" in text
    assert "-> ';" in text and "<- !;" in text


@pytest.mark.asyncio
async def test_the_probe_warns_of_a_keyed_station(box: Box) -> None:
    await load(box)
    box.box.set_tr(2, True)
    report = await probe(box.path)
    assert "station 2: TRANSMITTING" in report.text()
    assert "WARNING: station 2 transmits now." in report.text()


@pytest.mark.asyncio
async def test_the_probe_of_a_box_not_yet_loaded_says_it_cannot_know_who_is_keyed(
        box: Box) -> None:
    """First contact is with an inactive box, whose status the emulator (like the
    programming guide) gives no key state for: the report asks to unkey first."""
    box.box.set_tr(1, True)
    text = (await probe(box.path)).text()
    assert "the box is inactive" in text
    assert "CANNOT KNOW whether a station is keyed" in text
    assert "Unkey every radio" in text
    # an active box reports its key lines: the warning is the plain one, no doubt said
    box.box.set_tr(1, False)
    await load(box)
    box.box.set_tr(2, True)
    text = (await probe(box.path)).text()
    assert "WARNING: station 2 transmits now." in text
    assert "CANNOT KNOW" not in text


@pytest.mark.asyncio
async def test_a_port_a_running_link_holds_is_refused_saying_so(box: Box) -> None:
    link = SwitchLink(1, box.path, options=LinkOptions(timing=FAST))
    link.apply(LOADED)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        before = len(box.received)
        with pytest.raises(ProbeRefused, match="in use by another program"):
            await probe(box.path)
        await asyncio.sleep(0.1)
        assert b'"I;' not in bytes(box.received[before:])  # the probe wrote nothing
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_silent_port_gets_a_report_that_says_what_to_check() -> None:
    master, slave = pty.openpty()
    tty.setraw(slave)
    try:
        report = await probe(os.ttyname(slave), answer_timeout=0.05)  # nothing will answer
        assert not report.answered
        assert "No answer to any question." in report.text()
        assert "FTDI" in report.text()
        sent = [data for way, data in report.exchange if way == "->"]
        assert b"".join(sent) == b"".join(q * 2 for q in
                                          (b"';", b":;", b'"B;', b'"I;', b"|;"))
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.asyncio
async def test_the_probe_sends_nothing_that_is_not_a_question(box: Box) -> None:
    with pytest.raises(TypeError, match="not a question"):
        await probe(box.path, questions=(*PROBE_QUESTIONS, SetState((StateOp.RESET,))))
    assert bytes(box.received) == b""


@pytest.mark.asyncio
async def test_the_command_line_prints_the_report_and_records_the_exchange(
        box: Box, tmp_path: Path) -> None:
    recording = tmp_path / "probe.jsonl"
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--probe", box.path,
        "--record-serial", str(recording), "--switch-dtr", "off",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    out, err = await process.communicate()
    assert process.returncode == 0, err.decode()
    assert "the box is inactive" in out.decode()
    lines = read_recording(recording)
    sent = b"".join(text_bytes(line["data"]) for line in lines if line["kind"] == "out")
    heard = b"".join(text_bytes(line["data"]) for line in lines if line["kind"] == "in")
    assert sent == QUESTION_BYTES == bytes(box.received)
    assert heard.startswith(b".;:1000;")


@pytest.mark.asyncio
async def test_the_command_line_says_why_a_missing_port_cannot_be_probed(tmp_path: Path) -> None:
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--probe", str(tmp_path / "none"),
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    out, err = await process.communicate()
    assert process.returncode == 1
    assert f"cannot open {tmp_path / 'none'}" in err.decode()
    assert out == b""
