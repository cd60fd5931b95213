"""The server runs its sources from the configuration: Win-Test, DXLog.net and N1MM's
rotor window over real UDP on 127.0.0.1, into the engine and the rotator manager."""

from __future__ import annotations

import asyncio
import json
import socket
from collections.abc import AsyncIterator, Callable
from pathlib import Path

import pytest
import pytest_asyncio

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.base import ActiveRadio
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.sources.n1mm_rotor_packet import stop_command, turn_command
from moas_gui.sources.wintest_frame import status_frame
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


async def until(condition: Callable[[], bool], timeout: float = 5.0) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while not condition():
        if loop.time() > end:
            raise AssertionError("condition not met in time")
        await asyncio.sleep(0.02)


@pytest_asyncio.fixture
async def n1mm_pc() -> AsyncIterator[socket.socket]:
    """Plays the N1MM computer: sends commands, and hears headings on its port."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.setblocking(False)
    yield sock
    sock.close()


@pytest_asyncio.fixture
async def app(tmp_path: Path, n1mm_pc: socket.socket) -> AsyncIterator[ServerApp]:
    data = json.loads((EXAMPLES / "small-station.moas").read_text(encoding="utf-8"))
    data.update({
        "UseN1MMLogger": False,
        "UseWinTest": True, "WinTest": [{"StationName": "RUN", "Station": 1, "Radio": 2}],
        "UseDXLog": True, "N1MMLogger": [{"StationName": "OP-PC", "Station": 1}],
        "UseN1MMRotor": True,
        "N1MMRotorHeadings": [f"127.0.0.1:{n1mm_pc.getsockname()[1]}"],
    })
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(data), encoding="utf-8")
    server = ServerApp(ServerOptions(
        bind="127.0.0.1", tcp_port=0, udp_bind="127.0.0.1", dxlog_port=0, wintest_port=0,
        n1mm_rotor_port=0, start_rotator_program=False, switch_timing=FAST))
    assert (await server.open(path)).ok
    await until(lambda: server.status.state is ServerState.NORMAL)
    yield server
    await server.close()


@pytest.mark.asyncio
async def test_win_test_status_sets_the_configured_radio(app: ServerApp) -> None:
    assert app.sources.n1mm is None, "UseN1MMLogger is off"
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(b"garbage", ("127.0.0.1", app.sources.wintest.port))
        udp.sendto(status_frame("RUN", 7025.0), ("127.0.0.1", app.sources.wintest.port))
    await until(lambda: app.engine.radio_view(1, 2).khz == 7025.0)
    assert app.engine.radio_view(1, 1).khz is None


@pytest.mark.asyncio
async def test_dxlog_by_station_name_sets_the_radio_and_its_transmit_focus(app: ServerApp) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(radio_info_packet(1, 14025.0, station_name="OP-PC", app="DXLog",
                                     active_radio_nr=2),
                   ("127.0.0.1", app.sources.dxlog.port))
    await until(lambda: app.engine.radio_view(1, 1).khz == 14025.0)
    focus = app.latest_reports()
    assert isinstance(focus[("ActiveRadio", 1)], ActiveRadio)
    assert focus[("ActiveRadio", 1)].radio == 2


@pytest.mark.asyncio
async def test_n1mm_rotor_window_turns_the_rotator_and_sees_its_heading(
    app: ServerApp, n1mm_pc: socket.socket,
) -> None:
    loop = asyncio.get_running_loop()
    port = app.sources.rotor.port
    n1mm_pc.sendto(turn_command("Tribander", 90.0), ("127.0.0.1", port))
    await until(lambda: app.rotator_manager.view(1).target == 90, timeout=5)
    n1mm_pc.sendto(stop_command("tribander rotator"), ("127.0.0.1", port))
    await until(lambda: app.rotator_manager.view(1).target is None
                or not app.rotator_manager.view(1).moving, timeout=5)
    heading = app.rotator_manager.view(1).heading
    assert heading is not None
    seen: list[bytes] = []
    async with asyncio.timeout(5):
        while f"Tribander @ {heading * 10}".encode() not in seen:
            seen.append(await loop.sock_recv(n1mm_pc, 512))
            heading = app.rotator_manager.view(1).heading
    assert all(line.startswith(b"Tribander @ ") for line in seen)


@pytest.mark.asyncio
async def test_bad_input_on_every_port_changes_no_switch(app: ServerApp) -> None:
    before = app.emulators()[1].view().relays
    bad = [b"", b"\xff" * 100, b"X" * 60000,
           b'<!DOCTYPE r [<!ENTITY a "aaaa">]><RadioInfo><Freq>&a;</Freq></RadioInfo>',
           radio_info_packet(1, 14025.0, station_name="OP-PC").replace(
               b"<Freq>1402500<", b"<Freq>999999999999<"),
           status_frame("RUN", 3_000_000_000.0), b'STATUS: "RUN"',
           b"<N1MMRotor><rotor>Tribander</rotor><goazi>1e99</goazi></N1MMRotor>"]
    sources = app.sources
    listeners = [sources.dxlog, sources.wintest, sources.rotor]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for listener in listeners:
            for packet in bad:
                udp.sendto(packet, ("127.0.0.1", listener.port))
    await until(lambda: sources.dxlog.stats().received == len(bad)
                and sources.wintest.received == len(bad) and sources.rotor.received == len(bad))
    await asyncio.sleep(0.1)  # anything the engine would do, it would have done by now
    assert app.emulators()[1].view().relays == before
    assert app.engine.radio_view(1, 1).khz is None and app.engine.radio_view(1, 2).khz is None
    assert app.rotator_manager.view(1).target is None
    assert sources.dxlog.stats().malformed == len(bad) - 1  # <N1MMRotor> is just not RadioInfo
    assert sources.wintest.bad.total == len(bad)
    assert sources.rotor.bad.total + sources.rotor.ignored == len(bad)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(status_frame("RUN", 7025.0), ("127.0.0.1", sources.wintest.port))
    await until(lambda: app.engine.radio_view(1, 2).khz == 7025.0)


@pytest.mark.asyncio
async def test_a_port_in_use_leaves_that_source_out_and_the_others_running(
    tmp_path: Path, caplog: pytest.LogCaptureFixture,
) -> None:
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind(("127.0.0.1", 0))
    data = json.loads((EXAMPLES / "small-station.moas").read_text(encoding="utf-8"))
    data.update({"UseN1MMLogger": False, "UseWinTest": True,
                 "WinTest": [{"StationName": "RUN", "Station": 1}], "UseDXLog": True})
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(data), encoding="utf-8")
    server = ServerApp(ServerOptions(
        bind="127.0.0.1", tcp_port=0, udp_bind="127.0.0.1", wintest_port=0,
        dxlog_port=holder.getsockname()[1], start_rotator_program=False, switch_timing=FAST))
    try:
        assert (await server.open(path)).ok
        assert server.sources.dxlog is None and server.sources.wintest.port
        assert any("DXLog.net packets cannot be received" in r.getMessage()
                   for r in caplog.records)
    finally:
        holder.close()
        await server.close()
