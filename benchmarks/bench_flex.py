"""FlexRadio slice change to the first byte at the switch, beside N1MM Logger's path.

One process, one event loop, real sockets and a real pseudo-terminal: the server
(``ServerApp`` on examples/small-station.moas) follows the test FlexRadio
(:mod:`moas_gui.testing.flex_radio`, TCP on 127.0.0.1, slice A feeding station 1
radio 1) and listens for N1MM Logger's RadioInfo (UDP on 127.0.0.1); the switch
is the emulator on a pseudo-terminal, whose side of the terminal stamps each read.

The two paths take turns on the same radio: the Flex slice tunes to 80 m, then
N1MM says 20 m, then the slice 80 m again (a little higher each time, so every
change is a new frequency and a new band, and the relays change).  Each change's
time runs from the write of the slice status (or the ``sendto`` of the packet) to
the read holding the first byte of the switch command that follows.  The server's
relay dwell (automatic changes move a station's relays at most once in 100 ms) is 0
here, as in bench_server.py's latency floods, so each change's own command is timed
(``--dwell MS`` puts it back).  Printed: the count, median, p90, p99 and max of each
path, in ms, and the load average.

Run: ``.venv/bin/python benchmarks/bench_flex.py [--changes 200] [--gap 0.05]``
(``--changes 5`` is a smoke run of a few seconds).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import logging
import os
import socket
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.status import ServerState
from moas_gui.testing.flex_radio import FlexRadio

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "small-station.moas"


class TappedSwitch:
    """The emulator on a pseudo-terminal; every read of its side is stamped."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self.box = EmulatedBox()
        self.endpoint = PtyEndpoint()
        self.reads: list[tuple[float, bytes]] = []
        self.endpoint.start(loop, self._data)
        self.box.attach(self.endpoint.write)

    def _data(self, data: bytes) -> None:
        self.reads.append((time.perf_counter(), data))
        self.box.receive(data)

    def first_command_after(self, t0: float) -> float | None:
        """When the first read after ``t0`` holding a relay command (``!``) came."""
        return next((t for t, data in self.reads if t >= t0 and b"!" in data), None)

    def close(self) -> None:
        self.endpoint.close()
        self.box.close()


async def wait_for(condition: object, timeout: float = 5.0) -> None:
    end = time.monotonic() + timeout
    while not condition():  # type: ignore[operator]
        if time.monotonic() > end:
            raise RuntimeError("bench_flex: gave up waiting")
        await asyncio.sleep(0.001)


async def run(changes: int, gap: float, dwell: float) -> dict[str, list[float]]:
    loop = asyncio.get_running_loop()
    switch = TappedSwitch(loop)
    radio = FlexRadio()
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    data = json.loads(EXAMPLE.read_text(encoding="utf-8"))
    data["Switches"][0]["Port"] = switch.endpoint.path
    work = Path(tempfile.mkdtemp(prefix="bench-flex-"))
    path = work / "station.moas"
    path.write_text(json.dumps(data), encoding="utf-8")
    app = ServerApp(ServerOptions(
        bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
        start_rotator_program=False, antenna_log=False, relay_dwell=dwell,
        switch_timing=LinkTiming(ping_interval=5.0, answer_timeout=1.0, retry_first=0.1,
                                 retry_max=0.5),
        flex=(f"127.0.0.1:{radio.port}",), flex_radios="A=1/1"))
    times: dict[str, list[float]] = {"FlexRadio slice": [], "N1MM RadioInfo": []}
    udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        assert (await app.open(path)).ok
        await wait_for(lambda: app.status.state is ServerState.NORMAL)
        assert app.sources is not None and app.sources.n1mm is not None
        n1mm_port = app.sources.n1mm.port
        engine = app.engine
        assert engine is not None and n1mm_port is not None
        await wait_for(lambda: engine.radio_view(1, 1).khz == 14025.0)
        for i in range(changes):
            flex_khz = 3525.0 + i * 0.1
            t0 = time.perf_counter()
            radio.set_slice(0, RF_frequency=flex_khz / 1000.0)
            await _record(switch, t0, times["FlexRadio slice"])
            await asyncio.sleep(gap)
            n1mm_khz = 14025.0 + i * 0.1
            packet = radio_info_packet(1, n1mm_khz, station_name="RUN-PC")
            t0 = time.perf_counter()
            udp.sendto(packet, ("127.0.0.1", n1mm_port))
            await _record(switch, t0, times["N1MM RadioInfo"])
            await asyncio.sleep(gap)
    finally:
        udp.close()
        await app.close()
        await radio.stop()
        switch.close()
    return times


async def _record(switch: TappedSwitch, t0: float, into: list[float]) -> None:
    await wait_for(lambda: switch.first_command_after(t0) is not None)
    first = switch.first_command_after(t0)
    assert first is not None
    into.append((first - t0) * 1000.0)


def pct(values: list[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(p / 100 * (len(ordered) - 1)))]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--changes", type=int, default=200,
                        help="changes of each path (default 200)")
    parser.add_argument("--gap", type=float, default=0.05,
                        help="seconds between two changes (default 0.05)")
    parser.add_argument("--dwell", type=float, default=0.0, metavar="MS",
                        help="the server's relay dwell in ms (default 0)")
    args = parser.parse_args()
    logging.basicConfig(level=logging.WARNING)
    times = asyncio.run(run(args.changes, args.gap, args.dwell / 1000.0))
    print(f"change -> first byte at the switch, ms ({args.changes} changes each, relay "
          f"dwell {args.dwell:g} ms, load average {os.getloadavg()[0]:.2f})")
    print(f"{'path':<18}{'n':>5}{'median':>9}{'p90':>9}{'p99':>9}{'max':>9}")
    for name, values in times.items():
        print(f"{name:<18}{len(values):>5}{statistics.median(values):>9.3f}"
              f"{pct(values, 90):>9.3f}{pct(values, 99):>9.3f}{max(values):>9.3f}")


if __name__ == "__main__":
    main()
