"""Frequency sources: time from a datagram sent on 127.0.0.1 to the engine call.

For each UDP source the server runs (N1MM Logger+, DXLog.net, Win-Test, and
N1MM's rotor window) this sends one datagram at a time from a plain UDP socket
on 127.0.0.1 to the listening source, every one a new frequency (or heading),
and waits until the source's event reaches the sink; the sink calls a real
engine (``Engine.set_frequency`` for the small example station).  Printed per
source: median, p90, p99 and max of

- *to sink*: ``sendto`` to the moment the event enters the sink (what the
  source adds: kernel loopback, the loop waking, parsing, mapping), and
- *in source*: from the event loop handing the datagram to the source
  (``datagram_received``) to the sink: parsing, mapping, the change filter,
  without the kernel and the scheduler of a shared machine;
- *with engine*: until the engine call has returned.

The target is p99 under 1 ms for what the source adds (*in source*); *to sink*
also holds the loopback hop and the wake-up of the loop, which on a loaded
machine are the scheduler's.

Run: ``.venv/bin/python benchmarks/bench_sources.py [--count 3000]``
"""

from __future__ import annotations

import argparse
import asyncio
import socket
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from moas_gui.config import load_config
from moas_gui.engine import Engine
from moas_gui.sources.base import FrequencyReport, SourceEvent
from moas_gui.sources.dxlog import DXLogListener
from moas_gui.sources.n1mm import N1MMListener
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.sources.n1mm_rotor import N1MMRotorServer
from moas_gui.sources.n1mm_rotor_packet import turn_command
from moas_gui.sources.udp import DatagramSource
from moas_gui.sources.wintest import WinTestListener
from moas_gui.sources.wintest_frame import status_frame

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "small-station.moas"
TARGET_MS = 1.0


class Probe:
    """The sink: notes when an event arrives, calls the engine, wakes the sender."""

    def __init__(self, engine: Engine) -> None:
        self.engine = engine
        self.arrived = 0
        self.received = 0
        self.done = 0
        self.waiter: asyncio.Future[None] | None = None

    def event(self, event: SourceEvent) -> None:
        if not isinstance(event, FrequencyReport):
            return
        self.arrived = time.perf_counter_ns()
        self.engine.set_frequency(event.station, event.radio, event.rx_khz, event.tx_khz,
                                  now=time.monotonic())
        self._finish()

    def turn(self, rotator_id: int, heading: float) -> None:
        self.arrived = time.perf_counter_ns()
        self._finish()

    def _finish(self) -> None:
        self.done = time.perf_counter_ns()
        if self.waiter is not None and not self.waiter.done():
            self.waiter.set_result(None)


async def measure(name: str, source: DatagramSource, probe: Probe,
                  packet: Callable[[int], bytes], count: int) -> bool:
    port = await source.start(0, "127.0.0.1")
    loop = asyncio.get_running_loop()
    handler = source.datagram_received

    def timed(data: bytes, addr: tuple[str | int, ...]) -> None:
        probe.received = time.perf_counter_ns()
        handler(data, addr)

    source.datagram_received = timed  # type: ignore[method-assign]
    in_source: list[float] = []
    to_sink: list[float] = []
    total: list[float] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        packets = [packet(i) for i in range(count + 200)]
        for i, data in enumerate(packets):
            probe.waiter = loop.create_future()
            sent = time.perf_counter_ns()
            sock.sendto(data, ("127.0.0.1", port))
            await asyncio.wait_for(probe.waiter, 5)
            if i >= 200:  # the first ones warm up caches and the allocator
                to_sink.append((probe.arrived - sent) / 1e6)
                in_source.append((probe.arrived - probe.received) / 1e6)
                total.append((probe.done - sent) / 1e6)
    await source.close()
    p99 = statistics.quantiles(in_source, n=100)[98]
    ok = p99 < TARGET_MS

    def figures(values: list[float]) -> str:
        q = statistics.quantiles(values, n=100)
        return (f"median {statistics.median(values):.3f}, p90 {q[89]:.3f}, p99 {q[98]:.3f}, "
                f"max {max(values):.3f} ms")

    print(f"{name:<12} in source: {figures(in_source)}")
    print(f"{'':<12} to sink: {figures(to_sink)}")
    print(f"{'':<12} with engine: {figures(total)}")
    print(f"{'':<12} in source p99 < {TARGET_MS} ms: {'PASS' if ok else 'FAIL'}")
    return ok


async def main(count: int) -> int:
    config = load_config(EXAMPLE).unwrap()
    results = []
    for name, make, packet in (
        ("N1MM", lambda p: N1MMListener({"127.0.0.1": 1}, on_event=p.event),
         lambda i: radio_info_packet(1 + i % 2, 14000.0 + i / 100, station_name="SO2R-PC")),
        ("DXLog.net", lambda p: DXLogListener({"127.0.0.1": 1}, on_event=p.event),
         lambda i: radio_info_packet(1 + i % 2, 7000.0 + i / 100, app="DXLog")),
        ("Win-Test", lambda p: WinTestListener({"RUN": (1, 1)}, p.event),
         lambda i: status_frame("RUN", 21000.0 + i / 10)),
        ("N1MM rotor", lambda p: N1MMRotorServer({1: ("TH6",)}, turn=p.turn, stop=print,
                                                 headings=list),
         lambda i: turn_command("TH6", (i % 3600) / 10)),
    ):
        probe = Probe(Engine(config, now=time.monotonic()))
        results.append(await measure(name, make(probe), probe, packet, count))
    print(f"sources: {count} datagrams each over real UDP on 127.0.0.1, one at a time")
    return 0 if all(results) else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=3000)
    sys.exit(asyncio.run(main(parser.parse_args().count)))
