"""``moas-server --headless`` end to end, as a station runs it: a separate process, a
switch emulated on a real pseudo-terminal, N1MM Logger packets over UDP, a client over TCP,
and the switch's USB cable pulled and plugged back in."""

from __future__ import annotations

import asyncio
import itertools
import json
import os
import signal
import socket
import sys
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import free_port, until
from switch_support import Cable

from moas_gui.config import load_config
from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


class Client:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                 server_log: list[str] | None = None) -> None:
        self.reader, self.writer = reader, writer
        self.switch_status: dict[int, str] = {}
        self.server_log = server_log if server_log is not None else []

    async def event(self, name: str, timeout: float = 10.0) -> dict:
        while True:
            line = await asyncio.wait_for(self.reader.readline(), timeout)
            assert line, (f"the server closed the connection while {name!r} was awaited:\n"
                          + "".join(self.server_log))
            message = json.loads(line)
            assert "error" not in message, (message, "".join(self.server_log))
            if message.get("event") == "switch":
                self.switch_status[message["id"]] = message["status"]
            if message.get("event") == "state":
                for entry in message["switches"]:
                    self.switch_status[entry["id"]] = entry["status"]
            if message.get("event") == name:
                return message  # type: ignore[no-any-return]

    async def switch_becomes(self, status: str, timeout: float = 15.0) -> None:
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        while self.switch_status.get(1) != status:
            await self.event("switch", timeout=max(0.1, end - loop.time()))


