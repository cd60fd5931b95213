"""What every fault-injection test needs: real processes, a real client, switches.

* :class:`Process` runs ``moas-server --headless --new-instance``, ``moas-emulator
  --headless --link PATH``, ``moas-rotator`` or ``rotctld`` as a child and collects its
  standard error line by line (the server logs there).
* :class:`Client` is a client of the protocol on 127.0.0.1: it asks, and keeps every
  event it was told.
* :class:`ScriptedSwitch` is a MOAS II on a pseudo-terminal in the test's own process:
  the project's emulated box behind an endpoint that can turn its replies into garbage,
  cut them short, swap them or swallow them, and be unplugged (the path goes away).
* :func:`engine_relays` says which relays each switch must close according to the engine
  (from the server's saved state, once it matches what the clients were told), so a test
  can compare them with what the box holds.

The switch faults' servers run their switch links on :data:`SWITCH_TIMING`, short
clocks handed over by the test hook ``MOAS_GUI_SWITCH_TIMING`` (docs/reliability.md): a
switch that stops answering is seen in half a second, not three, and the retries come
quickly.  Everything else, and the switch links of the other faults' servers (where a
busy server must not pass for a silent switch), runs on its real clock.
"""

from __future__ import annotations

import asyncio
import functools
import json
import os
import signal
import socket
import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import pytest
from helpers import free_port, until

from moas_gui.config import read_config
from moas_gui.config.model import Config
from moas_gui.engine import Engine
from moas_gui.engine.snapshot import restore_selections
from moas_gui.engine.switchstate import SwitchState
from moas_gui.hw.moas2.commands import encode, split
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve
from moas_gui.hw.moas2.emulator.stepped import SteppedBox
from moas_gui.hw.moas2.sync import initialise
from moas_gui.hw.moas2.timing import ENVIRONMENT as SWITCH_TIMING_HOOK
from moas_gui.hw.moas2.timing import LinkTiming
from moas_gui.state_store import SAVE_DELAY_HOOK, decode, fingerprint, state_path

LEVELS = ("WARNING", "ERROR", "CRITICAL")

SWITCH_TIMING = LinkTiming(ping_interval=0.1, answer_timeout=0.5, retry_first=0.1,
                           retry_max=0.4)
"""The switch links' clocks in the fault tests' servers: pings ten times a second,
half a second of silence makes a switch unresponsive, retries after 0.1 s to 0.4 s."""

QUICK_SAVES = 0.1
"""How often the servers of the tests that wait for a change to be saved
(:func:`holds_what_the_engine_says` waits for the saved state) write their state: the
test hook ``MOAS_GUI_SAVE_DELAY`` (docs/reliability.md); the real second only made each
such wait longer."""


@dataclass
class Process:
    """A child process whose standard error is collected line by line."""

    process: asyncio.subprocess.Process
    lines: list[str] = field(default_factory=list)
    reader: asyncio.Task[None] | None = None

    @classmethod
    async def start(cls, *args: str, env: dict[str, str], python: bool = True,
                    preexec: Callable[[], None] | None = None) -> Process:
        """``preexec`` runs in the child before it starts (a resource limit, say)."""
        argv = (sys.executable, *args) if python else args
        process = await asyncio.create_subprocess_exec(
            *argv, stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE, env=env,
            preexec_fn=preexec)
        self = cls(process)

        async def collect() -> None:
            assert process.stderr is not None
            async for line in process.stderr:
                self.lines.append(line.decode(errors="replace").rstrip("\n"))

        self.reader = asyncio.get_running_loop().create_task(collect())
        return self

    def text(self, start: int = 0) -> str:
        return "\n".join(self.lines[start:])

    def problems(self, start: int = 0) -> list[str]:
        """Lines logged at Warning or above since line ``start``."""
        return [line for line in self.lines[start:] if any(w in line for w in LEVELS)]

    async def end(self, sig: int = signal.SIGTERM) -> int:
        if self.process.returncode is None:
            self.process.send_signal(sig)
        code = await asyncio.wait_for(self.process.wait(), 15)
        if self.reader is not None:
            await asyncio.wait_for(self.reader, 5)
        return code


