"""The model-based fault test of the safety rule across re-sync (issue 19): random
interleavings of keying, band changes and faults against real processes, and the
invariants checked on the emulated box's own record after every step.

The pieces:

* :class:`Box`: ``moas-emulator --headless --control SOCKET`` in its own process, on
  its own pseudo-terminal; the test keys and unkeys its stations through the control
  socket and follows its record (every relay change, key change and ``*0``, each with
  every station's key state) through a second connection that ``watch``\\ es it.
* :class:`Cable`: the USB cable between the server and that box: a pseudo-terminal of
  the test's own (the port the server opens, behind a link) joined byte for byte to the
  box's port.  It can be pulled out and plugged back (the server's port closes and its
  path goes away, as an adapter's does; the box, on its own power, keeps everything),
  and it can spoil what the box says (garbage, replies cut short, replies swapped, the
  box status replies lost, or nothing at all), with the spoilers of
  :mod:`fault_harness`.
* :class:`Rig`: those two, ``moas-server --headless --new-instance`` (its own XDG
  directories, the short switch clocks of :data:`fault_harness.SWITCH_TIMING`), a
  logger sending N1MM RadioInfo packets, and the faults of the server: ``kill -9`` and
  a restart, a stall (SIGSTOP, then SIGCONT after longer than every link timeout), and
  a state file that cannot be written (a directory where the server's temporary file
  goes, which stops even root).
* :func:`violations`: the invariants, on the record: no relay of a keyed station
  changes between its key and its unkey (except by the box's own interrupt mode, for
  a station the configuration puts in it), and no ``*0`` reaches the box while any
  station is keyed.  :meth:`Rig.settle` checks the third: with every fault over and
  every station unkeyed, the box holds what the engine says (so every change held
  under a key has been carried out).
* :class:`ModelRun`: the random walk over all of that, with its figures.

The configuration is ``examples/small-station.moas``: two radios of one station, on
switch stations 1 and 2, both in wait mode.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import random
import signal
import time
import tty
from collections import Counter
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fault_harness import (
    SWITCH_TIMING,
    Client,
    FaultyPty,
    Process,
    Station,
    garbage,
    holds_what_the_engine_says,
    reordered,
    truncated,
)
from helpers import EXAMPLES, until

from moas_gui.hw.moas2.emulator.record import Entry, EntryCause
from moas_gui.hw.moas2.emulator.serve import make_link
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.state_store import decode, fingerprint

STATIONS = (1, 2)
"""The switch stations the configuration drives (radio n on station n)."""

BANDS = (1830.0, 3510.0, 7020.0, 14025.0, 14200.0, 21030.0, 21200.0, 28050.0)
"""Frequencies the logger tunes the radios to (kHz)."""

STALL_S = 2 * SWITCH_TIMING.answer_timeout + SWITCH_TIMING.retry_max
"""A stall longer than every timeout of the switch links (with their short clocks)."""

NOISES = ("garbage", "truncated", "reordered", "no box status", "silence")


def small_station(tmp_path: Path, port: Path, save_delay: float | None = None) -> Station:
    """The small example on ``port``, its servers on the short switch clocks and, with
    ``save_delay``, writing their state at most that often (the test hook
    ``MOAS_GUI_SAVE_DELAY``; None: the real second, as the benchmark's walk runs)."""
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(port)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    for radio in data["Radios"]:
        assert radio["Interrupt"] is False  # the invariants allow no interrupt mode
    return Station.make(tmp_path, data, SWITCH_TIMING, save_delay)


# --------------------------------------------------------------------------- the invariants


def violations(entries: list[Entry], before: Entry | None = None) -> list[str]:
    """What in ``entries`` (consecutive entries of a box's record; ``before`` the entry
    just before them, if any) breaks the safety rule: a ``*0`` received while a station
    is keyed; a keyed station's relays changed while it stayed keyed (unless the box
    has it in interrupt mode); a gap in the record (entries lost: nothing can be said)."""
    found: list[str] = []
    previous = before
    for entry in entries:
        if entry.event is EntryCause.RESET and entry.keyed:
            who = (f"station {_numbers(entry.keyed)} was" if len(entry.keyed) == 1
                   else f"stations {_numbers(entry.keyed)} were")
            found.append(f"record #{entry.seq}: {entry.cause} reached the box while {who} "
                         f"keyed (relays {_numbers(entry.relays)})")
        if previous is not None:
            if entry.seq != previous.seq + 1:
                found.append(f"record #{previous.seq + 1}-#{entry.seq - 1} lost: cannot check")
            for number in sorted(previous.keyed & entry.keyed):
                if number in previous.interrupt_mode & entry.interrupt_mode:
                    continue  # the box's own interrupt (a reset ends interrupt mode)
                was, now = previous.station_relays(number), entry.station_relays(number)
                if was != now:
                    found.append(
                        f"record #{entry.seq} ({entry.cause}): station {number} is keyed and "
                        f"its relays moved from {_numbers(was)} to {_numbers(now)}")
        previous = entry
    return found


def _numbers(values: frozenset[int]) -> str:
    return " ".join(str(v) for v in sorted(values)) or "none"


# --------------------------------------------------------------------------- the box


async def control_connection(process: Process, control: Path, timeout: float = 30.0,
                             ) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    """A connection to the emulator's control socket, once it takes one: the socket's
    file appears when it is bound, a moment before it listens (a connection then is
    refused), so a refusal or a missing file is "not yet" until ``timeout``."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout
    while True:
        try:
            return await asyncio.open_unix_connection(str(control))
        except (ConnectionRefusedError, FileNotFoundError):
            if process.process.returncode is not None or loop.time() > deadline:
                raise AssertionError("the emulator's control socket never took a "
                                     "connection:\n" + process.text()) from None
            await asyncio.sleep(0.02)


@dataclass
class Box:
    """``moas-emulator`` in its own process, keyed and read through its control socket."""

    process: Process
    port: Path
    """The box's own port (its ``--link``)."""
    control: Path
    asking: tuple[asyncio.StreamReader, asyncio.StreamWriter]
    watching: tuple[asyncio.StreamReader, asyncio.StreamWriter]
    entries: list[Entry] = field(default_factory=list)
    reader: asyncio.Task[None] | None = None
    lock: asyncio.Lock = field(default_factory=asyncio.Lock)

    @classmethod
    async def start(cls, station: Station, where: Path) -> Box:
        port, control = where / "box", where / "box.ctl"
        process = await station.emulator(port, "--control", str(control))
        box = cls(process, port, control, await control_connection(process, control),
                  await control_connection(process, control))
        box.watching[1].write(b"watch 0\n")
        box.reader = asyncio.get_running_loop().create_task(box._follow())
        return box

    async def _follow(self) -> None:
        reader = self.watching[0]
        while line := await reader.readline():
            text = line.decode().rstrip("\n")
            if text.startswith("record "):
                self.entries.append(Entry.from_json(json.loads(text.split(" ", 1)[1])))

    async def ask(self, command: str) -> str:
        async with self.lock:
            reader, writer = self.asking
            writer.write(command.encode() + b"\n")
            lines = []
            while True:
                line = (await asyncio.wait_for(reader.readline(), 10)).decode().rstrip("\n")
                assert line, "the emulator's control closed"
                lines.append(line)
                if not line.startswith("record "):
                    return "\n".join(lines)

    async def key(self, station: int, on: bool) -> None:
        verb = "key" if on else "unkey"
        assert await self.ask(f"{verb} {station}") == f"ok {verb} {station}"

    async def status(self) -> dict[str, Any]:
        reply = await self.ask("status")
        return json.loads(reply.split(" ", 1)[1])  # type: ignore[no-any-return]

    async def caught_up(self) -> None:
        """Wait until every entry written so far has come through the watch."""
        written = int((await self.ask("record 999999999")).rsplit("end ", 1)[1])
        await until(lambda: bool(self.entries) and self.entries[-1].seq >= written or
                    written == 0, what="the record followed")

    @property
    def relays(self) -> frozenset[int]:
        return self.entries[-1].relays if self.entries else frozenset()

    def station_relays(self, station: int) -> frozenset[int]:
        return self.entries[-1].station_relays(station) if self.entries else frozenset()

    def resets(self, start: int = 0) -> list[Entry]:
        return [e for e in self.entries[start:] if e.event is EntryCause.RESET]

    async def close(self) -> None:
        for _, writer in (self.asking, self.watching):
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()
        if self.reader is not None:
            self.reader.cancel()
            await asyncio.gather(self.reader, return_exceptions=True)
        await self.process.end()


# --------------------------------------------------------------------------- the cable


def without_box_status() -> Callable[[bytes], bytes]:
    """A line that loses every box status reply (``"B...;``) and nothing else."""
    tail = bytearray()

    def spoil(data: bytes) -> bytes:
        tail.extend(data)
        out = bytearray()
        while (end := tail.find(b";")) >= 0:
            message = bytes(tail[:end + 1])
            del tail[:end + 1]
            if not message.startswith(b'"B'):
                out += message
        return bytes(out)

    return spoil


class Cable:
    """The cable from the server's port (behind ``link``) to the box's port."""

    def __init__(self, link: Path, box_port: Path) -> None:
        self.link = link
        self.box_port = box_port
        self.endpoint: FaultyPty | None = None
        self.noise = ""
        self.to_box = bytearray()
        """Everything the server sent through the cable (for a test to watch)."""
        self._fd = -1
        self._loop: asyncio.AbstractEventLoop | None = None

    def connect_box(self) -> Cable:
        self._loop = asyncio.get_running_loop()
        self._fd = os.open(os.path.realpath(self.box_port), os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self._fd)
        os.set_blocking(self._fd, False)
        self._loop.add_reader(self._fd, self._from_box)
        return self

    def plug(self) -> None:
        """Plugged in: a new port behind the same path, the noise as it was."""
        assert self.endpoint is None and self._loop is not None
        self.endpoint = FaultyPty()
        self.endpoint.start(self._loop, self._to_box)
        self.spoil(self.noise)
        make_link(self.endpoint.path, self.link)

    def unplug(self) -> None:
        """Pulled out: the path goes away and the server's port hangs up."""
        assert self.endpoint is not None
        self.link.unlink(missing_ok=True)
        self.endpoint.close()
        self.endpoint = None

    @property
    def plugged(self) -> bool:
        return self.endpoint is not None

    def spoil(self, noise: str) -> None:
        """Spoil what the box says: one of :data:`NOISES`, or "" for a clean line."""
        self.noise = noise
        if self.endpoint is None:
            return
        self.endpoint.silent = noise == "silence"
        self.endpoint.spoil = {
            "": None,
            "silence": None,
            "garbage": garbage,
            "truncated": truncated(),
            "reordered": reordered(lambda: self.endpoint),
            "no box status": without_box_status(),
        }[noise]

    def _to_box(self, data: bytes) -> None:
        self.to_box += data
        view = memoryview(data)
        while view:
            try:
                written = os.write(self._fd, view)
            except BlockingIOError:
                time.sleep(0.001)  # the box's input is a few bytes a millisecond at most
                continue
            view = view[written:]

    def _from_box(self) -> None:
        try:
            data = os.read(self._fd, 4096)
        except (BlockingIOError, OSError):
            return
        if data and self.endpoint is not None:
            self.endpoint.write(data)

    def close(self) -> None:
        if self.endpoint is not None:
            self.unplug()
        if self._fd >= 0 and self._loop is not None:
            self._loop.remove_reader(self._fd)
            os.close(self._fd)
            self._fd = -1


# --------------------------------------------------------------------------- the rig


class Rig:
    """The box, the cable, the server and the logger, and the faults of each."""

    def __init__(self, tmp_path: Path, save_delay: float | None = None) -> None:
        self.tmp_path = tmp_path
        self.station = small_station(tmp_path, tmp_path / "moas1", save_delay)
        self.box: Box | None = None
        self.cable: Cable | None = None
        self.server: Process | None = None
        self.client: Client | None = None
        self.stopped_at: float | None = None
        """When the server was stopped (SIGSTOP), if it is."""
        self.state_blocked = False
        self.khz: dict[int, float] = {}
        self.checked = 0
        """Record entries already checked."""
        self.found: list[str] = []
        """Every violation found so far."""

    @classmethod
    @contextlib.asynccontextmanager
    async def up(cls, tmp_path: Path, save_delay: float | None = None) -> AsyncIterator[Rig]:
        """The rig started: the box, the cable plugged, the server with its switch ok
        (its state saves at most every ``save_delay`` seconds: :func:`small_station`)."""
        rig = cls(tmp_path, save_delay)
        try:
            rig.box = await Box.start(rig.station, tmp_path)
            rig.cable = Cable(rig.station.config.parent / "moas1", rig.box.port).connect_box()
            rig.cable.plug()
            await rig.start_server()
            await rig.switch_ok()
            yield rig
        finally:
            await rig.close()

    # ------------------------------------------------------------------ the server

    @property
    def server_pid(self) -> int:
        assert self.server is not None
        return self.server.process.pid

    async def start_server(self) -> None:
        self.server = await self.station.server("--no-rotator-program")
        if self.state_blocked:
            self._block_state(True)

    async def restart(self) -> None:
        """``kill -9`` of the server, and a new one."""
        assert self.server is not None
        await self.server.end(signal.SIGKILL)
        self._block_state(False)
        self.stopped_at = None
        await self._drop_client()
        await self.start_server()

    def stall(self) -> None:
        os.kill(self.server_pid, signal.SIGSTOP)
        self.stopped_at = time.monotonic()

    async def resume(self) -> None:
        """SIGCONT, once the stall has lasted :data:`STALL_S`."""
        if self.stopped_at is None:
            return
        await asyncio.sleep(max(0.0, self.stopped_at + STALL_S - time.monotonic()))
        os.kill(self.server_pid, signal.SIGCONT)
        self.stopped_at = None

    def block_state(self, blocked: bool) -> None:
        """The state file cannot be written (or can again)."""
        self.state_blocked = blocked
        self._block_state(blocked)

    def _block_state(self, blocked: bool) -> None:
        # The server writes a temporary file (named as moas_gui.files.temporary_name
        # names it, after the writer's process id), then renames it over the state
        # file: a directory where that temporary file goes stops every write, even root's.
        state = self.station.state_file
        blocker = state.with_name(f".{state.name}.{self.server_pid}.tmp")
        if blocked:
            if blocker.is_file():  # a temporary file a killed writer of that number left
                blocker.unlink()
            blocker.mkdir(parents=True, exist_ok=True)
        else:
            with contextlib.suppress(OSError):
                blocker.rmdir()

    async def connect(self) -> Client:
        if self.client is None:
            assert self.server is not None
            self.client = await Client.connect(self.station.tcp, self.server)
        return self.client

    async def _drop_client(self) -> None:
        if self.client is not None:
            await self.client.close()
            self.client = None

    async def switch_ok(self, timeout: float = 20.0) -> None:
        client = await self.connect()
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        while (await client.state())["switches"] != [{"id": 1, "status": "ok"}]:
            if loop.time() > end:
                raise AssertionError(f"switch 1 never ok:\n{self.server_log()}")
            await asyncio.sleep(0.05)

    def server_log(self, lines: int = 60) -> str:
        return "\n".join(self.server.lines[-lines:]) if self.server else ""

    # ------------------------------------------------------------------ the logger

    def band(self, radio: int, khz: float) -> None:
        self.khz[radio] = khz
        self.station.logger(radio_info_packet(radio, khz))

    async def saved(self, radio: int, khz: float) -> None:
        """Wait until the clients are told radio ``radio`` is on ``khz`` and the saved
        state says so too."""
        client = await self.connect()

        async def done() -> bool:
            state = await client.state()
            radios = {r["radio"]: r for r in state["radios"] if r["station"] == 1}
            return (radios[radio]["khz"] == khz and self.saved_khz(radio) == khz
                    and self.station.engine_relays(state) is not None)

        loop = asyncio.get_running_loop()
        end = loop.time() + 15
        while not await done():
            if loop.time() > end:
                raise AssertionError(f"radio {radio} never saved on {khz}:\n{self.server_log()}")
            await asyncio.sleep(0.05)

    def saved_khz(self, radio: int) -> float | None:
        """Radio ``radio``'s frequency in the saved state file (None: none there)."""
        try:
            saved = decode(self.station.state_file.read_bytes(),
                           fingerprint(self.station.config.read_bytes()))
        except (OSError, ValueError):
            return None
        for entry in saved.engine.get("radios", []):
            if entry["radio"] == [1, radio]:
                return entry["khz"]  # type: ignore[no-any-return]
        return None

    # ------------------------------------------------------------------ the checks

    async def check(self) -> list[str]:
        """The violations in the record since the last check (also kept in :attr:`found`)."""
        assert self.box is not None
        await self.box.caught_up()
        entries = self.box.entries
        before = entries[self.checked - 1] if self.checked else None
        new = violations(entries[self.checked:], before)
        self.checked = len(entries)
        self.found += new
        return new

    async def holds_what_the_engine_says(self, timeout: float = 20.0) -> None:
        assert self.box is not None
        box = self.box
        await holds_what_the_engine_says(self.station, await self.connect(),
                                         lambda: box.relays, timeout=timeout)

    async def settle(self) -> None:
        """Every fault over, every station unkeyed, the logger moves each radio once
        more (so the state is saved again): then the box must hold what the engine says."""
        assert self.box is not None and self.cable is not None
        await self.resume()
        if not self.cable.plugged:
            self.cable.plug()
        self.cable.spoil("")
        self.block_state(False)
        for number in STATIONS:
            await self.box.key(number, False)
        await self.switch_ok()
        for radio in STATIONS:
            khz = next(k for k in BANDS if k != self.khz.get(radio))
            self.band(radio, khz)
            await self.saved(radio, khz)
        await self.holds_what_the_engine_says()

    async def close(self) -> None:
        with contextlib.suppress(ProcessLookupError, AssertionError):
            if self.stopped_at is not None:
                os.kill(self.server_pid, signal.SIGCONT)
        await self._drop_client()
        if self.server is not None:
            with contextlib.suppress(ProcessLookupError, AssertionError):
                self._block_state(False)
            await self.server.end()
        if self.cable is not None:
            self.cable.close()
        if self.box is not None:
            await self.box.close()


# --------------------------------------------------------------------------- the random walk


STEPS: dict[str, int] = {
    "key": 30,
    "band": 34,
    "restart": 4,
    "unplug": 5,
    "stall": 4,
    "noise": 7,
    "state": 4,
    "settle": 2,
}
"""What a step does, and how often (weights)."""

FAULTS = ("restart", "unplug", "stall", "noise", "state")


@dataclass
class Figures:
    steps: int = 0
    done: Counter[str] = field(default_factory=Counter)
    """Steps of each kind (faults, keys, band changes, settles)."""
    violations: list[str] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def faults(self) -> int:
        return sum(n for what, n in self.done.items() if what.split(" ")[0] in FAULT_WORDS)

    def violation_kinds(self) -> Counter[str]:
        kinds: Counter[str] = Counter()
        for violation in self.violations:
            kinds[next((kind for word, kind in VIOLATION_KINDS if word in violation),
                       "other")] += 1
        return kinds

    def report(self) -> str:
        lines = [f"steps {self.steps} in {self.seconds:.0f} s ({self.faults} faults)"]
        lines += [f"  {kind:<22} {count}" for kind, count in sorted(self.done.items())]
        lines.append(f"violations {len(self.violations)}")
        lines += [f"  {kind:<22} {count}" for kind, count in
                  sorted(self.violation_kinds().items())]
        lines += [f"  {v}" for v in self.violations[:40]]
        return "\n".join(lines)


FAULT_WORDS = ("restart", "unplug", "replug", "stall", "resume", "noise", "state")
"""The first words of the steps that are faults (or their ends)."""

VIOLATION_KINDS = (
    ("reached the box while", "reset under a key"),
    ("relays moved", "relays moved under a key"),
    ("after settling", "box is not the engine"),
    ("lost: cannot check", "record lost"),
)
"""What each violation's text contains, and its kind."""


class ModelRun:
    """Random steps on a rig, checked after each one."""

    def __init__(self, rig: Rig, seed: int, *, kinds: dict[str, int] | None = None,
                 pause: float = 0.15) -> None:
        self.rig = rig
        self.random = random.Random(seed)
        self.kinds = STEPS if kinds is None else kinds
        self.pause = pause
        self.figures = Figures()
        self.history: list[str] = []

    async def run(self, steps: int, *, progress: Callable[[Figures], None] | None = None,
                  ) -> Figures:
        started = time.monotonic()
        for radio in STATIONS:
            self.rig.band(radio, self.random.choice(BANDS))
        for _ in range(steps):
            await self.step()
            self.figures.seconds = time.monotonic() - started
            if progress is not None:
                progress(self.figures)
        await self.settle()
        self.figures.seconds = time.monotonic() - started
        return self.figures

    async def step(self) -> None:
        kind = self.random.choices(list(self.kinds), weights=list(self.kinds.values()))[0]
        what = await getattr(self, f"_{kind}")()
        self.history.append(what)
        first = what.split(" ")[0]
        self.figures.done[first if first in ("key", "unkey", "band") else what] += 1
        self.figures.steps += 1
        if self.rig.stopped_at is not None and self.random.random() < 0.5:
            await self.rig.resume()
            self.history.append("resume (SIGCONT)")
            self.figures.done["resume (SIGCONT)"] += 1
        await asyncio.sleep(self.random.uniform(0, self.pause))
        self._blame(await self.rig.check())

    async def settle(self) -> None:
        try:
            await self.rig.settle()
        except AssertionError as exc:
            self._blame([f"after settling: {exc}"])
        self._blame(await self.rig.check())

    def _blame(self, found: list[str]) -> None:
        for violation in found:
            self.figures.violations.append(
                f"step {self.figures.steps} (after {', '.join(self.history[-6:])}): "
                f"{violation}")

    # ------------------------------------------------------------------ the steps

    async def _key(self) -> str:
        assert self.rig.box is not None
        number = self.random.choice(STATIONS)
        keyed = number in {st["station"] for st in (await self.rig.box.status())["stations"]
                           if st["key"]}
        await self.rig.box.key(number, not keyed)
        return f"{'unkey' if keyed else 'key'} {number}"

    async def _band(self) -> str:
        radio = self.random.choice(STATIONS)
        khz = self.random.choice([k for k in BANDS if k != self.rig.khz.get(radio)])
        self.rig.band(radio, khz)
        return f"band {radio} {khz:g}"

    async def _restart(self) -> str:
        await self.rig.restart()
        return "restart (kill -9)"

    async def _unplug(self) -> str:
        cable = self.rig.cable
        assert cable is not None
        if cable.plugged:
            cable.unplug()
            return "unplug"
        cable.plug()
        return "replug"

    async def _stall(self) -> str:
        if self.rig.stopped_at is None:
            self.rig.stall()
            return "stall (SIGSTOP)"
        await self.rig.resume()
        return "resume (SIGCONT)"

    async def _noise(self) -> str:
        cable = self.rig.cable
        assert cable is not None
        if cable.noise:
            cable.spoil("")
            return "noise off"
        noise = self.random.choice(NOISES)
        cable.spoil(noise)
        return f"noise {noise}"

    async def _state(self) -> str:
        self.rig.block_state(not self.rig.state_blocked)
        return "state unwritable" if self.rig.state_blocked else "state writable"

    async def _settle(self) -> str:
        await self.settle()
        return "settle"


__all__ = [
    "BANDS",
    "FAULTS",
    "FAULT_WORDS",
    "NOISES",
    "STALL_S",
    "STEPS",
    "Box",
    "Cable",
    "Figures",
    "ModelRun",
    "Rig",
    "violations",
    "without_box_status",
]
