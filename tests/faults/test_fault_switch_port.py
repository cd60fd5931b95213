"""Faults of the switch's port, against the real server process: the USB adapter pulled
and plugged back (the emulator process killed and started again on the same path; a
scripted switch unplugged while a station is keyed), garbage, cut-short and reordered
replies, and a switch that stops answering and comes back.

After each fault: the switch holds exactly the relays the engine's selections call for,
the client was told (``unresponsive`` then ``ok``), and the log says it in one line at
Warning or above (not none, not a flood)."""

from __future__ import annotations

import asyncio
import json
import signal
from dataclasses import replace
from pathlib import Path

import pytest
from fault_harness import (
    FAULT_MARKS,
    QUICK_SAVES,
    SWITCH_TIMING,
    Client,
    FaultyPty,
    Process,
    ScriptedSwitch,
    Station,
    changes,
    emulator_relays,
    garbage,
    holds_what_the_engine_says,
    reordered,
    truncated,
)
from helpers import EXAMPLES, until

from moas_gui.hw.moas2.emulator.serve import make_link, serve
from moas_gui.hw.moas2.timing import REAL_TIMING, LinkTiming
from moas_gui.hw.moas2.transport import SerialTransport
from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = FAULT_MARKS

SPOILED_TIMING = replace(SWITCH_TIMING, answer_timeout=REAL_TIMING.answer_timeout)
"""Quick pings, the real answer timeout: a line that spoils every reply loses most
pongs, and after the answer timeout the switch is rightly unresponsive; the spoiled-reply
tests watch what the spoiling costs before that (every band change on the air, and no
news), as with the real clocks."""


def small_station(tmp_path: Path, port: Path,
                  switch_timing: LinkTiming = SWITCH_TIMING) -> Station:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(port)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    return Station.make(tmp_path, data, switch_timing, QUICK_SAVES)


async def test_emulator_killed_mid_transmit_and_started_again(tmp_path: Path) -> None:
    link = tmp_path / "moas1"
    station = small_station(tmp_path, link)
    emulator = await station.emulator(link)
    server = await station.server("--no-rotator-program")
    try:
        client = await Client.connect(station.tcp, server)
        station.logger(radio_info_packet(1, 14025.0))
        await holds_what_the_engine_says(station, client, lambda: emulator_relays(emulator))
        mark, told = len(server.lines), len(client.told)

        # the USB adapter pulled while the server is writing a band change
        station.logger(radio_info_packet(1, 7020.0))
        await emulator.end(signal.SIGKILL)
        # its path goes with it, as a pulled adapter's device node does (the dead
        # pseudo-terminal's number is soon another test's, behind a stale link)
        link.unlink(missing_ok=True)
        await until(lambda: "unresponsive" in client.switch_news(1, told),
                    what="the client told the switch is unresponsive")
        station.logger(radio_info_packet(1, 3510.0))  # the logger moves on meanwhile

        # ... and plugged back: a new pseudo-terminal behind the same path
        emulator = await station.emulator(link)
        await until(lambda: client.switch_news(1, told)[-1:] == ["ok"], timeout=15,
                    what="the client told the switch is ok again")
        await holds_what_the_engine_says(station, client, lambda: emulator_relays(emulator))
        assert (await client.state())["radios"][0]["khz"] == 3510.0
        assert changes(client.switch_news(1, told)) == ["unresponsive", "ok"]
        problems = server.problems(mark)
        assert len(problems) == 1, server.text(mark)
        assert "switch 1" in problems[0] and str(link) in problems[0], problems
        await client.close()
    finally:
        await server.end()
        await emulator.end()


async def scripted_station(tmp_path: Path, switch_timing: LinkTiming = SWITCH_TIMING,
                           ) -> tuple[Station, ScriptedSwitch, Process]:
    switch = ScriptedSwitch(tmp_path / "moas1").plug()
    station = small_station(tmp_path, switch.link, switch_timing)
    server = await station.server("--no-rotator-program")
    return station, switch, server