class Client:
    """A client of the protocol: requests, and every event it was told, kept in order."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.next_id = 1
        self.told: list[dict[str, Any]] = []
        self._replies: dict[int, asyncio.Future[dict[str, Any]]] = {}
        self._task = asyncio.get_running_loop().create_task(self._read())

    @classmethod
    async def connect(cls, port: int, server: Process) -> Client:
        for _ in range(300):
            if server.process.returncode is not None:
                break
            try:
                reader, writer = await asyncio.open_connection("127.0.0.1", port)
                client = cls(reader, writer)
                await client.ask("hello", client="fault test")
                return client
            except OSError:
                await asyncio.sleep(0.05)
        raise AssertionError("the server never listened:\n" + server.text())

    async def _read(self) -> None:
        while line := await self.reader.readline():
            message = json.loads(line)
            if "event" in message:  # events carry an "id" of their own (a switch's...)
                self.told.append(message)
                continue
            future = self._replies.pop(message.get("id", -1), None)
            if future is not None and not future.done():
                future.set_result(message)

    async def ask(self, cmd: str, **arguments: object) -> dict[str, Any]:
        ident = self.next_id
        self.next_id += 1
        future: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
        self._replies[ident] = future
        self.writer.write(json.dumps({"id": ident, "cmd": cmd, **arguments}).encode() + b"\n")
        return await asyncio.wait_for(future, 10)

    async def state(self) -> dict[str, Any]:
        reply = await self.ask("state")
        assert reply["ok"], reply
        return reply["result"]  # type: ignore[no-any-return]

    def events(self, name: str, start: int = 0) -> list[dict[str, Any]]:
        return [m for m in self.told[start:] if m["event"] == name]

    def switch_news(self, switch: int, start: int = 0) -> list[str]:
        """The statuses of ``switch`` the client was told since event ``start``."""
        return [m["status"] for m in self.events("switch", start) if m["id"] == switch]

    def rotator_news(self, rotator: int, start: int = 0) -> list[bool]:
        """The ``online`` values of ``rotator`` the client was told, changes only."""
        seen: list[bool] = []
        for m in self.events("rotator", start):
            if m["id"] == rotator and (not seen or seen[-1] != m["online"]):
                seen.append(m["online"])
        return seen

    async def close(self) -> None:
        self.writer.close()
        self._task.cancel()
        await asyncio.gather(self._task, return_exceptions=True)


def changes(values: Iterable[object]) -> list[object]:
    """``values`` with repeats in a row folded: ``ok ok unresponsive ok`` -> ``ok unresponsive ok``."""
    out: list[object] = []
    for value in values:
        if not out or out[-1] != value:
            out.append(value)
    return out


class FaultyPty(PtyEndpoint):
    """A pseudo-terminal whose replies can be spoiled on the way to the computer."""

    def __init__(self) -> None:
        super().__init__()
        self.spoil: Callable[[bytes], bytes] | None = None
        self.silent = False

    def write(self, data: bytes) -> None:
        if self.silent:
            return
        if self.spoil is not None:
            data = self.spoil(data)
        if data:
            super().write(data)


def garbage(data: bytes) -> bytes:
    """Noise on the line: bytes no MOAS II message has, in the middle of a reply."""
    cut = len(data) // 2
    return data[:cut] + b"\x07\xff%&\x1b[0m" + data[cut:]


def truncated() -> Callable[[bytes], bytes]:
    """Every third reply cut short: its last byte (the ';' or more) is lost."""
    count = [0]

    def spoil(data: bytes) -> bytes:
        count[0] += 1
        return data[:-1] if count[0] % 3 == 0 else data

    return spoil


def reordered(endpoint: Callable[[], FaultyPty | None]) -> Callable[[bytes], bytes]:
    """Replies swapped in pairs: a reply is held back until the next one has gone out
    (or 50 ms have passed: a reply delayed, never lost).  ``endpoint`` gives the
    pseudo-terminal the spoiling is on (it may change: a cable plugged in again)."""
    held: list[bytes] = []

    def late() -> None:
        pty = endpoint()
        if held and pty is not None:
            pty.spoil = None
            pty.write(held.pop())
            pty.spoil = spoil

    def spoil(data: bytes) -> bytes:
        if not held:
            held.append(data)
            asyncio.get_running_loop().call_later(0.05, late)
            return b""
        return data + held.pop()

    return spoil


class CommandByCommandBox(EmulatedBox):
    """A box that takes the computer's bytes one command at a time, so its listeners see
    every state the relays pass through (a reset and a reload written together open
    every relay for a moment on a real box)."""

    def receive(self, data: bytes) -> None:
        start = 0
        for end, byte in enumerate(data, 1):
            if byte == 0x3B:  # ';' ends a command
                super().receive(data[start:end])
                start = end
        if start < len(data):
            super().receive(data[start:])


class ScriptedSwitch:
    """A MOAS II in the test's process on a pseudo-terminal behind ``link``."""

    def __init__(self, link: Path, unit_id: int = 0) -> None:
        self.link = link
        self.unit_id = unit_id
        self.box: EmulatedBox | None = None
        self.endpoint: FaultyPty | None = None
        self.received = bytearray()

    def plug(self) -> ScriptedSwitch:
        from moas_gui.hw.moas2.emulator.box import Traffic
        from moas_gui.hw.moas2.emulator.model import EmulatorModel

        self.box = CommandByCommandBox(EmulatorModel(unit_id=self.unit_id))
        self.endpoint = FaultyPty()
        serve(self.box, self.endpoint, asyncio.get_running_loop())

        def heard(kind: Traffic, data: bytes) -> None:
            if kind is Traffic.RECEIVED:
                self.received += data

        self.box.add_listener(heard)
        make_link(self.endpoint.path, self.link)
        return self

    def unplug(self) -> None:
        """The cable pulled: the port's path goes away and the pseudo-terminal closes."""
        assert self.endpoint is not None and self.box is not None
        self.link.unlink()
        self.endpoint.close()
        self.box.close()

    @property
    def relays(self) -> frozenset[int]:
        assert self.box is not None
        return self.box.view().relays

    @property
    def active(self) -> bool:
        assert self.box is not None
        return self.box.view().active


