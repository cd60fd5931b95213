"""Rotator peers dying and coming back, against the real server process: the MOAS
Rotator program the server started (killed with SIGKILL; the server starts it again),
Debian's own ``rotctld -m 1`` (killed, started again on the same port) and a Rotator
Genius (the project's emulator in a process of its own, killed and started again).

After each: the client was told the rotator went offline and came back online, a turn
asked afterwards reaches its heading, and the log said it in one line at Warning or
above.  The server runs with short reconnect and restart waits (its test hook,
docs/rotators.md), so that it comes back in a fraction of a second, not in 1-2 s."""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import signal
import sys
from pathlib import Path

import pytest
from fault_harness import Client, Process, Station
from helpers import EXAMPLES, free_port, until

from moas_gui.hw.rotators.base import TIMING_HOOK

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
    pytest.mark.skipif(shutil.which("rotctld") is None, reason="Hamlib's rotctld is needed"),
    pytest.mark.asyncio,
    pytest.mark.timeout(120),
]

HERE = Path(__file__).resolve().parent
SERIAL, HAMLIB, GENIUS = 11, 12, 13
QUICK = "reconnect_min=0.05,reconnect_max=0.2,restart_min=0.1"
"""The server's rotator delays: reconnects from 50 ms on, a dead program restarted after
0.1 s (a station's: 0.5 s and 1 s)."""
AWAY = 0.3
"""Seconds a peer stays dead: long enough for a reconnection or two to fail."""


def children(pid: int) -> list[int]:
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        text = (task / "children").read_text().split()
        found += [int(child) for child in text]
    return found


async def turns(client: Client, rotator: int, heading: int) -> None:
    """Ask a turn and wait until the client is told the rotator points there."""
    start = len(client.told)
    reply = await client.ask("rotate", rotator=rotator, heading=heading)
    assert reply["ok"], reply

    def arrived() -> bool:
        return any(m["id"] == rotator and m["heading"] is not None
                   and abs(m["heading"] - heading) <= 2 and not m["moving"]
                   for m in client.events("rotator", start))
    await until(arrived, timeout=15, what=f"rotator {rotator} at {heading}")


async def test_rotator_peers_die_and_come_back(tmp_path: Path) -> None:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = "emulator"
    program, hamlib, genius = free_port(), free_port(), free_port()
    controller = tmp_path / "rotor"
    data["Rotators"] += [
        {"ID": SERIAL, "ShortName": "Serial", "Control": "Serial",
         "Address": f"127.0.0.1:{program}", "CommPort": str(controller), "Model": "Yaesu",
         "Poll": 200},
        {"ID": HAMLIB, "ShortName": "Hamlib", "Control": "Hamlib",
         "Address": f"127.0.0.1:{hamlib}", "Poll": 200},
        {"ID": GENIUS, "ShortName": "Genius", "Control": "RotatorGenius",
         "Address": f"127.0.0.1:{genius}", "Port": 1, "Poll": 200},
    ]
    data["StartMOASRotator"] = True
    station = Station.make(tmp_path, data)
    env = station.env
    env[TIMING_HOOK] = QUICK

    async def start_rotctld() -> Process:
        return await Process.start("rotctld", "-m", "1", "-T", "127.0.0.1", "-t", str(hamlib),
                                   env=env, python=False)

    async def start_genius() -> Process:
        return await Process.start(str(HERE / "genius_peer.py"), str(genius), env=env)

    rotor = await Process.start("-m", "moas_gui.cli.rotator", "--emulate", "Yaesu", "--link",
                                str(controller), "--speed", "60", env=env)
    peers = [rotor, await start_rotctld(), await start_genius()]
    await until(controller.exists, what="the emulated controller")
    server = await station.server()
    try:
        client = await Client.connect(station.tcp, server)

        async def all_online() -> bool:
            views = (await client.state())["rotators"]
            return all(v["online"] for v in views)

        for _ in range(300):
            if await all_online():
                break
            await asyncio.sleep(0.05)
        assert await all_online(), server.text() + "\n".join(p.text() for p in peers)
        await turns(client, SERIAL, 8)

        # the MOAS Rotator program the server started dies
        mark, told = len(server.lines), len(client.told)
        [pid] = children(server.process.pid)
        os.kill(pid, signal.SIGKILL)
        await until(lambda: client.rotator_news(SERIAL, told)[-2:] == [False, True],
                    timeout=20, what="the Serial rotator offline, then online")
        await turns(client, SERIAL, 16)
        serial_problems = server.problems(mark)

        # rotctld dies and is started again on the same port
        mark, told = len(server.lines), len(client.told)
        await peers[1].end(signal.SIGKILL)
        await until(lambda: client.rotator_news(HAMLIB, told)[-1:] == [False],
                    what="the Hamlib rotator offline")
        await asyncio.sleep(AWAY)  # away long enough for a reconnection to fail
        peers[1] = await start_rotctld()
        await until(lambda: client.rotator_news(HAMLIB, told)[-2:] == [False, True],
                    timeout=20, what="the Hamlib rotator online again")
        await turns(client, HAMLIB, 6)
        hamlib_problems = server.problems(mark)

        # the Rotator Genius goes away and comes back
        mark, told = len(server.lines), len(client.told)
        await peers[2].end(signal.SIGKILL)
        await until(lambda: client.rotator_news(GENIUS, told)[-1:] == [False],
                    what="the Rotator Genius offline")
        await asyncio.sleep(AWAY)
        peers[2] = await start_genius()
        await until(lambda: client.rotator_news(GENIUS, told)[-2:] == [False, True],
                    timeout=20, what="the Rotator Genius online again")
        await turns(client, GENIUS, 20)
        genius_problems = server.problems(mark)
        # the program's death (and its restart), and its rotators offline: two lines
        assert len(serial_problems) == 2, serial_problems
        assert "exited with code -9; starting it again" in serial_problems[1], serial_problems
        assert "its rotators are offline" in serial_problems[0], serial_problems
        # one line each, saying the address once
        address = f"127.0.0.1:{hamlib}"
        assert len(hamlib_problems) == 1, hamlib_problems
        assert hamlib_problems[0].count(address) == 1 and "rotator 12" in hamlib_problems[0]
        address = f"127.0.0.1:{genius}"
        assert len(genius_problems) == 1, genius_problems
        assert genius_problems[0].count(address) == 1 and "Genius" in genius_problems[0]
        await client.close()
    finally:
        await server.end()
        for peer in peers:
            await peer.end(signal.SIGKILL)
