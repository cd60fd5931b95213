"""ServerApp.act, the one door into the engine, and the listeners the app starts itself."""

from __future__ import annotations

import asyncio
import json
import shutil
import socket
from collections.abc import AsyncIterator, Callable
from pathlib import Path

import pytest
import pytest_asyncio

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine import NotFound, NotRunning
from moas_gui.engine.operations import (
    Select,
    SelectDirection,
    SetFrequency,
    SetTransmitting,
    StartSwitches,
    StopSwitches,
)
from moas_gui.hw.moas2.link import LinkTiming

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


async def until(condition: Callable[[], bool], timeout: float = 5.0) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while not condition():
        if loop.time() > end:
            raise AssertionError("condition not met in time")
        await asyncio.sleep(0.02)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     switch_timing=FAST))
    yield server
    await server.close()


@pytest.fixture
def station(tmp_path: Path) -> Path:
    path = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", path)
    return path


@pytest.mark.asyncio
async def test_act_without_a_configuration_is_refused_as_not_running(app: ServerApp) -> None:
    with pytest.raises(NotRunning, match="No configuration is open"):
        app.act(SetFrequency(1, 1, 14025.0))


@pytest.mark.asyncio
async def test_act_applies_an_operation_and_sends_it_to_the_switch(
        app: ServerApp, station: Path) -> None:
    await app.open(station)
    assert app.engine is not None
    app.act(SetFrequency(1, 1, 14025.0))
    chosen = app.engine.radio_view(1, 1).tx
    assert chosen is not None and app.engine.radio_view(1, 1).khz == 14025.0
    link = app._run.links[1]  # type: ignore[union-attr]
    await until(lambda: link.sent == app.engine.switch_states()[1])  # type: ignore[union-attr]
    app.act(SetTransmitting(1, 1, True))
    assert app.engine.radio_view(1, 1).transmitting
    app.act(SetTransmitting(1, 1, False))
    app.act(StopSwitches())
    assert not app.engine.running
    app.act(StartSwitches())
    assert app.engine.running


@pytest.mark.asyncio
async def test_a_refused_operation_raises_the_engine_error_and_changes_nothing(
        app: ServerApp, station: Path) -> None:
    await app.open(station)
    assert app.engine is not None
    app.act(SetFrequency(1, 1, 14025.0))
    before = app.engine.radios(), app.engine.switch_states()
    with pytest.raises(NotFound, match="antenna 99|Antenna 99|no antenna"):
        app.act(Select(1, 1, 99))
    with pytest.raises(NotFound, match="rotator 42"):
        app.act(SelectDirection(42, 90.0))
    assert (app.engine.radios(), app.engine.switch_states()) == before


@pytest.mark.asyncio
async def test_the_app_starts_and_closes_the_rotctld_listeners(
        app: ServerApp, station: Path) -> None:
    data = json.loads(station.read_text())
    port = free_port()
    data["Rotators"][0]["RotctldPort"] = port
    station.write_text(json.dumps(data))
    await app.open(station)
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        writer.write(b"+p\n")
        async with asyncio.timeout(2.0):
            lines = [(await reader.readline()).decode() for _ in range(4)]
    finally:
        writer.close()
        await writer.wait_closed()
    assert lines[0] == "get_pos:\n" and lines[-1] == "RPRT 0\n"
    await app.close()
    with pytest.raises(OSError):
        await asyncio.open_connection("127.0.0.1", port)
