"""The server core on one asyncio loop, in process: configuration in, relays in the
built-in emulator out, clients and the logger told."""

from __future__ import annotations

import asyncio
import json
import shutil
import socket
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.config import load_config
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def relays_for(path: Path, antenna: int, khz: float, station: int, radio: int) -> frozenset[int]:
    config = load_config(path).unwrap()
    ant = config.antenna(antenna)
    assert ant is not None
    for control in ant.control:
        if control.range.contains(khz):
            for entry in control.stations:
                if entry.applies_to(station, radio):
                    return entry.relays
    raise AssertionError("no relays")


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     switch_timing=FAST))
    yield server
    await server.close()


def relays(app: ServerApp, switch_id: int = 1) -> frozenset[int]:
    return app.emulators()[switch_id].view().relays  # type: ignore[no-any-return]


@pytest.mark.asyncio
async def test_logger_packets_put_the_radio_on_its_antenna_in_the_emulator(app: ServerApp) -> None:
    path = EXAMPLES / "small-station.moas"
    assert (await app.open(path)).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    assert relays(app) == frozenset()
    address = app.n1mm_address
    assert address is not None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(radio_info_packet(1, 14025.0), address)
    expected = relays_for(path, app.engine.radio_view(1, 1).tx or 0, 14025.0, 1, 1)
    await until(lambda: app.engine.radio_view(1, 1).tx is not None)
    await until(lambda: relays(app) == expected)
    assert app.engine.radio_view(1, 1).khz == 14025.0


@pytest.mark.asyncio
async def test_a_broken_configuration_leaves_the_running_one_untouched(
        app: ServerApp, tmp_path: Path) -> None:
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    broken = tmp_path / "broken.moas"
    broken.write_text('{"Switches": [{"ID": 1, "Port": "emulator",}]}')
    result = await app.open(broken)
    assert result.config is None and result.errors[0].line == 1
    assert app.status.file == "small-station.moas"
    assert app.status.state is ServerState.NORMAL
    assert app.client_address is not None


@pytest.mark.asyncio
async def test_stop_switches_turns_relays_off_and_start_brings_them_back(app: ServerApp) -> None:
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    app.apply_changes(app.engine.set_frequency(1, 1, 7025.0))
    await until(lambda: bool(relays(app)))
    held = relays(app)
    app.stop_switches()
    assert app.status.state is ServerState.STOPPED
    await until(lambda: not app.emulators()[1].view().active)
    assert relays(app) == frozenset()
    app.start_switches()
    await until(lambda: relays(app) == held)
    await until(lambda: app.status.state is ServerState.NORMAL)


@pytest.mark.asyncio
async def test_a_client_select_moves_the_relays_and_other_clients_hear(app: ServerApp) -> None:
    path = EXAMPLES / "small-station.moas"
    assert (await app.open(path)).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    address = app.client_address
    assert address is not None
    readers = []
    for name in ("picker", "watcher"):
        reader, writer = await asyncio.open_connection(*address)
        writer.write(json.dumps({"id": 0, "cmd": "hello", "client": name}).encode() + b"\n")
        readers.append((reader, writer))
    picker, watcher = readers
    picker[1].write(b'{"id": 1, "cmd": "frequency", "station": 1, "radio": 1, "khz": 14025}\n')
    config = load_config(path).unwrap()
    vertical = max(a.id for a in config.antennas if any(
        c.range.contains(14025) for c in a.control))
    picker[1].write(json.dumps({"id": 2, "cmd": "select", "station": 1, "radio": 1,
                                "antenna": vertical, "exclusive": True}).encode() + b"\n")

    async def reply(reader: asyncio.StreamReader, wanted: int) -> dict:
        while True:
            message = json.loads(await asyncio.wait_for(reader.readline(), 3))
            if message.get("id") == wanted:
                return message  # type: ignore[no-any-return]

    answer = await reply(picker[0], 2)
    assert answer["ok"] and answer["result"]["tx"] == vertical
    await until(lambda: relays(app) == relays_for(path, vertical, 14025.0, 1, 1))
    while True:
        event = json.loads(await asyncio.wait_for(watcher[0].readline(), 3))
        if event.get("event") == "radio" and event["tx"] == vertical:
            break
    for _, writer in readers:
        writer.close()


@pytest.mark.asyncio
async def test_opening_another_file_restarts_on_it(app: ServerApp, tmp_path: Path) -> None:
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    other = tmp_path / "other.moas"
    shutil.copy(EXAMPLES / "2x6.moas", other)
    assert (await app.open(other)).ok
    assert app.status.file == "other.moas"
    assert app.config is not None and len(app.config.antennas) == 6
    await until(lambda: app.status.state is ServerState.NORMAL)


@pytest.mark.asyncio
async def test_save_switch_data_writes_every_switch(app: ServerApp, tmp_path: Path) -> None:
    assert (await app.open(EXAMPLES / "big-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    target = await app.save_switch_data(tmp_path / "data.txt")
    text = target.read_text()
    assert "MOAS II switch 1" in text and "MOAS II switch 2" in text
    assert '"B' in text
    assert not list(tmp_path.glob(".data.txt.*"))


@pytest.mark.asyncio
async def test_closing_leaves_the_relays_as_they_are(app: ServerApp) -> None:
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    app.apply_changes(app.engine.set_frequency(1, 1, 3525.0))
    await until(lambda: bool(relays(app)))
    box = app.emulators()[1]
    held = box.view().relays
    await app.close()
    assert box.view().relays == held and box.view().active
    assert app.status.state is ServerState.NO_CONFIG


@pytest.mark.asyncio
async def test_each_file_that_opens_is_kept_and_its_last_good_version_runs_under_its_name(
        app: ServerApp, tmp_path: Path) -> None:
    from moas_gui.state_store import last_good_path

    path = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", path)
    assert (await app.open(path)).ok
    kept = last_good_path(path)
    await until(lambda: kept.is_file() and kept.read_bytes() == path.read_bytes(),
                what="the file kept as its last good version")
    good = path.read_bytes()
    path.write_text(path.read_text().replace('"ID": 0', '"ID": "zero"', 1))
    assert (await app.restart()) is not None and app.config is not None  # still running
    assert kept.read_bytes() == good  # a broken file is never kept
    await app.close()
    assert (await app.open(path)).config is None
    assert (await app.open(path, last_good=True)).ok
    assert app.status.file == "station.moas (last good version: the file has errors)"
    assert app.path == path