@pytest_asyncio.fixture
async def station(tmp_path: Path) -> AsyncIterator[tuple[Cable, Path]]:
    cable = Cable(tmp_path / "moas1")
    cable.plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(cable.link)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    config = tmp_path / "station.moas"
    config.write_text(json.dumps(data, indent=2))
    yield cable, config
    if cable.endpoint is not None:
        cable.endpoint.close()


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_headless_server_follows_the_logger_survives_a_pulled_cable_and_stops_cleanly(
        station: tuple[Cable, Path]) -> None:
    cable, config_path = station
    tcp, udp = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_DGRAM)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config_path),
        "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", str(udp),
        "--no-rotator-program", "--new-instance", "--log-level", "info",
        stderr=asyncio.subprocess.PIPE, env=env)
    stderr_lines: list[str] = []

    async def collect() -> None:
        assert process.stderr is not None
        async for line in process.stderr:
            stderr_lines.append(line.decode(errors="replace"))

    collector = asyncio.create_task(collect())
    writer: asyncio.StreamWriter | None = None
    try:
        for _ in range(100):
            try:
                reader, writer = await asyncio.open_connection("127.0.0.1", tcp)
                break
            except OSError:
                await asyncio.sleep(0.1)
        else:
            raise AssertionError("the server never listened:\n" + "".join(stderr_lines))
        client = Client(reader, writer, stderr_lines)
        writer.write(b'{"id": 1, "cmd": "hello", "client": "test"}\n')
        await client.event("state")
        await client.switch_becomes("ok")

        # The logger tunes radio 1 to 20 m: the switch closes that antenna's relays.
        config = load_config(config_path).unwrap()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(radio_info_packet(1, 14025.0), ("127.0.0.1", udp))
        radio = await client.event("radio")
        while radio["khz"] is None:  # the logger's transmit focus may be told first
            radio = await client.event("radio")
        antenna = config.antenna(radio["tx"])
        assert antenna is not None and radio["khz"] == 14025.0
        wanted = next(e.relays for c in antenna.control if c.range.contains(14025.0)
                      for e in c.stations if e.applies_to(1, 1))
        await until(lambda: cable.box is not None and cable.box.view().relays == wanted)

        # The USB cable is pulled: clients hear the switch is unresponsive.
        cable.unplug()
        await client.switch_becomes("unresponsive")
        assert any("switch 1" in line.lower() and "not" in line for line in stderr_lines)

        # Plugged back in (a switch that lost power: power-on state): the server
        # initialises it again and restores the antennas in use.
        new_box = cable.plug()
        assert new_box.view().relays == frozenset()
        await client.switch_becomes("ok", timeout=30)
        await until(lambda: new_box.view().relays == wanted and new_box.view().active)

        writer.close()
        process.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(process.wait(), 15) == 0
        assert new_box.view().relays == wanted, "stopping the server leaves the relays alone"
        assert any("Stopping" in line for line in stderr_lines)
    finally:
        if writer is not None:
            writer.close()  # also when a check failed: no socket left for another test
        if process.returncode is None:
            process.kill()
            await process.wait()
        await collector


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_a_logger_flood_moves_the_relays_once_a_dwell_and_the_latest_band_lands(
        station: tuple[Cable, Path], tmp_path: Path) -> None:
    """The relay dwell end to end: N1MM packets as fast as a socket sends them, every one
    another band, into the real server; the box's own record shows its relays moved at
    most once a dwell, and the last packet's antenna is what it holds at the end."""
    cable, config_path = station
    tcp, udp = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_DGRAM)
    dwell = 0.25
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config_path),
        "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", str(udp),
        "--no-rotator-program", "--new-instance", "--log-level", "info",
        "--relay-dwell", str(int(dwell * 1000)),
        stderr=asyncio.subprocess.DEVNULL, env=dict(os.environ, PYTHONUNBUFFERED="1"))
    try:
        box = cable.box
        assert box is not None
        await until(lambda: box.view().active, timeout=30, what="the box loaded")
        config = load_config(config_path).unwrap()
        bands = (14025.0, 7025.0, 28025.0, 21025.0)

        def relays_for(khz: float) -> frozenset[int]:
            antenna = next(a for a in config.antennas if any(
                c.range.contains(khz) and any(e.applies_to(1, 1) for e in c.stations)
                for c in a.control))
            return next(e.relays for c in antenna.control if c.range.contains(khz)
                        for e in c.stations if e.applies_to(1, 1))

        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(radio_info_packet(1, 3525.0), ("127.0.0.1", udp))
            await until(lambda: box.view().relays == relays_for(3525.0))
            await asyncio.sleep(dwell)  # that change's dwell is over: the flood starts afresh
            first = box.record.written
            started = asyncio.get_running_loop().time()
            for i in range(402):
                sender.sendto(radio_info_packet(1, bands[i % 4]), ("127.0.0.1", udp))
                if i % 20 == 19:
                    await asyncio.sleep(0.01)
            flood = asyncio.get_running_loop().time() - started
        await until(lambda: box.view().relays == relays_for(bands[401 % 4]),
                    what="the last packet's band on the box")
        await asyncio.sleep(2 * dwell)  # nothing else lands after the latest
        assert box.view().relays == relays_for(bands[401 % 4])
        moves = [e.at for e in box.record.after(first) if e.cause.startswith("!1")]
        assert moves, "the flood moved no relay at all"
        # at most one move a dwell: never two closer together, however slow the machine
        assert all(b - a >= dwell * 0.95 for a, b in itertools.pairwise(moves)), moves
        assert len(moves) <= flood / dwell + 2, (len(moves), flood)
    finally:
        process.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(process.wait(), 15) == 0


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_a_headless_start_on_a_file_broken_since_runs_its_last_good_version(
        station: tuple[Cable, Path], tmp_path: Path) -> None:
    """A service restarted after an edit that broke the file: the server starts the last
    version that opened (kept beside the saved state), says so loudly, and the switch is
    driven; never nothing (issue 30, "Decided already")."""
    _cable, config_path = station
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"))

    async def start() -> tuple[asyncio.subprocess.Process, list[str], int]:
        tcp = free_port(socket.SOCK_STREAM)
        process = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config_path),
            "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
            "--no-rotator-program", "--new-instance", "--log-level", "info",
            stderr=asyncio.subprocess.PIPE, env=env)
        lines: list[str] = []

        async def collect() -> None:
            assert process.stderr is not None
            async for line in process.stderr:
                lines.append(line.decode(errors="replace"))
        asyncio.ensure_future(collect())
        await until(lambda: any("Serving " in line for line in lines)
                    or process.returncode is not None, timeout=30, what="the server serving")
        return process, lines, tcp

    first, _, _ = await start()
    first.send_signal(signal.SIGTERM)
    assert await asyncio.wait_for(first.wait(), 15) == 0
    data = json.loads(config_path.read_text())
    data["Antennas"][0]["ID"] = "zero"  # an edit that breaks the file, then a power cut
    config_path.write_text(json.dumps(data, indent=2))
    second, lines, tcp = await start()
    try:
        assert second.returncode is None, "".join(lines)
        text = "".join(lines)
        assert "was not opened" in text and "RUNNING THE LAST GOOD VERSION" in text
        reader, writer = await asyncio.open_connection("127.0.0.1", tcp)
        client = Client(reader, writer, lines)
        writer.write(b'{"id": 1, "cmd": "hello", "client": "test"}\n')
        await client.event("state")
        await client.switch_becomes("ok", timeout=30)
        writer.close()
    finally:
        second.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(second.wait(), 15) == 0
