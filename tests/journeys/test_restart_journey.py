"""``kill -9`` of the server mid-contest and a restart: nothing changes on the air.

Real processes: ``moas-emulator --headless --link PATH`` holds the switch on a
pseudo-terminal (it outlives the server, as a real box does, and logs every
change of its relays); ``moas-server --headless --new-instance`` with its own
XDG directories; N1MM Logger packets over UDP and a client over TCP.
"""

from __future__ import annotations

import asyncio
import json
import os
import signal
import socket
import sys
from collections.abc import AsyncIterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import free_port, until

from moas_gui.config import load_config
from moas_gui.engine import Engine, EngineError
from moas_gui.engine.snapshot import restore_selections
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.state_store import SAVE_DELAY_HOOK, decode, fingerprint, state_path

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@dataclass
class Process:
    """A child process whose stderr is collected line by line."""

    process: asyncio.subprocess.Process
    lines: list[str] = field(default_factory=list)
    reader: asyncio.Task[None] | None = None

    @classmethod
    async def start(cls, *args: str, env: dict[str, str]) -> Process:
        process = await asyncio.create_subprocess_exec(
            sys.executable, *args, stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE, env=env)
        self = cls(process)

        async def collect() -> None:
            assert process.stderr is not None
            async for line in process.stderr:
                self.lines.append(line.decode(errors="replace").rstrip("\n"))

        self.reader = asyncio.get_running_loop().create_task(collect())
        return self

    def text(self) -> str:
        return "\n".join(self.lines)

    async def end(self, sig: int = signal.SIGKILL) -> int:
        if self.process.returncode is None:
            self.process.send_signal(sig)
        code = await asyncio.wait_for(self.process.wait(), 15)
        if self.reader is not None:
            await asyncio.wait_for(self.reader, 5)
        return code


class Client:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.next_id = 1
        self.events: list[dict] = []

    @classmethod
    async def connect(cls, port: int, server: Process) -> Client:
        for _ in range(200):
            try:
                reader, writer = await asyncio.open_connection("127.0.0.1", port)
                return cls(reader, writer)
            except OSError:
                await asyncio.sleep(0.05)
        raise AssertionError("the server never listened:\n" + server.text())

    async def message(self, timeout: float = 10.0) -> dict:
        line = await asyncio.wait_for(self.reader.readline(), timeout)
        assert line, "the server closed the connection"
        return json.loads(line)  # type: ignore[no-any-return]

    async def ask(self, cmd: str, **arguments: object) -> dict:
        ident = self.next_id
        self.next_id += 1
        self.writer.write(json.dumps({"id": ident, "cmd": cmd, **arguments}).encode() + b"\n")
        while True:
            message = await self.message()
            if message.get("id") == ident:
                return message
            self.events.append(message)

    async def event(self, name: str, timeout: float = 10.0) -> dict:
        for i, message in enumerate(self.events):
            if message.get("event") == name:
                return self.events.pop(i)
        while True:
            message = await self.message(timeout)
            if message.get("event") == name:
                return message
            self.events.append(message)

    async def switch_ok(self, snapshot: dict, timeout: float = 20.0) -> None:
        """Wait until switch 1 is ``ok`` (the snapshot may say so already)."""
        if snapshot["switches"] == [{"id": 1, "status": "ok"}]:
            return
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        while True:
            message = await self.event("switch", timeout=max(0.1, end - loop.time()))
            if message["status"] == "ok":
                return

    def close(self) -> None:
        self.writer.close()


@dataclass
class Station:
    config: Path
    env: dict[str, str]
    emulator: Process
    tcp: int
    udp: int

    def server_args(self) -> list[str]:
        return ["-m", "moas_gui.cli.server", "--headless", str(self.config), "--bind",
                "127.0.0.1", "--tcp-port", str(self.tcp), "--udp-port", str(self.udp),
                "--no-rotator-program", "--new-instance", "--log-level", "info"]

    async def server(self) -> Process:
        return await Process.start(*self.server_args(), env=self.env)

    def relay_lines(self, start: int = 0) -> list[str]:
        """The emulator's log of its relays since line ``start``."""
        return [line for line in self.emulator.lines[start:] if " relays " in f" {line}"]


@pytest_asyncio.fixture
async def station(tmp_path: Path) -> AsyncIterator[Station]:
    runtime = tmp_path / "run"
    runtime.mkdir(mode=0o700)
    # the servers write their state at most every 0.1 s (the test hook; the real second
    # only made the first journey wait for its save, and gave the heavy traffic's kills
    # fewer writes to land in)
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_RUNTIME_DIR=str(runtime),
               XDG_CONFIG_HOME=str(tmp_path / "config"), XDG_STATE_HOME=str(tmp_path / "state"),
               **{SAVE_DELAY_HOOK: "0.1"})
    link = tmp_path / "moas1"
    emulator = await Process.start("-m", "moas_gui.cli.emulator", "--headless", "--link",
                                   str(link), "--log-level", "info", env=env)
    await until(lambda: link.is_symlink(), what="the emulator's link")
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(link)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    config = tmp_path / "station.moas"
    config.write_text(json.dumps(data, indent=2))
    yield Station(config, env, emulator, free_port(socket.SOCK_STREAM),
                  free_port(socket.SOCK_DGRAM))
    await emulator.end(signal.SIGTERM)


def state_directory(station: Station) -> Path:
    return Path(station.env["XDG_STATE_HOME"]) / "moas-gui"


