"""Benchmark of the client protocol server (prints figures; not a test).

The server runs in its own process (``python -m moas_gui.testing.fake_server``,
the fake backend, which reports a ``radio`` event for every select that
changes something) on 127.0.0.1; the clients run here, on one asyncio loop,
with the lightest possible reading (a line is timed the moment its bytes
arrive), so the figures include both processes sharing the machine's cores.

1. Fan-out: ``--clients`` (50) greeted clients; one of them sends ``select``
   (alternating two antennas, so every press changes the radio), and the
   time from sending it to the ``radio`` event having arrived at *all the
   others* is measured, ``--presses`` times.  Target: p99 under 20 ms.
2. Rate: one client sends ``--rate`` (1,000) requests a second for
   ``--seconds`` (5) seconds, a mix of select, layout, frequency, state and
   stop, paced by the clock; the achieved rate, the latency from request to
   reply, and whether a backlog grows are reported.  Then the same with the
   fan-out clients still connected, listening to every event.

Run: ``.venv/bin/python benchmarks/bench_clients.py [--clients 50] [--presses 1000]``
"""

from __future__ import annotations

import argparse
import asyncio
import functools
import json
import os
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field

HOST = "127.0.0.1"
RADIO_EVENT = b'{"event": "radio"'


@dataclass
class Round:
    """One press: who still has to hear of it."""

    waiting: set[int]
    done: asyncio.Future[float]
    last: float = 0.0


class Peer(asyncio.Protocol):
    """A client that times each line as its bytes arrive."""

    def __init__(self, number: int, bench: Bench) -> None:
        self.number, self.bench = number, bench
        self.buffer = b""
        self.transport: asyncio.Transport | None = None
        self.replies: dict[int, asyncio.Future[float]] = {}

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport

    def data_received(self, data: bytes) -> None:
        now = time.perf_counter()
        self.buffer += data
        while (end := self.buffer.find(b"\n")) >= 0:
            line, self.buffer = self.buffer[:end], self.buffer[end + 1 :]
            if line.startswith(RADIO_EVENT):
                self.bench.heard(self.number, now)
            elif line.startswith(b'{"id": '):
                request_id = int(line[7 : line.index(b",")])
                future = self.replies.pop(request_id, None)
                if future is not None and not future.done():
                    ok = line.find(b'"ok": true') >= 0
                    future.set_result(now if ok else -now)

    def request(self, request_id: int, message: dict[str, object]) -> asyncio.Future[float]:
        assert self.transport is not None
        future: asyncio.Future[float] = asyncio.get_running_loop().create_future()
        self.replies[request_id] = future
        self.transport.write(json.dumps({"id": request_id, **message}).encode() + b"\n")
        return future


@dataclass
class Bench:
    port: int
    peers: list[Peer] = field(default_factory=list)
    round: Round | None = None

    def heard(self, number: int, now: float) -> None:
        r = self.round
        if r is not None and number in r.waiting:
            r.waiting.discard(number)
            r.last = max(r.last, now)
            if not r.waiting and not r.done.done():
                r.done.set_result(r.last)

    async def connect(self, count: int) -> None:
        loop = asyncio.get_running_loop()
        for _ in range(count):
            number = len(self.peers)
            _, peer = await loop.create_connection(
                functools.partial(Peer, number, self), HOST, self.port
            )
            self.peers.append(peer)
            await peer.request(0, {"cmd": "hello", "client": f"bench {number}"})

    def close(self) -> None:
        for peer in self.peers:
            if peer.transport is not None:
                peer.transport.close()
        self.peers.clear()


def percentile(values: list[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(p / 100 * (len(ordered) - 1)))]


def ms(value: float) -> str:
    return f"{value * 1000:7.2f} ms"


async def fan_out(bench: Bench, presses: int) -> list[float]:
    presser = bench.peers[0]
    others = set(range(1, len(bench.peers)))
    loop = asyncio.get_running_loop()
    latencies: list[float] = []
    for i in range(presses + 20):
        bench.round = Round(set(others), loop.create_future())
        antenna = 1 if i % 2 == 0 else 2
        start = time.perf_counter()
        reply = presser.request(i + 1, {"cmd": "select", "station": 1, "radio": 1,
                                        "antenna": antenna})
        last = await asyncio.wait_for(bench.round.done, 10)
        if await reply < 0:
            raise SystemExit(f"select {i} was refused")
        if i >= 20:  # the first presses warm both processes up
            latencies.append(last - start)
        await asyncio.sleep(0.002)
    bench.round = None
    return latencies


MIX: list[dict[str, object]] = [
    {"cmd": "select", "station": 1, "radio": 1, "antenna": 1},
    {"cmd": "layout", "station": 1, "radio": 1, "rows": 4, "columns": 3},
    {"cmd": "select", "station": 1, "radio": 1, "antenna": 2},
    {"cmd": "frequency", "station": 2, "radio": 1, "khz": 7050.0},
    {"cmd": "state"},
    {"cmd": "stop", "rotator": 1},
    {"cmd": "frequency", "station": 2, "radio": 1, "khz": 7025.0},
]


