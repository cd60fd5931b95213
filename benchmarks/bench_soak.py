"""Soak: an hour of contest traffic compressed into ten minutes, against the real server.

The real headless server (``moas-server --headless --new-instance``, its own XDG
directories) runs the big example station (two stations, two switches, twelve
rotators: the nine serial ones made Test rotators) with both switches emulated on
pseudo-terminals.  Traffic, six times a contest's real rate:

- two loggers (one per station, from 127.0.0.1 and 127.0.0.2) send N1MM RadioInfo
  packets to the UDP port: tuning steps six times a second, and a band change about
  every ten seconds; each band change is followed until the switch holds the relays
  of the antenna the server chose for it (the benchmark reads the emulated boxes);
- twenty clients (``hello``, ``layout``) press antenna buttons, step through relative
  antennas and ask for the state, each about every twenty seconds, and turn rotators
  now and then; every client reads every event;
- the emulated switches now and then send a burst of garbage in the middle of their
  replies (``--no-garbage`` leaves it out).

Every five seconds the server process's resident memory (RSS) and open file
descriptors are sampled.  At the end the server is stopped with SIGTERM and its log
is read.  PASS means: no ERROR line and no traceback in the log, every band change
reached the switch, and RSS and file descriptors flat (the last quarter's mean within
10 % / 5 descriptors of the second quarter's).  Linux only (``/proc``).

Run: ``.venv/bin/python benchmarks/bench_soak.py [--minutes 10] [--clients 20]``
(not part of the test suite).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import signal
import socket
import statistics
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Awaitable, Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from moas_gui.config import load_config
from moas_gui.config.model import Config
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve
from moas_gui.sources.n1mm_packet import radio_info_packet

T = TypeVar("T")
SPEED = 6.0
"""Contest time per benchmark time: an hour in ten minutes."""
BANDS = {  # kHz: (low, high) of the phone+CW segment the loggers tune in
    1830.0: (1800.0, 1900.0), 3525.0: (3500.0, 3800.0), 7025.0: (7000.0, 7200.0),
    14025.0: (14000.0, 14300.0), 21025.0: (21000.0, 21400.0), 28025.0: (28000.0, 28500.0),
}
LOGGERS = {1: "127.0.0.1", 2: "127.0.0.2"}
"""Station -> the address its logger sends from."""


# ---- the switches, on a loop of their own ------------------------------------------------


class Switchboard:
    """The emulated switches on pseudo-terminals, served by their own thread and
    loop, so that the benchmark's traffic never delays their answers."""

    def __init__(self, links: dict[int, Path]) -> None:
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self._thread.start()
        self.boxes: dict[int, EmulatedBox] = {}
        self.endpoints: dict[int, PtyEndpoint] = {}
        self.run(self._plug(links))

    def run(self, coroutine: Awaitable[T]) -> T:
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(10)  # type: ignore[arg-type]

    async def _plug(self, links: dict[int, Path]) -> None:
        for switch, link in links.items():
            box = EmulatedBox(loop=self.loop)
            endpoint = PtyEndpoint()
            serve(box, endpoint, self.loop)
            make_link(endpoint.path, link)
            self.boxes[switch], self.endpoints[switch] = box, endpoint

    async def _relays(self) -> frozenset[int]:
        closed: set[int] = set()
        for switch, box in self.boxes.items():
            closed.update((switch - 1) * 100 + r for r in box.view().relays)
        return frozenset(closed)

    async def relays(self) -> frozenset[int]:
        """Every closed relay, numbered as the configuration numbers them."""
        future: Future[frozenset[int]] = asyncio.run_coroutine_threadsafe(
            self._relays(), self.loop)
        return await asyncio.wrap_future(future)

    def garbage(self, switch: int, data: bytes) -> None:
        self.loop.call_soon_threadsafe(self.endpoints[switch].write, data)

    def close(self) -> None:
        async def unplug() -> None:
            for box in self.boxes.values():
                box.close()
            for endpoint in self.endpoints.values():
                endpoint.close()

        self.run(unplug())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(5)


# ---- figures ------------------------------------------------------------------------------


