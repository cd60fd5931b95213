"""``kill -9`` of the server in the middle of band changes, and a restart, against the
real process with a scripted switch: nothing moves on the air, the clients see what
they saw, the log says in one line that the box still held the saved state, and every
file the server had written is whole.  (The same over six kills under heavy traffic is
``tests/journeys/test_restart_journey.py``.)"""

from __future__ import annotations

import asyncio
import json
import signal
from pathlib import Path

from fault_harness import (
    FAULT_MARKS,
    QUICK_SAVES,
    Client,
    ScriptedSwitch,
    Station,
    holds_what_the_engine_says,
)
from helpers import EXAMPLES

from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.state_store import decode, fingerprint

pytestmark = FAULT_MARKS


def radios(snapshot: dict) -> list[tuple[object, ...]]:
    return [(r["station"], r["radio"], r["khz"], r["tx"], r["rx"]) for r in snapshot["radios"]]


async def test_kill_9_mid_band_changes_and_restart(tmp_path: Path) -> None:
    switch = ScriptedSwitch(tmp_path / "moas1").plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(switch.link)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    station = Station.make(tmp_path, data, save_delay=QUICK_SAVES)
    server = await station.server("--no-rotator-program")
    try:
        client = await Client.connect(station.tcp, server)
        for khz in (14025.0, 7020.0, 3510.0, 21030.0):
            station.logger(radio_info_packet(1, khz))
            await holds_what_the_engine_says(station, client, lambda: switch.relays)
        before = radios(await client.state())
        held = switch.relays
        assert switch.box is not None
        moved: list[frozenset[int]] = []
        switch.box.add_listener(lambda kind, data: moved.append(switch.relays))

        # kill -9 while the logger keeps sending the same frequency
        station.logger(radio_info_packet(1, 21030.0))
        await server.end(signal.SIGKILL)
        await client.close()
        for path in Path(station.env["XDG_STATE_HOME"]).rglob("*"):
            if path.is_file() and not path.name.endswith((".tmp", ".last-good.moas")):
                decode(path.read_bytes(), fingerprint(station.config.read_bytes()))  # whole

        server = await station.server("--no-rotator-program")
        client = await Client.connect(station.tcp, server)
        while (await client.state())["switches"] != [{"id": 1, "status": "ok"}]:
            await asyncio.sleep(0.02)
        assert radios(await client.state()) == before, "the clients see what they saw"
        await asyncio.sleep(0.3)
        assert set(moved) <= {held}, (
            f"relays moved across the restart on {switch.endpoint and switch.endpoint.path}:"
            f" {sorted(set(moved), key=len)}\n{server.text()}")
        assert server.problems() == [], server.text()
        assert sum("still holds the saved state" in line for line in server.lines) == 1
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        # ... and it drives the box again
        station.logger(radio_info_packet(1, 7020.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        assert switch.relays != held
        await client.close()
    finally:
        await server.end()
        switch.unplug()
