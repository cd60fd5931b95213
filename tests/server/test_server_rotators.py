"""Rotators end to end: a client's ``rotate`` goes through the server core, the
``moas-rotator`` program the server starts itself (``StartMOASRotator``), and a
real pseudo-terminal to an emulated Yaesu controller; the headings come back to
the client as ``rotator`` events.  Also: the program dying in the middle of a
turn, as seen by the client."""

from __future__ import annotations

import asyncio
import json
import logging
import re
import sys
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import pytest_asyncio
from helpers import FakeClock, free_port, until
from test_server_protocol import EXAMPLES, FAST, Message, Peer

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.rotators.base import Timing
from moas_gui.hw.rotators.controllers.models import find_model
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort
from moas_gui.hw.rotators.moas_rotator_process import LocalMoasRotator

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

START = 30.0
"""Where the emulated controller points at power-on."""
SPEED = 150.0
"""Degrees a second the emulated controller turns (a real one: about 6): a turn of 90
degrees still gives several reports at the Poll below."""
POLL = 100
"""The rotator's Poll, in milliseconds."""
QUICK = Timing(reconnect_min=0.05, reconnect_max=0.2, restart_min=0.1)
"""The server's rotator delays: it reconnects to the program from 50 ms on and starts a
dead one again after 0.1 s (a station's: 0.5 s and 1 s)."""


@dataclass
class Station:
    app: ServerApp
    host: EmulatorHost
    port: ServedPort
    program_port: int

    def azimuth(self) -> float:
        return self.host.call(self.port, lambda emulator, _now: emulator.azimuth)


@pytest_asyncio.fixture
async def station(tmp_path: Path, request: pytest.FixtureRequest) -> AsyncIterator[Station]:
    """The small station with its tribander on a Yaesu controller at this computer's
    MOAS Rotator program, which the server starts on a free port.  The controller turns
    :data:`SPEED` degrees a second, or as many as a test's indirect parameter says."""
    speed = getattr(request, "param", SPEED)
    host = EmulatorHost().start()
    link = tmp_path / "yaesu"
    port = host.add(find_model("Yaesu").make_emulator(START, speed, host.clock()), link=str(link))
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Rotators"] = [{
        "ID": 1, "ShortName": "Tribander", "LongName": "Tribander rotator",
        "CCWLimit": 0, "Rotation": 360, "HasStop": True, "Control": "Serial",
        "Address": "127.0.0.1", "CommPort": str(link), "Model": "Yaesu", "Poll": POLL,
    }]
    data["StartMOASRotator"] = True
    config = tmp_path / "station.moas"
    config.write_text(json.dumps(data, indent=2))
    program_port = free_port()
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", rotator_program_port=program_port,
                                  switch_timing=FAST, rotator_timing=QUICK))
    try:
        assert (await app.open(config)).ok
        yield Station(app, host, port, program_port)
    finally:
        await app.close()
        host.close()


@pytest_asyncio.fixture
async def peers() -> AsyncIterator[list[Peer]]:
    made: list[Peer] = []
    yield made
    for peer in made:
        await peer.close()


async def client(station: Station, peers: list[Peer]) -> Peer:
    address = station.app.client_address
    assert address is not None
    peer = await Peer.connect(address)
    peers.append(peer)
    await peer.ok("hello", client="compass")
    await peer.event("state")
    return peer


def tribander(test: Any) -> Any:
    """Matches a ``rotator`` event for rotator 1, or a ``state`` event, passing ``test``."""
    def match(m: Message) -> bool:
        if m.get("event") == "rotator" and m["id"] == 1:
            return bool(test(m))
        if m.get("event") == "state":
            return any(r["id"] == 1 and test(r) for r in m["rotators"])
        return False
    return match


def program(station: Station) -> Any:
    local = station.app.rotator_manager.local_program
    assert local is not None, "the server did not start the MOAS Rotator program"
    return local


@pytest.mark.asyncio
@pytest.mark.timeout(60)
async def test_rotate_turns_the_serial_controller_through_the_started_program(
        station: Station, peers: list[Peer]) -> None:
    local = program(station)
    assert local.port == station.program_port
    assert local.process is not None and local.process.returncode is None
    assert local.command[-2:] == ["--port", str(station.program_port)]
    peer = await client(station, peers)
    await peer.wait_for(tribander(lambda r: r["online"] and r["heading"] == START),
                        timeout=15, what="the tribander online at its heading")

    since = peer.mark()
    assert await peer.ok("rotate", rotator=1, heading=120) == {}
    moving = await peer.event("rotator", since, where=lambda m: m["moving"])
    assert moving["target"] == 120
    arrived = await peer.event("rotator", since, timeout=15,
                               where=lambda m: m["heading"] == 120 and not m["moving"])
    assert arrived["online"] is True
    headings = [m["heading"] for m in peer.events("rotator", since)]
    assert headings == sorted(headings) and len(set(headings)) >= 3, headings
    assert station.azimuth() == pytest.approx(120, abs=1)

    since = peer.mark()
    await peer.ok("rotate", rotator=1, heading=300)
    await peer.event("rotator", since, where=lambda m: m["moving"] and m["heading"] > 130)
    assert await peer.ok("stop", rotator=1) == {}
    stopped = await peer.event("rotator", since, timeout=10, where=lambda m: not m["moving"])
    assert stopped["target"] is None and 130 < stopped["heading"] < 300
    await until(lambda: abs(station.azimuth() - stopped["heading"]) <= 2,
                what="the controller stopped where the client was told")


