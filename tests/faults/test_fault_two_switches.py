"""A second switch failing while the first keeps working, against the real server
process: the big example station on two scripted switches; switch 2's cable is
pulled; band changes keep reaching switch 1 all the while, and
switch 2 is brought to the engine's state when it is back."""

from __future__ import annotations

import json
from pathlib import Path

from fault_harness import (
    FAULT_MARKS,
    QUICK_SAVES,
    SWITCH_TIMING,
    Client,
    ScriptedSwitch,
    Station,
    changes,
    holds_what_the_engine_says,
)
from helpers import EXAMPLES, until

from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = FAULT_MARKS


async def test_second_switch_fails_while_the_first_keeps_working(tmp_path: Path) -> None:
    one = ScriptedSwitch(tmp_path / "moas1").plug()
    two = ScriptedSwitch(tmp_path / "moas2").plug()
    data = json.loads((EXAMPLES / "big-station.moas").read_text())
    data["Switches"][0]["Port"] = str(one.link)
    data["Switches"][1]["Port"] = str(two.link)
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    data["StartMOASRotator"] = False
    station = Station.make(tmp_path, data, SWITCH_TIMING, QUICK_SAVES)
    server = await station.server("--no-rotator-program")
    try:
        client = await Client.connect(station.tcp, server)
        await until(lambda: one.active and two.active, what="both boxes loaded")
        station.logger(radio_info_packet(1, 14025.0))
        await holds_what_the_engine_says(station, client, lambda: one.relays, switch=1)
        await holds_what_the_engine_says(station, client, lambda: two.relays, switch=2)
        mark, told = len(server.lines), len(client.told)

        two.unplug()  # switch 2's cable is pulled (its silence is another test's)
        await until(lambda: "unresponsive" in client.switch_news(2, told),
                    what="the client told switch 2 is unresponsive")
        held_by_one = [one.relays]
        for khz in (7020.0, 3510.0, 21030.0, 28040.0, 14025.0, 7020.0):
            station.logger(radio_info_packet(1, khz))
            await holds_what_the_engine_says(station, client, lambda: one.relays, switch=1)
            held_by_one.append(one.relays)
        assert len(set(held_by_one)) > 2, "the band changes moved switch 1's relays"
        assert client.switch_news(1, told) == [], "switch 1 stayed ok all along"

        two.plug()  # a fresh box on the same path
        await until(lambda: client.switch_news(2, told)[-1:] == ["ok"], timeout=15,
                    what="the client told switch 2 is ok again")
        await holds_what_the_engine_says(station, client, lambda: two.relays, switch=2)
        await holds_what_the_engine_says(station, client, lambda: one.relays, switch=1)
        assert changes(client.switch_news(2, told)) == ["unresponsive", "ok"]
        problems = server.problems(mark)
        assert len(problems) == 1 and "switch 2" in problems[0], server.text(mark)
        await client.close()
    finally:
        await server.end()
        one.unplug()
        if two.link.is_symlink():
            two.unplug()
