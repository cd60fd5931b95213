"""32 emulated rotators on one ``moas-rotator``, polled every second.

Prints two figures:

- CPU used by the ``moas-rotator`` process (user + system time over the
  measuring window, as a share of one core).  Target: under 5 %.
- Latency: from a heading changed at a controller (turned by hand on the
  emulator) to the ``<rotator> <degrees>`` line arriving on TCP.  Target:
  within one poll interval + 50 ms.

The emulators (every model in turn) run in this process, on pseudo-terminals;
the program runs as a separate process on 127.0.0.1, started exactly as a
user would start it.  Emulated ports have no baud-rate delay: on real
controllers add the bytes' time on the wire (a 12-byte SPID answer at 600
baud takes 0.2 s).

Run: ``.venv/bin/python benchmarks/bench_rotator_program.py [--rotators 32] [--seconds 20]``
"""

from __future__ import annotations

import argparse
import os
import random
import socket
import statistics
import subprocess
import sys
import time

from moas_gui.hw.rotators.controllers.models import MODELS
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Reports:
    """Reads ``<rotator> <degrees>`` lines from the program, noting when each came."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.sock.setblocking(False)
        self.buffer = b""

    def drain(self, until: float, enough: int | None = None) -> list[tuple[float, str]]:
        """Lines until ``until``, or until ``enough`` lines have come."""
        lines: list[tuple[float, str]] = []
        while time.monotonic() < until and (enough is None or len(lines) < enough):
            try:
                data = self.sock.recv(65536)
            except BlockingIOError:
                time.sleep(0.002)
                continue
            if not data:
                raise SystemExit("the program closed the connection")
            now = time.monotonic()
            self.buffer += data
            *complete, self.buffer = self.buffer.split(b"\r")
            lines += [(now, line.decode("ascii")) for line in complete]
        return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rotators", type=int, default=32)
    parser.add_argument("--seconds", type=float, default=20.0, help="measuring window")
    parser.add_argument("--poll", type=int, default=1000, help="poll time in ms")
    args = parser.parse_args()

    program = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.rotator", "--bind", "127.0.0.1", "--port", "0",
         "--log-level", "WARNING"], stdout=subprocess.PIPE, text=True)
    assert program.stdout is not None
    port = int(program.stdout.readline().strip().rsplit(":", 1)[1])
    host = EmulatorHost().start()
    served: list[tuple[ServedPort, str, bool]] = []
    try:
        for number in range(args.rotators):
            model = MODELS[number % len(MODELS)]
            emulator = model.make_emulator(100.0 + number, 6.0, host.clock())
            served.append((host.add(emulator), model.name, model.info.has_readback))
        sock = socket.create_connection(("127.0.0.1", port))
        sock.sendall("".join(f"CONFIGURE {n} {name.replace(' ', '')} {p.path} {args.poll}\r"
                             for n, (p, name, _) in enumerate(served)).encode("ascii"))
        reports = Reports(sock)
        first = reports.drain(time.monotonic() + 3.0)
        seen = {int(line.split()[0]) for _, line in first}
        expected = {n for n, (_, _, readback) in enumerate(served) if readback}
        print(f"{args.rotators} rotators ({len(expected)} with position readback), "
              f"poll {args.poll} ms; first headings from {len(seen & expected)}")

        start_cpu, start = cpu_seconds(program.pid), time.monotonic()
        latencies: list[float] = []
        last: dict[int, int] = {}
        missed = 0
        rng = random.Random(7)
        while time.monotonic() - start < args.seconds:
            # Turn every rotator with readback by hand, at a random moment of the poll cycle.
            time.sleep(rng.uniform(0.0, args.poll / 1000))
            wanted: dict[int, int] = {}
            changed_at = time.monotonic()
            for n, (p, _, readback) in enumerate(served):
                if readback:
                    heading = rng.randrange(10, 350)
                    while heading == last.get(n):  # an unchanged heading is not reported
                        heading = rng.randrange(10, 350)
                    host.call(p, lambda e, now, h=heading: e.turn_by_hand(float(h), now))
                    wanted[n] = last[n] = heading
            deadline = changed_at + args.poll / 1000 * 2 + 1.0
            while wanted and time.monotonic() < deadline:
                for when, line in reports.drain(deadline, enough=1):
                    rotator, degrees = (int(x) for x in line.split())
                    if wanted.get(rotator) == degrees:
                        latencies.append((when - changed_at) * 1000)
                        del wanted[rotator]
            missed += len(wanted)
        elapsed = time.monotonic() - start
        used = cpu_seconds(program.pid) - start_cpu
        sock.close()
    finally:
        program.terminate()
        program.wait(timeout=10)
        host.close()

    latencies.sort()
    print(f"CPU of moas-rotator: {used:.2f} s in {elapsed:.1f} s = {100 * used / elapsed:.2f} % "
          f"of one core (target < 5 %)")
    if latencies:
        p95 = latencies[int(0.95 * (len(latencies) - 1))]
        print(f"heading change -> TCP report, {len(latencies)} changes: "
              f"median {statistics.median(latencies):.0f} ms, 95th percentile {p95:.0f} ms, "
              f"max {latencies[-1]:.0f} ms (target <= {args.poll + 50} ms); missed {missed}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