@dataclass
class Figures:
    packets: int = 0
    band_changes: int = 0
    reached: int = 0
    no_antenna: int = 0
    band_change_ms: list[float] = field(default_factory=list)
    missed: list[str] = field(default_factory=list)
    requests: Counter[str] = field(default_factory=Counter)
    replies: Counter[str] = field(default_factory=Counter)
    request_ms: list[float] = field(default_factory=list)
    events: int = 0
    garbage: int = 0
    samples: list[tuple[float, int, int]] = field(default_factory=list)
    """(seconds since start, RSS kB, open descriptors)."""


def pct(values: list[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(p / 100 * len(ordered)))] if ordered else 0.0


# ---- clients ---------------------------------------------------------------------------------


class Client:
    """One protocol client that reads every line and matches replies to requests."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                 figures: Figures) -> None:
        self.reader, self.writer, self.figures = reader, writer, figures
        self.waiting: dict[int, asyncio.Future[dict[str, Any]]] = {}
        self.next_id = 0
        self.listeners: list[Callable[[dict[str, Any]], None]] = []
        self.task = asyncio.create_task(self._read())
        self.keeper = asyncio.create_task(self._keep_alive())

    async def _keep_alive(self) -> None:
        """A blank line every 30 s: the server closes a client silent for two minutes, and
        the observer only listens (docs/client-protocol.md)."""
        while True:
            await asyncio.sleep(30)
            self.writer.write(b"\n")

    @classmethod
    async def connect(cls, port: int, figures: Figures) -> Client:
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        return cls(reader, writer, figures)

    async def _read(self) -> None:
        while line := await self.reader.readline():
            message = json.loads(line)
            if "event" in message:
                self.figures.events += 1
                for listener in self.listeners:
                    listener(message)
            else:
                future = self.waiting.pop(message["id"], None)
                if future is not None and not future.done():
                    future.set_result(message)

    async def request(self, cmd: str, **args: Any) -> dict[str, Any]:
        self.next_id += 1
        future: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
        self.waiting[self.next_id] = future
        self.writer.write(json.dumps({"id": self.next_id, "cmd": cmd, **args}).encode() + b"\n")
        started = time.monotonic()
        reply = await asyncio.wait_for(future, 10)
        self.figures.request_ms.append((time.monotonic() - started) * 1000)
        self.figures.requests[cmd] += 1
        self.figures.replies["ok" if reply["ok"] else reply["error"]["code"]] += 1
        return reply

    async def close(self) -> None:
        self.writer.close()
        self.task.cancel()
        self.keeper.cancel()
        await asyncio.gather(self.task, self.keeper, return_exceptions=True)


class Station:
    """What the benchmark knows of one station: its lock (a band change being
    followed to the switch is not disturbed by button presses) and its band."""

    def __init__(self, number: int) -> None:
        self.number = number
        self.lock = asyncio.Lock()
        self.band = 14025.0
        self.khz = 14025.0


async def operator(client: Client, station: Station, config: Config, rotators: list[int],
                   stop: asyncio.Event, rng: random.Random) -> None:
    """A client pressing buttons for one station's radio about every 20 s of benchmark time."""
    await client.request("hello", client=f"soak {id(client) % 10_000}", station=station.number,
                         radio=1)
    while not stop.is_set():
        try:
            await asyncio.wait_for(stop.wait(), rng.uniform(5.0, 35.0))
            return
        except TimeoutError:
            pass
        choice = rng.random()
        if choice < 0.1 and rotators:
            await client.request("rotate", rotator=rng.choice(rotators),
                                 heading=rng.uniform(0, 359))
            continue
        if choice < 0.2:
            await client.request("state")
            continue
        async with station.lock:
            layout = (await client.request("layout", station=station.number, radio=1, rows=4,
                                           columns=3))["result"]
            antennas = [b["id"] for b in layout["buttons"] if b["type"] == "Antenna"]
            if choice < 0.35:
                await client.request("relative", station=station.number, radio=1,
                                     step=rng.choice((1, -1)))
            elif antennas:
                await client.request("select", station=station.number, radio=1,
                                     antenna=rng.choice(antennas))


