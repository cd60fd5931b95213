"""N1MM Logger flood: 1,000 RadioInfo packets a second for 10 s over real UDP on 127.0.0.1.

A separate sender process plays two SO2R radios whose frequency changes in
every packet (so every packet reaches ``on_frequency``), paced to the rate
asked.  The listener runs on a plain asyncio loop in this process.  Printed:

- packets sent / received / passed on / superseded (read in the same burst as
  a newer packet for the same radio, so only the newer one is passed on) /
  lost (sent but never read), and the kernel's drop count for the socket;
- time from ``sendto`` in the sender to the frequency being acted on here
  (CLOCK_MONOTONIC is shared by both processes): for a superseded packet, until
  the newer frequency that replaced it reached ``on_frequency``.  Median, p90,
  p99, max, and p99 per second, which stays flat when nothing backs up;
- the largest receive-queue length the kernel reported for the socket
  (sampled every 100 ms from /proc/net/udp) and the CPU time of the listener.

Run: ``.venv/bin/python benchmarks/bench_n1mm.py [--rate 1000] [--seconds 10]``
"""

from __future__ import annotations

import argparse
import asyncio
import json
import resource
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from moas_gui.sources.n1mm import N1MMListener, radio_info_packet

BASE_UNITS = 1_400_000  # 14,000.00 kHz in 10 Hz units


def send(port: int, rate: int, seconds: float) -> None:
    """The sender process: paced packets, then the send times as JSON on stdout."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    count = int(rate * seconds)
    packets = [radio_info_packet(1 + seq % 2, (BASE_UNITS + seq) / 100, station_name="SO2R-PC")
               for seq in range(count)]
    sent = [0] * count
    start = time.monotonic() + 0.2
    for seq, data in enumerate(packets):
        due = start + seq / rate
        delay = due - time.monotonic()
        if delay > 0.0005:
            time.sleep(delay - 0.0003)
        while time.monotonic() < due:
            pass
        sent[seq] = time.monotonic_ns()
        sock.sendto(data, ("127.0.0.1", port))
    print(json.dumps(sent))


def rx_queue(port: int) -> tuple[int, int]:
    """(receive-queue bytes, drops) of the UDP socket bound to ``port``, from /proc/net/udp."""
    try:
        lines = Path("/proc/net/udp").read_text().splitlines()[1:]
    except OSError:
        return (0, 0)
    for line in lines:
        parts = line.split()
        if int(parts[1].split(":")[1], 16) == port:
            return (int(parts[4].split(":")[1], 16), int(parts[-1]))
    return (0, 0)


async def listen(rate: int, seconds: float) -> None:
    received: dict[int, int] = {}

    def on_frequency(station: int, radio: int, khz: float, tx_khz: float) -> None:
        received[round(khz * 100) - BASE_UNITS] = time.monotonic_ns()

    listener = N1MMListener({"127.0.0.1": 1}, on_frequency)
    port = await listener.start(port=0, host="127.0.0.1")
    cpu_before = resource.getrusage(resource.RUSAGE_SELF)
    sender = await asyncio.create_subprocess_exec(
        sys.executable, __file__, "--send", str(port), "--rate", str(rate),
        "--seconds", str(seconds), stdout=subprocess.PIPE)
    queue_max = 0
    drops = 0
    reader = asyncio.ensure_future(sender.communicate())
    while not reader.done():
        queued, drops = rx_queue(port)
        queue_max = max(queue_max, queued)
        await asyncio.wait([reader], timeout=0.1)
    stdout, _ = reader.result()
    await asyncio.sleep(0.2)
    cpu_after = resource.getrusage(resource.RUSAGE_SELF)
    stats = listener.stats()
    await listener.close()

    sent: list[int] = json.loads(stdout)
    acted = acted_on(received, len(sent))
    latencies = sorted((acted[seq] - t) / 1e6 for seq, t in enumerate(sent) if seq in acted)
    cpu = (cpu_after.ru_utime + cpu_after.ru_stime) - (cpu_before.ru_utime + cpu_before.ru_stime)
    wall = (sent[-1] - sent[0]) / 1e9

    def pct(values: list[float], p: float) -> float:
        return values[min(len(values) - 1, int(p / 100 * len(values)))]

    print(f"N1MM flood: {len(sent)} packets at {rate}/s over {wall:.1f} s, real UDP on 127.0.0.1")
    lost = len(sent) - stats.received
    unaccounted = len(sent) - len(received) - stats.superseded
    print(f"  received {stats.received}, passed on {stats.delivered}, superseded "
          f"{stats.superseded}, refused {sum(stats.refused.values())}, lost {lost} "
          f"(kernel drops {drops})")
    print(f"  send -> acted on: median {statistics.median(latencies):.3f} ms, "
          f"p90 {pct(latencies, 90):.3f} ms, p99 {pct(latencies, 99):.3f} ms, "
          f"max {latencies[-1]:.3f} ms")
    per_second = []
    for second in range(int(seconds)):
        chunk = sorted((acted[seq] - sent[seq]) / 1e6
                       for seq in range(second * rate, min((second + 1) * rate, len(sent)))
                       if seq in acted)
        if chunk:
            per_second.append(f"{pct(chunk, 99):.2f}")
    print(f"  p99 per second (ms): {' '.join(per_second)}")
    print(f"  largest kernel receive queue: {queue_max} bytes; listener CPU {cpu:.2f} s "
          f"({100 * cpu / max(wall, 1e-9):.1f}% of one core)")
    complete = lost == 0 and unaccounted == 0 and len(acted) == len(sent)
    verdict = "PASS" if pct(latencies, 99) < 5.0 and complete else "FAIL"
    if unaccounted:
        print(f"  {unaccounted} packets were read but neither passed on nor superseded")
    print(f"  target p99 < 5 ms and nothing lost: {verdict}")


def acted_on(received: dict[int, int], count: int) -> dict[int, int]:
    """When each packet's frequency was acted on: its own ``on_frequency`` call, or,
    for one superseded in a burst, the call of the next packet for the same radio
    (packets alternate between the two radios)."""
    acted: dict[int, int] = {}
    for seq in range(count - 1, -1, -1):
        if seq in received:
            acted[seq] = received[seq]
        elif seq + 2 in acted:
            acted[seq] = acted[seq + 2]
    return acted


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=int, default=1000)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--send", type=int, metavar="PORT", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.send:
        send(args.send, args.rate, args.seconds)
    else:
        asyncio.run(listen(args.rate, args.seconds))


if __name__ == "__main__":
    main()