@pytest.mark.asyncio
@pytest.mark.timeout(60)
@pytest.mark.parametrize("station", [300.0], indirect=True)  # the program is back in 0.5 s
async def test_the_program_killed_mid_turn_shows_offline_then_comes_back_and_finishes(
        station: Station, peers: list[Peer]) -> None:
    local = program(station)
    peer = await client(station, peers)
    await peer.wait_for(tribander(lambda r: r["online"] and r["heading"] == START),
                        timeout=15, what="the tribander online at its heading")

    since = peer.mark()
    await peer.ok("rotate", rotator=1, heading=300)
    await peer.event("rotator", since, where=lambda m: m["moving"] and m["heading"] >= 60)
    killed = local.process
    assert killed is not None
    killed.kill()

    offline = await peer.event("rotator", since, where=lambda m: not m["online"])
    assert 60 <= offline["heading"] < 300, "an offline rotator keeps its last heading"
    since = peer.mark()
    back = await peer.event("rotator", since, timeout=20, where=lambda m: m["online"])
    assert local.process is not None and local.process.pid != killed.pid
    assert back["heading"] >= offline["heading"]
    await peer.event("rotator", since, timeout=15,
                     where=lambda m: m["heading"] == 300 and not m["moving"] and m["online"])
    assert station.azimuth() == pytest.approx(300, abs=1)


@pytest.mark.asyncio
async def test_a_program_that_keeps_dying_is_restarted_ever_less_often_until_stopped(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.hw.rotators.moas_rotator_process")
    local = LocalMoasRotator([sys.executable, "-c", "raise SystemExit(3)"], free_port(),
                             restart_min=0.05, restart_max=0.2)

    def waits() -> list[float]:
        found = (re.search(r"exited with code 3; starting it again in ([0-9.]+) s", r.message)
                 for r in caplog.records)
        return [float(m.group(1)) for m in found if m]

    await local.start()
    try:
        await until(lambda: len(waits()) >= 4, timeout=20, what="four restarts")
    finally:
        await local.stop()
    assert waits()[:4] == [0.05, 0.1, 0.2, 0.2]
    after_stop = len(waits())
    await asyncio.sleep(0.4)
    assert len(waits()) == after_stop and local.process is None, "stop ends the restarts"


@pytest.mark.asyncio
async def test_restarts_wait_on_the_clock_and_a_steady_run_starts_the_back_off_again(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    """On a fake clock: no restart before its wait has passed on that clock; the waits
    double (1, 2, 4 s); a program that then ran for a minute (STEADY) before dying is
    restarted after the shortest wait again."""
    caplog.set_level(logging.INFO, logger="moas_gui.hw.rotators.moas_rotator_process")
    hold = tmp_path / "hold"
    script = ("import pathlib, sys, time\n"
              f"hold = pathlib.Path({str(hold)!r})\n"
              "if hold.exists():\n"
              "    print('running', flush=True)\n"
              "while hold.exists():\n"
              "    time.sleep(0.02)\n"
              "sys.exit(3)\n")
    clock = FakeClock()
    local = LocalMoasRotator([sys.executable, "-c", script], free_port(),
                             restart_min=1.0, restart_max=8.0, clock=clock)

    def waits() -> list[float]:
        found = (re.search(r"exited with code 3; starting it again in ([0-9.]+) s", r.message)
                 for r in caplog.records)
        return [float(m.group(1)) for m in found if m]

    await local.start()
    try:
        await until(lambda: waits() == [1.0], what="the first death")
        await asyncio.sleep(0.3)
        assert waits() == [1.0], "no restart while the fake clock stands still"
        await clock.advance(1.0)
        await until(lambda: waits() == [1.0, 2.0], what="the second death")
        await clock.advance(2.0)
        await until(lambda: waits() == [1.0, 2.0, 4.0], what="the third death")
        hold.touch()
        await clock.advance(4.0)
        await until(lambda: "MOAS Rotator: running" in caplog.text, what="a steady run")
        await clock.advance(61.0)
        hold.unlink()
        await until(lambda: len(waits()) == 4, what="the steady program's death")
        assert waits() == [1.0, 2.0, 4.0, 1.0]
    finally:
        await local.stop()


@pytest.mark.asyncio
@pytest.mark.timeout(60)
async def test_a_controller_whose_port_is_gone_is_offline_refuses_turns_and_comes_back(
        station: Station, peers: list[Peer]) -> None:
    """One truth per rotator (issue 30): the MOAS Rotator program runs, but the
    controller's port is pulled: the program says so (OFFLINE), clients see the rotator
    offline, a turn is refused with the reason instead of answering ok with a target
    that never comes; when the port is back, so is the rotator."""
    peer = await client(station, peers)
    await peer.wait_for(tribander(lambda r: r["online"] and r["heading"] == START),
                        timeout=15, what="the tribander online")
    link = station.port.link
    assert link is not None
    station.host.remove(station.port)  # the USB adapter pulled
    since = peer.mark()
    await peer.event("rotator", since, timeout=15, where=lambda m: m["id"] == 1
                     and not m["online"] and not m["moving"])
    code, message = await peer.refused("rotate", rotator=1, heading=90)
    assert code == "unavailable" and "offline" in message and link in message, message
    assert not any(m["moving"] for m in peer.events("rotator", since) if m["id"] == 1)
    station.port = station.host.add(find_model("Yaesu").make_emulator(
        START, SPEED, station.host.clock()), link=link)  # plugged back
    await peer.event("rotator", since, timeout=20, where=lambda m: m["id"] == 1
                     and m["online"])
    assert await peer.ok("rotate", rotator=1, heading=90) == {}
    await peer.event("rotator", since, timeout=15,
                     where=lambda m: m["id"] == 1 and m["heading"] == 90)