async def test_cable_pulled_while_a_station_is_keyed_never_moves_a_relay(
        tmp_path: Path) -> None:
    station, switch, server = await scripted_station(tmp_path)
    try:
        client = await Client.connect(station.tcp, server)
        station.logger(radio_info_packet(1, 14025.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        assert switch.box is not None
        switch.box.set_tr(1, True)  # radio 1 transmits
        keyed = switch.relays
        seen: list[frozenset[int]] = []
        switch.box.add_listener(lambda kind, data: seen.append(switch.relays))
        mark, told = len(server.lines), len(client.told)

        # the USB cable pulled: the path goes away, the box (on its own power) keeps on
        box = switch.box
        assert switch.endpoint is not None
        switch.link.unlink()
        switch.endpoint.close()
        await until(lambda: "unresponsive" in client.switch_news(1, told),
                    what="the client told the switch is unresponsive")
        # ... and plugged back in: a new port for the same box, behind the same path
        switch.endpoint = FaultyPty()
        serve(box, switch.endpoint, asyncio.get_running_loop())
        make_link(switch.endpoint.path, switch.link)
        await until(lambda: client.switch_news(1, told)[-1:] == ["ok"], timeout=15,
                    what="the client told the switch is ok again")
        await asyncio.sleep(0.3)
        assert set(seen) <= {keyed}, f"relays moved under a transmitting station: {seen}"
        box.set_tr(1, False)
        station.logger(radio_info_packet(1, 7020.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        assert changes(client.switch_news(1, told)) == ["unresponsive", "ok"]
        problems = server.problems(mark)
        assert len(problems) == 1 and "went away" in problems[0], server.text(mark)
        await client.close()
    finally:
        await server.end()
        switch.unplug()


@pytest.mark.parametrize("spoil", ["garbage", "truncated", "reordered"])
async def test_spoiled_replies_cost_nothing_on_the_air(tmp_path: Path, spoil: str) -> None:
    station, switch, server = await scripted_station(tmp_path, SPOILED_TIMING)
    try:
        client = await Client.connect(station.tcp, server)
        while (await client.state())["switches"] != [{"id": 1, "status": "ok"}]:
            await asyncio.sleep(0.02)
        mark, told = len(server.lines), len(client.told)
        assert switch.endpoint is not None
        switch.endpoint.spoil = {"garbage": garbage, "truncated": truncated(),
                                 "reordered": reordered(lambda: switch.endpoint)}[spoil]
        for khz in (14025.0, 7020.0, 3510.0, 21030.0):
            station.logger(radio_info_packet(1, khz))
            await holds_what_the_engine_says(station, client, lambda: switch.relays)
        await asyncio.sleep(3 * SPOILED_TIMING.ping_interval)  # pings through the spoiled line
        assert client.switch_news(1, told) == [], server.text(mark)
        assert (await client.state())["switches"] == [{"id": 1, "status": "ok"}]
        assert server.problems(mark) == [], server.text(mark)
        await client.close()
    finally:
        await server.end()
        switch.unplug()


async def test_a_switch_that_stops_answering_and_comes_back(tmp_path: Path) -> None:
    station, switch, server = await scripted_station(tmp_path)
    try:
        client = await Client.connect(station.tcp, server)
        station.logger(radio_info_packet(1, 14025.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        mark, told = len(server.lines), len(client.told)
        assert switch.endpoint is not None
        switch.endpoint.silent = True
        await until(lambda: "unresponsive" in client.switch_news(1, told), timeout=8,
                    what="the client told the switch is unresponsive")
        station.logger(radio_info_packet(1, 7020.0))  # while it says nothing
        # a retry meets the silence too: it asks the unit id, gives up, and a second asks
        asked = switch.received.count(b":;")
        await until(lambda: switch.received.count(b":;") >= asked + 2, timeout=8,
                    what="two retries")
        switch.endpoint.silent = False
        await until(lambda: client.switch_news(1, told)[-1:] == ["ok"], timeout=15,
                    what="the client told the switch is ok again")
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        assert changes(client.switch_news(1, told)) == ["unresponsive", "ok"]
        problems = server.problems(mark)
        assert len(problems) == 1 and "stopped answering" in problems[0], server.text(mark)
        assert f"nothing for {SWITCH_TIMING.answer_timeout:.1f} s" in problems[0]
        assert "answers again" in server.text(mark)
        await client.close()
    finally:
        await server.end()
        switch.unplug()


async def test_a_wake_up_with_nothing_to_read_is_not_a_lost_port(tmp_path: Path) -> None:
    """Seen on a live pseudo-terminal under load: the loop says the port is readable and
    a read gives nothing, as a hung-up port does; the link took it for a pulled cable."""
    switch = ScriptedSwitch(tmp_path / "moas1").plug()
    transport = SerialTransport(str(switch.link))
    lost: list[str] = []
    transport.open(lambda data: None, lost.append)
    try:
        transport._readable()  # woken with nothing there
        assert lost == []
        switch.unplug()  # the other end hangs up
        transport._readable()
        transport._readable()
        assert lost == ["the port was closed at the other end"]
    finally:
        transport.close()