def _other_antenna(config_path: Path) -> int:
    """An antenna radio 2 can take at 7020 kHz that is not the one selection picks."""
    config = load_config(config_path).unwrap()
    engine = Engine(config)
    engine.set_frequency(1, 1, 14025.0)
    engine.set_frequency(1, 2, 7020.0)
    picked = engine.radio_view(1, 2).tx
    for antenna in sorted(a.id for a in config.antennas):
        if antenna == picked:
            continue
        trial = Engine(config)
        trial.set_frequency(1, 1, 14025.0)
        trial.set_frequency(1, 2, 7020.0)
        try:
            trial.select(1, 2, antenna, "both", exclusive=True)
        except EngineError:
            continue  # not this one
        if trial.radio_view(1, 2).tx == antenna:
            return antenna
    raise AssertionError("the example has no second antenna for radio 2 at 7020 kHz")


def _radios(snapshot: dict) -> dict[tuple[int, int], tuple[object, ...]]:
    return {(r["station"], r["radio"]): (r["khz"], r["tx"], r["rx"]) for r in snapshot["radios"]}


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_kill_9_and_restart_change_nothing_on_the_air(station: Station) -> None:
    other = _other_antenna(station.config)
    server = await station.server()
    try:
        client = await Client.connect(station.tcp, server)
        await client.ask("hello", client="test")
        await client.switch_ok(await client.event("state"))

        # The logger tunes radio 1; the operator tunes radio 2 and picks another antenna.
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(radio_info_packet(1, 14025.0), ("127.0.0.1", station.udp))
        await client.event("radio")
        assert (await client.ask("frequency", station=1, radio=2, khz=7020.0))["ok"]
        chosen = await client.ask("select", station=1, radio=2, antenna=other, exclusive=True)
        assert chosen["ok"] and chosen["result"]["tx"] == other, chosen
        before = _radios((await client.ask("state"))["result"])
        assert before[(1, 1)][1] is not None and before[(1, 2)][1] == other

        # Whatever the box now holds is saved soon after, whole.
        saved_at = state_directory(station) / state_path(station.config).name
        print_ = fingerprint(station.config.read_bytes())

        def saved_has_it() -> bool:
            try:
                saved = decode(saved_at.read_bytes(), print_)
            except (OSError, ValueError):
                return False
            radios = {tuple(r["radio"]): r["tx"] for r in saved.engine["radios"]}
            return radios.get((1, 2)) == other and radios.get((1, 1)) is not None \
                and 1 in saved.switches
        await until(saved_has_it, what="the saved state")
        held = station.relay_lines()[-1]
        assert "(active)" in held and "none" not in held, held
        client.close()

        # kill -9 mid-contest, and start again
        await server.end(signal.SIGKILL)
        mark = len(station.emulator.lines)
        server = await station.server()
        client = await Client.connect(station.tcp, server)
        await client.ask("hello", client="test")
        snapshot = await client.event("state")
        assert _radios(snapshot) == before, "clients see the same selections after the restart"
        await client.switch_ok(snapshot)
        # The box never went to all-open: not one relay changed across the restart.
        await asyncio.sleep(0.3)
        assert station.relay_lines(mark) == [], station.relay_lines(mark)
        assert "still holds the saved state" in server.text(), server.text()
        assert (await client.ask("state"))["result"]["switches"] == [{"id": 1, "status": "ok"}]

        # ... and the server still drives it: the logger moves radio 1 to 80 m.
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(radio_info_packet(1, 3510.0), ("127.0.0.1", station.udp))
        await until(lambda: len(station.relay_lines(mark)) > 0, what="a relay change")
        assert all("(active)" in line for line in station.relay_lines(mark))
        client.close()
    finally:
        await server.end(signal.SIGTERM)


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_kill_9_during_heavy_traffic_never_leaves_a_partial_state_file(
        station: Station) -> None:
    config = load_config(station.config).unwrap()
    print_ = fingerprint(station.config.read_bytes())
    saved_at = state_directory(station) / state_path(station.config).name
    bands = (1830.0, 3510.0, 7020.0, 14025.0, 21030.0, 28040.0)
    loaded = []
    for round_ in range(6):
        server = await station.server()
        try:
            client = await Client.connect(station.tcp, server)
            await client.ask("hello", client="test")
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
                loop = asyncio.get_running_loop()
                end = loop.time() + 0.25 + 0.08 * round_  # killed at six different points
                before = saved_at.stat().st_mtime_ns if saved_at.exists() else None
                n = 0

                def saved_in_this_round(before: int | None = before) -> bool:
                    if not saved_at.exists() or saved_at.stat().st_mtime_ns == before:
                        return False
                    engine = Engine(config)
                    restore_selections(engine, decode(saved_at.read_bytes(), print_).engine)
                    return engine.radio_view(1, 1).khz is not None

                # traffic until the time is up and this server has saved once (a slow
                # start on a busy machine must not leave a round with nothing written)
                while loop.time() < end or not saved_in_this_round():
                    assert loop.time() < end + 20, "no state written in 20 s of traffic"
                    for _ in range(20):
                        n += 1
                        sender.sendto(radio_info_packet(1, bands[n % 6] + n % 7),
                                      ("127.0.0.1", station.udp))
                    client.writer.write(json.dumps(
                        {"cmd": "frequency", "station": 1, "radio": 2,
                         "khz": bands[(n + 3) % 6]}).encode() + b"\n")
                    await asyncio.sleep(0.002)
                # killed in the middle of it all
                await server.end(signal.SIGKILL)
            client.close()
        finally:
            await server.end(signal.SIGKILL)
        saved = decode(saved_at.read_bytes(), print_)  # whole, or this raises
        engine = Engine(config)
        restore_selections(engine, saved.engine)
        loaded.append(engine.radio_view(1, 1).khz)
        leftovers = [p.name for p in saved_at.parent.iterdir()
                     if p != saved_at and not p.name.endswith(".last-good.moas")]
        assert len(leftovers) <= 1 and all(p.endswith(".tmp") for p in leftovers), leftovers
    assert all(khz is not None for khz in loaded)
