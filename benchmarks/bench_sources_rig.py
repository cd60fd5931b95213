"""Polled rig daemons: what rigctld polling costs, and the time from answer to engine call.

Two parts:

1. **CPU**: ``--radios`` real ``rigctld -m 1`` processes (Hamlib's dummy rig)
   on 127.0.0.1, each polled by one :class:`RigctldSource` at 10 Hz for
   ``--seconds``; printed: this process's CPU time over the wall time, per
   radio, in % of one core (target < 1 %), and the rigctld processes' own
   CPU for comparison (from /proc, Linux).
2. **Latency**: one source polling a stand-in rigctld on loopback that
   answers every poll with a new frequency, so every answer is a change; the
   sink calls a real engine (``Engine.set_frequency``, the small example
   station).  Printed: median, p90, p99, max of the time from the read that
   completed the answer to the sink (*in source*: parsing, the change filter,
   the report) and to the engine call's return (*with engine*).  Target: p99
   of *in source* < 1 ms.

Run: ``.venv/bin/python benchmarks/bench_sources_rig.py [--radios 2] [--seconds 10]``
"""

from __future__ import annotations

import argparse
import asyncio
import os
import shutil
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from moas_gui.config import load_config
from moas_gui.engine import Engine
from moas_gui.sources.base import FrequencyReport, SourceEvent
from moas_gui.sources.rigctld import RigctldSource

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "small-station.moas"
CPU_TARGET = 1.0
LATENCY_TARGET_MS = 1.0


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def proc_cpu(pid: int) -> float:
    """Seconds of CPU a process used (Linux /proc), or NaN."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return float("nan")


def start_daemons(ports: list[int]) -> list[subprocess.Popen[bytes]]:
    return [subprocess.Popen(["rigctld", "-m", "1", "-T", "127.0.0.1", "-t", str(p)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for p in ports]


async def cpu(radios: int, seconds: float) -> bool:
    ports = [free_port() for _ in range(radios)]
    daemons = start_daemons(ports)
    try:
        for p in ports:
            for _ in range(500):
                try:
                    socket.create_connection(("127.0.0.1", p), 1).close()
                    break
                except OSError:
                    await asyncio.sleep(0.01)
        reports: list[SourceEvent] = []
        sources = [RigctldSource(1, 1 + i % 2, reports.append, port=p, interval=0.1)
                   for i, p in enumerate(ports)]
        for s in sources:
            await s.start()
        await asyncio.sleep(1.0)  # connected and warm
        polls = sum(s.polls for s in sources)
        daemon_cpu = [proc_cpu(d.pid) for d in daemons]
        wall, own = time.perf_counter(), time.process_time()
        await asyncio.sleep(seconds)
        wall, own = time.perf_counter() - wall, time.process_time() - own
        polls = sum(s.polls for s in sources) - polls
        daemon_cpu = [proc_cpu(d.pid) - before for d, before in zip(daemons, daemon_cpu,
                                                                     strict=True)]
        for s in sources:
            await s.close()
    finally:
        for d in daemons:
            d.terminate()
            d.wait(5)
    per_radio = 100.0 * own / wall / radios
    ok = per_radio < CPU_TARGET
    print(f"rigctld CPU: {radios} radios polled {polls / wall / radios:.1f} times a second each "
          f"for {wall:.1f} s")
    print(f"  this process: {100.0 * own / wall:.2f} % of a core in all, "
          f"{per_radio:.2f} % per radio (target < {CPU_TARGET} %): {'PASS' if ok else 'FAIL'}")
    print("  each rigctld (dummy rig) itself: "
          + ", ".join(f"{100.0 * c / wall:.2f} %" for c in daemon_cpu))
    return ok


async def _poll(reader: asyncio.StreamReader) -> bool:
    try:
        await reader.readuntil(b"+t\n")
    except (asyncio.IncompleteReadError, ConnectionError):
        return False
    return True


async def latency(count: int) -> bool:
    engine = Engine(load_config(EXAMPLE).unwrap(), now=time.monotonic())
    served = 0

    async def serve(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        nonlocal served
        while await _poll(reader):
            served += 1
            hz = 14_000_000 + (served % 30000) * 10
            writer.write(f"get_freq:\nFrequency: {hz}\nRPRT 0\nget_split_vfo:\nSplit: 0\n"
                         f"TX VFO: VFOA\nRPRT 0\nget_split_freq:\nTX Frequency: {hz}\n"
                         f"RPRT 0\nget_ptt:\nPTT: 0\nRPRT 0\n".encode())

    server = await asyncio.start_server(serve, "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    in_source: list[float] = []
    total: list[float] = []
    done = asyncio.Event()
    source: RigctldSource

    def sink(event: SourceEvent) -> None:
        reached = time.perf_counter()
        assert isinstance(event, FrequencyReport)
        engine.set_frequency(event.station, event.radio, event.rx_khz, event.tx_khz,
                             now=time.monotonic())
        finished = time.perf_counter()
        if source.reports > 200:  # the first ones warm up
            in_source.append((reached - source.answered_at) * 1e3)
            total.append((finished - source.answered_at) * 1e3)
        if len(in_source) >= count:
            done.set()

    source = RigctldSource(1, 1, sink, port=port, interval=0.001)
    await source.start()
    await asyncio.wait_for(done.wait(), 120)
    await source.close()
    server.close()

    def figures(values: list[float]) -> str:
        q = statistics.quantiles(values, n=100)
        return (f"median {statistics.median(values):.3f}, p90 {q[89]:.3f}, p99 {q[98]:.3f}, "
                f"max {max(values):.3f} ms")

    p99 = statistics.quantiles(in_source, n=100)[98]
    ok = p99 < LATENCY_TARGET_MS
    print(f"rigctld answer to engine call, {count} answers, each a new frequency:")
    print(f"  in source: {figures(in_source)}")
    print(f"  with engine: {figures(total)}")
    print(f"  in source p99 < {LATENCY_TARGET_MS} ms: {'PASS' if ok else 'FAIL'}")
    return ok


async def main(radios: int, seconds: float, count: int) -> int:
    results = [await latency(count)]
    if shutil.which("rigctld"):
        results.append(await cpu(radios, seconds))
    else:
        print("rigctld CPU: skipped, Hamlib's rigctld is not installed (libhamlib-utils)")
    return 0 if all(results) else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radios", type=int, default=2)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--count", type=int, default=3000)
    a = parser.parse_args()
    sys.exit(asyncio.run(main(a.radios, a.seconds, a.count)))