def emulator_relays(emulator: Process) -> frozenset[int] | None:
    """What ``moas-emulator --log-level info`` last said its relays are (None: not yet)."""
    for line in reversed(emulator.lines):
        if " relays " in f" {line} ":
            text = line.split("relays ", 1)[1].rsplit(" (", 1)[0]
            return frozenset() if text == "none" else frozenset(int(r) for r in text.split())
    return None


@dataclass
class Station:
    """A configuration and the places a server started on it uses."""

    config: Path
    env: dict[str, str]
    running: Process | None = None
    """The server started last."""
    tcp: int = field(default_factory=free_port)
    udp: int = field(default_factory=lambda: free_port(socket.SOCK_DGRAM))
    answers: dict[object, dict[int, frozenset[int]] | None] = field(
        default_factory=dict, repr=False)
    """What :meth:`engine_relays` found, by configuration, saved state and selections."""

    @classmethod
    def make(cls, tmp_path: Path, data: dict[str, Any],
             switch_timing: LinkTiming | None = None,
             save_delay: float | None = None) -> Station:
        """A station on ``data``; its servers' switch links run on ``switch_timing``
        (None: the real clocks) and write their state at most every ``save_delay``
        seconds (None: the real second)."""
        runtime = tmp_path / "run"
        runtime.mkdir(mode=0o700, exist_ok=True)
        env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_RUNTIME_DIR=str(runtime),
                   XDG_CONFIG_HOME=str(tmp_path / "config"),
                   XDG_DATA_HOME=str(tmp_path / "data"),
                   XDG_STATE_HOME=str(tmp_path / "state"))
        env.pop(SWITCH_TIMING_HOOK, None)
        env.pop(SAVE_DELAY_HOOK, None)
        if save_delay is not None:
            env[SAVE_DELAY_HOOK] = str(save_delay)
        if switch_timing is not None:
            env[SWITCH_TIMING_HOOK] = " ".join(
                f"{item.name}={getattr(switch_timing, item.name)}" for item in fields(LinkTiming))
        config = tmp_path / "station.moas"
        config.write_text(json.dumps(data, indent=2))
        return cls(config, env)

    async def server(self, *extra: str, preexec: Callable[[], None] | None = None) -> Process:
        self.running = await Process.start(
            "-m", "moas_gui.cli.server", "--headless", str(self.config), "--bind", "127.0.0.1",
            "--tcp-port", str(self.tcp), "--udp-port", str(self.udp), "--udp-bind", "127.0.0.1",
            "--new-instance", "--log-level", "info", *extra, env=self.env, preexec=preexec)
        return self.running

    async def emulator(self, link: Path, *extra: str) -> Process:
        emulator = await Process.start("-m", "moas_gui.cli.emulator", "--headless", "--link",
                                       str(link), "--log-level", "info", *extra, env=self.env)
        await until(lambda: link.is_symlink() and link.exists(), what=f"the emulator at {link}")
        return emulator

    def logger(self, packet: bytes) -> None:
        """One N1MM Logger packet to the server's UDP port."""
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.sendto(packet, ("127.0.0.1", self.udp))

    @property
    def state_file(self) -> Path:
        return Path(self.env["XDG_STATE_HOME"]) / "moas-gui" / state_path(self.config).name

    def engine_relays(self, snapshot: dict[str, Any]) -> dict[int, frozenset[int]] | None:
        """The relays each switch must close by the engine's decision, once the saved
        state shows the selections ``snapshot`` (the clients' view) shows; else None.
        (The tests ask this many times a second while they wait: the same saved state
        and the same selections give the same answer, worked out once.)"""
        try:
            saved = self.state_file.read_bytes()
            config = self.config.read_bytes()
        except OSError:
            return None
        shown = tuple((r["station"], r["radio"], r["tx"], r["rx"]) for r in snapshot["radios"])
        key = (config, saved, shown)
        if key not in self.answers:
            if len(self.answers) > 200:
                self.answers.clear()
            self.answers[key] = self._engine_relays(config, saved, snapshot)
        return self.answers[key]

    def _engine_relays(self, config: bytes, saved: bytes, snapshot: dict[str, Any],
                       ) -> dict[int, frozenset[int]] | None:
        try:
            stored = decode(saved, fingerprint(config))
        except ValueError:
            return None
        engine = Engine(_configuration(config, self.config))
        restore_selections(engine, stored.engine)
        for radio in snapshot["radios"]:
            view = engine.radio_view(radio["station"], radio["radio"])
            if (view.tx, view.rx) != (radio["tx"], radio["rx"]):
                return None
        return {number: reference_relays(state)
                for number, state in engine.switch_states().items()}