async def sustained(bench: Bench, rate: int, seconds: float) -> dict[str, float]:
    loop = asyncio.get_running_loop()
    _, sender = await loop.create_connection(lambda: Peer(-1, bench), HOST, bench.port)
    sent_at: dict[int, float] = {}
    latencies: list[tuple[float, float]] = []
    refused = 0
    pending: set[asyncio.Future[float]] = set()

    def done(request_id: int, future: asyncio.Future[float]) -> None:
        nonlocal refused
        pending.discard(future)
        arrived = future.result()
        if arrived < 0:
            refused += 1
        latencies.append((sent_at[request_id], abs(arrived) - sent_at[request_id]))

    start = time.perf_counter()
    sent = 0
    total = int(rate * seconds)
    while sent < total:
        due = min(total, int((time.perf_counter() - start) * rate) + 1)
        while sent < due:
            sent += 1
            sent_at[sent] = time.perf_counter()
            future = sender.request(sent, MIX[sent % len(MIX)])
            pending.add(future)
            future.add_done_callback(functools.partial(done, sent))
        await asyncio.sleep(0.0005)
    backlog_at_end = len(pending)
    if pending:
        await asyncio.wait(pending, timeout=10)
    elapsed = max(t + lat for t, lat in latencies) - start
    assert sender.transport is not None
    sender.transport.close()
    lat = [x for _, x in latencies]
    first = [x for t, x in latencies if t - start < 1.0]
    last = [x for t, x in latencies if t - start >= seconds - 1.0]
    return {
        "requests": float(len(latencies)), "refused": float(refused),
        "rate": len(latencies) / elapsed, "p50": statistics.median(lat),
        "p99": percentile(lat, 99), "max": max(lat),
        "p99_first_second": percentile(first, 99), "p99_last_second": percentile(last, 99),
        "backlog_at_end": float(backlog_at_end),
    }


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def report_rate(title: str, r: dict[str, float], cpu: float | None, own: float) -> None:
    print(f"\n{title}")
    print(f"  requests answered     {int(r['requests']):>7}  ({int(r['refused'])} refused by "
          "the rules, e.g. an antenna in use)")
    print(f"  achieved rate         {r['rate']:7.0f} requests/s")
    print(f"  latency p50           {ms(r['p50'])}")
    print(f"  latency p99           {ms(r['p99'])}   (first second {ms(r['p99_first_second'])},"
          f" last second {ms(r['p99_last_second'])})")
    print(f"  latency max           {ms(r['max'])}")
    print(f"  unanswered when the sending stopped: {int(r['backlog_at_end'])}")
    if cpu is not None:
        print(f"  server CPU            {cpu * 100:7.1f} % of one core")
    print(f"  clients' CPU          {own * 100:7.1f} % of one core (this process)")


async def measure(args: argparse.Namespace, pid: int, port: int) -> None:
    bench = Bench(port)
    print(f"Client protocol server benchmark (fake backend, server pid {pid}, "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f})")
    await bench.connect(args.clients)
    latencies = await fan_out(bench, args.presses)
    print(f"\nFan-out: {args.clients} clients, {args.presses} presses; time from a select "
          f"on one client to the radio event at all {args.clients - 1} others")
    print(f"  p50 {ms(statistics.median(latencies))}   p90 {ms(percentile(latencies, 90))}"
          f"   p99 {ms(percentile(latencies, 99))}   max {ms(max(latencies))}"
          f"   (target p99 < 20 ms)")
    within = sum(1 for x in latencies if x < 0.010) / len(latencies)
    print(f"  presses heard by every client within 10 ms: {within * 100:.1f} %")

    listeners = len(bench.peers)
    bench.close()
    await asyncio.sleep(0.2)
    for title in (f"Sustained: one client, {args.rate} requests/s for {args.seconds:g} s",
                  f"Sustained with {listeners} more clients listening to every event"):
        if not title.startswith("Sustained:"):
            await bench.connect(listeners)
        before, own = cpu_seconds(pid), time.process_time()
        result = await sustained(bench, args.rate, args.seconds)
        cpu = (cpu_seconds(pid) - before) / args.seconds
        own = (time.process_time() - own) / args.seconds
        report_rate(title, result, cpu, own)
    bench.close()


def main(args: argparse.Namespace) -> None:
    server = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.testing.fake_server", "--host", HOST, "--port", "0",
         "--log", "WARNING", "--max-per-address", "100000"],  # every client is on 127.0.0.1
        stdout=subprocess.PIPE, text=True,
    )
    try:
        assert server.stdout is not None
        port = int(server.stdout.readline().split()[1])
        asyncio.run(measure(args, server.pid, port))
    finally:
        server.terminate()
        server.wait(10)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="client protocol server benchmark")
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--presses", type=int, default=1000)
    parser.add_argument("--rate", type=int, default=1000)
    parser.add_argument("--seconds", type=float, default=5.0)
    main(parser.parse_args())