def wanted_relays(config: Config, station: int, antenna_id: int, khz: float) -> frozenset[int]:
    """The relays that receiving on ``antenna_id`` at ``khz`` closes for the station's radio."""
    antenna = config.antenna(antenna_id)
    if antenna is None:
        return frozenset()
    for control in antenna.control:
        if control.range.contains(khz):
            for entry in control.stations:
                if entry.applies_to(station, 1):
                    return entry.rx_relays if entry.rx_relays is not None else entry.relays
    return frozenset()


async def logger(station: Station, other: Station, udp_port: int, observer: Client,
                 switchboard: Switchboard, config: Config, figures: Figures,
                 stop: asyncio.Event, rng: random.Random) -> None:
    """One N1MM logger: tuning steps six times a second, a band change every ~10 s."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((LOGGERS[station.number], 0))
    sock.setblocking(False)
    name = f"STATION{station.number}"
    heard: dict[float, asyncio.Future[dict[str, Any]]] = {}

    def on_event(message: dict[str, Any]) -> None:
        if message.get("event") == "radio" and message.get("station") == station.number:
            future = heard.pop(message.get("khz"), None)
            if future is not None and not future.done():
                future.set_result(message)

    observer.listeners.append(on_event)
    next_band_change = time.monotonic() + rng.uniform(2.0, 10.0)
    try:
        while not stop.is_set():
            if time.monotonic() >= next_band_change:
                next_band_change = time.monotonic() + rng.uniform(5.0, 15.0)
                await band_change(station, other, sock, udp_port, name, heard, switchboard,
                                  config, figures, rng)
                continue
            low, high = BANDS[station.band]
            station.khz = round(min(high, max(low, station.khz + rng.uniform(-2.0, 2.0))), 2)
            sock.sendto(radio_info_packet(1, station.khz, station_name=name),
                        ("127.0.0.1", udp_port))
            figures.packets += 1
            await asyncio.sleep(1 / SPEED)
    finally:
        sock.close()


async def band_change(station: Station, other: Station, sock: socket.socket, udp_port: int,
                      name: str, heard: dict[float, asyncio.Future[dict[str, Any]]],
                      switchboard: Switchboard, config: Config, figures: Figures,
                      rng: random.Random) -> None:
    bands = [b for b in BANDS if b not in (station.band, other.band)]
    band = rng.choice(bands)
    async with station.lock:
        station.band, station.khz = band, band
        future: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
        heard[band] = future
        started = time.monotonic()
        sock.sendto(radio_info_packet(1, band, station_name=name), ("127.0.0.1", udp_port))
        figures.packets += 1
        figures.band_changes += 1
        try:
            event = await asyncio.wait_for(future, 5)
        except TimeoutError:
            figures.missed.append(f"station {station.number} to {band} kHz: no radio event")
            return
        if event.get("rx") is None:
            figures.no_antenna += 1
            return
        want = wanted_relays(config, station.number, event["rx"], band)
        deadline = started + 5
        while not want <= await switchboard.relays():
            if time.monotonic() > deadline:
                figures.missed.append(
                    f"station {station.number} to {band} kHz, antenna {event['rx']}: relays "
                    f"{sorted(want)} not closed")
                return
            await asyncio.sleep(0.005)
        figures.reached += 1
        figures.band_change_ms.append((time.monotonic() - started) * 1000)


async def garbage(switchboard: Switchboard, figures: Figures, stop: asyncio.Event,
                  rng: random.Random) -> None:
    """Now and then a switch puts a burst of noise on the line."""
    while not stop.is_set():
        try:
            await asyncio.wait_for(stop.wait(), rng.uniform(20.0, 40.0))
            return
        except TimeoutError:
            pass
        noise = bytes(rng.choice(b"#!@xyz\x00\xff09\r") for _ in range(rng.randint(1, 12)))
        switchboard.garbage(rng.choice(list(switchboard.boxes)), noise)
        figures.garbage += 1


# ---- the server -----------------------------------------------------------------------------


def free_port(kind: int) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def station_file(directory: Path, links: dict[int, Path]) -> Path:
    data = json.loads((ROOT / "examples" / "big-station.moas").read_text())
    for switch in data["Switches"]:
        switch["Port"] = str(links[switch["ID"]])
    for rotator in data["Rotators"]:
        if rotator["Control"] == "Serial":
            for key in ("Address", "CommPort", "Model", "Poll"):
                rotator.pop(key, None)
            rotator["Control"] = "Test"
    data["N1MMLogger"] = [{"Address": a, "Station": s} for s, a in LOGGERS.items()]
    data["UseN1MMLogger"] = True
    data["StartMOASRotator"] = False
    path = directory / "soak.moas"
    path.write_text(json.dumps(data, indent=2))
    return path


def sample(pid: int) -> tuple[int, int]:
    rss = 0
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            rss = int(line.split()[1])
    return rss, len(os.listdir(f"/proc/{pid}/fd"))


async def sampler(pid: int, figures: Figures, stop: asyncio.Event, started: float) -> None:
    while not stop.is_set():
        rss, fds = sample(pid)
        figures.samples.append((time.monotonic() - started, rss, fds))
        try:
            await asyncio.wait_for(stop.wait(), 5.0)
        except TimeoutError:
            pass


async def soak(minutes: float, clients: int, with_garbage: bool, seed: int) -> int:
    rng = random.Random(seed)
    figures = Figures()
    with tempfile.TemporaryDirectory(prefix="moas-soak-") as tmp:
        directory = Path(tmp)
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        for name in ("XDG_RUNTIME_DIR", "XDG_CONFIG_HOME", "XDG_STATE_HOME", "XDG_DATA_HOME",
                     "XDG_CACHE_HOME"):
            (directory / name).mkdir(mode=0o700)
            env[name] = str(directory / name)
        links = {1: directory / "switch1", 2: directory / "switch2"}
        switchboard = Switchboard(links)
        path = station_file(directory, links)
        config = load_config(path).unwrap()
        rotators = [r.id for r in config.rotators]
        tcp, udp = free_port(socket.SOCK_STREAM), free_port(socket.SOCK_DGRAM)
        log_path = directory / "server.log"
        with log_path.open("wb") as log_file:
            process = await asyncio.create_subprocess_exec(
                sys.executable, "-m", "moas_gui.cli.server", "--headless", str(path),
                "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", str(udp),
                "--udp-bind", "127.0.0.1", "--no-rotator-program", "--new-instance",
                "--log-level", "info", stderr=log_file, env=env, cwd=ROOT)
        try:
            observer = await connect_when_ready(tcp, figures, process)
            await observer.request("hello", client="soak observer")
            stop = asyncio.Event()
            started = time.monotonic()
            stations = {1: Station(1), 2: Station(2)}
            stations[2].band = stations[2].khz = 7025.0
            operators = [await Client.connect(tcp, figures) for _ in range(clients)]
            tasks = [asyncio.create_task(sampler(process.pid, figures, stop, started))]
            tasks += [asyncio.create_task(operator(c, stations[1 + i % 2], config, rotators, stop,
                                                   random.Random(rng.random())))
                      for i, c in enumerate(operators)]
            tasks += [asyncio.create_task(logger(stations[s], stations[3 - s], udp, observer,
                                                 switchboard, config, figures, stop,
                                                 random.Random(rng.random())))
                      for s in (1, 2)]
            if with_garbage:
                tasks.append(asyncio.create_task(garbage(switchboard, figures, stop, rng)))
            await report_progress(minutes * 60, started, figures, tasks)
            stop.set()
            await asyncio.gather(*tasks)
            figures.samples.append((time.monotonic() - started, *sample(process.pid)))
            for client in (*operators, observer):
                await client.close()
        finally:
            if process.returncode is None:
                process.send_signal(signal.SIGTERM)
                try:
                    await asyncio.wait_for(process.wait(), 15)
                except TimeoutError:
                    process.kill()
                    await process.wait()
            switchboard.close()
        log_text = log_path.read_text(errors="replace")
    return verdict(minutes, clients, figures, log_text, process.returncode)


async def connect_when_ready(port: int, figures: Figures,
                             process: asyncio.subprocess.Process) -> Client:
    for _ in range(200):
        if process.returncode is not None:
            raise SystemExit(f"the server ended at start (status {process.returncode})")
        try:
            return await Client.connect(port, figures)
        except OSError:
            await asyncio.sleep(0.1)
    raise SystemExit("the server never listened")


async def report_progress(seconds: float, started: float, figures: Figures,
                          tasks: list[asyncio.Task[None]]) -> None:
    while (left := started + seconds - time.monotonic()) > 0:
        await asyncio.sleep(min(60.0, left))
        failed = [t for t in tasks if t.done() and t.exception() is not None]
        if failed:
            raise failed[0].exception()  # type: ignore[misc]
        rss, fds = figures.samples[-1][1:] if figures.samples else (0, 0)
        print(f"  {time.monotonic() - started:5.0f} s: {figures.packets} packets, "
              f"{figures.reached}/{figures.band_changes} band changes on the switch, "
              f"{sum(figures.requests.values())} requests, RSS {rss / 1024:.1f} MB, "
              f"{fds} descriptors", flush=True)


def verdict(minutes: float, clients: int, figures: Figures, log_text: str,
            status: int | None) -> int:
    lines = log_text.splitlines()
    levels = Counter(line.split()[1] for line in lines if len(line.split()) > 1)
    errors = [line for line in lines if " ERROR " in line or "Traceback" in line]
    quarter = max(1, len(figures.samples) // 4)
    second = figures.samples[quarter:2 * quarter] or figures.samples
    last = figures.samples[-quarter:]
    rss_second = statistics.mean(s[1] for s in second) / 1024
    rss_last = statistics.mean(s[1] for s in last) / 1024
    fds_second = statistics.mean(s[2] for s in second)
    fds_last = statistics.mean(s[2] for s in last)
    rss_all = [s[1] / 1024 for s in figures.samples]
    fds_all = [s[2] for s in figures.samples]
    flat = rss_last <= rss_second * 1.10 and fds_last <= fds_second + 5
    print(f"Soak: {minutes:g} min ({minutes * SPEED:g} min of contest time), {clients} clients, "
          "2 loggers, 2 emulated switches, 12 rotators")
    print(f"  logger packets {figures.packets:,}; band changes {figures.band_changes}, on the "
          f"switch {figures.reached}, no free antenna {figures.no_antenna}, "
          f"missed {len(figures.missed)}")
    if figures.band_change_ms:
        print(f"  packet -> relays closed: median {statistics.median(figures.band_change_ms):.1f}"
              f" ms, p99 {pct(figures.band_change_ms, 99):.1f} ms, "
              f"max {max(figures.band_change_ms):.1f} ms")
    print(f"  requests {sum(figures.requests.values()):,} "
          f"({', '.join(f'{k} {v}' for k, v in figures.requests.most_common())}); replies "
          f"{', '.join(f'{k} {v}' for k, v in figures.replies.most_common())}")
    print(f"  request round trip: median {statistics.median(figures.request_ms or [0]):.1f} ms,"
          f" p99 {pct(figures.request_ms, 99):.1f} ms; events received {figures.events:,}; "
          f"garbage bursts {figures.garbage}")
    print(f"  server RSS MB: min {min(rss_all):.1f}, max {max(rss_all):.1f}, second quarter "
          f"{rss_second:.1f}, last quarter {rss_last:.1f}")
    print(f"  open descriptors: min {min(fds_all)}, max {max(fds_all)}, second quarter "
          f"{fds_second:.1f}, last quarter {fds_last:.1f}")
    print(f"  log: {len(lines):,} lines ({', '.join(f'{k} {v}' for k, v in levels.most_common())})"
          f"; server exit status {status}")
    for line in errors[:10]:
        print(f"  log ERROR: {line}")
    for miss in figures.missed[:10]:
        print(f"  missed: {miss}")
    ok = not errors and not figures.missed and flat and status == 0 and figures.band_changes > 0
    print(f"  target no ERROR line, every band change on the switch, RSS and descriptors "
          f"flat: {'PASS' if ok else 'FAIL'}")
    return 0 if ok else 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--clients", type=int, default=20)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-garbage", action="store_true")
    args = parser.parse_args()
    if not sys.platform.startswith("linux"):
        raise SystemExit("the soak reads /proc: Linux only")
    sys.exit(asyncio.run(soak(args.minutes, args.clients, not args.no_garbage, args.seed)))


if __name__ == "__main__":
    main()