@functools.lru_cache(maxsize=8)
def _configuration(data: bytes, path: Path) -> Config:
    """The configuration file at ``path`` holding ``data`` (read once for each content)."""
    return read_config(data, str(path), path).unwrap()


async def holds_what_the_engine_says(station: Station, client: Client,
                                     relays: Callable[[], frozenset[int] | None],
                                     switch: int = 1, timeout: float = 15.0) -> None:
    """Wait until the box's relays (``relays()``) are the ones the engine's selections
    (as the client is told them) call for on ``switch``."""
    last: tuple[object, object] = (None, None)
    loop = asyncio.get_running_loop()
    end = loop.time() + timeout
    while True:
        wanted = station.engine_relays(await client.state())
        last = (wanted and wanted.get(switch), relays())
        if wanted is not None and last[0] == last[1]:
            return
        if loop.time() > end:
            log = station.running.text()[-4000:] if station.running else ""
            raise AssertionError(
                f"switch {switch} holds {last[1]}, the engine says {last[0]}; the server:\n{log}")
        await asyncio.sleep(0.05)


@functools.lru_cache(maxsize=256)
def reference_relays(state: SwitchState) -> frozenset[int]:
    """The relays a freshly loaded box closes for ``state`` (no station keyed; worked
    out once per state)."""
    box = SteppedBox()
    for command in initialise(state).commands:
        for part in split(command):
            box.send(encode(part).decode("latin-1"))
    box.settle()
    return frozenset(box.relays)


def kill(process: Process) -> None:
    if process.process.returncode is None:
        process.process.send_signal(signal.SIGKILL)


FAULT_MARKS = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
    pytest.mark.asyncio,
    pytest.mark.timeout(90),
]
"""Every fault test drives real processes on pseudo-terminals, on the real clock."""
