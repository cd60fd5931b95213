"""What the antenna log costs (docs/antenna-log.md, "What it costs").

    .venv/bin/python benchmarks/bench_antenna_log.py [--changes 400] [--hours 48] [--rate 200]

Prints:

* **on the loop, per band change**: the time the running server's hooks take when a
  box confirms a band change (:meth:`AntennaRecorder.landed`: compare, then queue one
  tuple), measured in a running server on the built-in emulator;
* **band change to the box, log on and off**: from the engine's decision (``act``) to
  the emulated box holding the new relays, with the log on and with it off, in the
  same run (the log is never on that path: the two should not differ);
* **the writer's CPU per row**: the journal's writer thread, fed a burst of rows;
* **a 48-hour contest at 200 QSOs an hour** (synthetic: four radios, a band change per
  radio every 4 minutes, 1.5 transmissions per QSO, a heading every 3 minutes): the
  database's size on disk, and the time to join every QSO to the antennas.

Figures are worth something only on a quiet machine (nothing else running).
Everything is written under a temporary directory (``XDG_DATA_HOME`` and
``XDG_STATE_HOME`` are set to it).
"""

from __future__ import annotations

import argparse
import asyncio
import os
import random
import statistics
import tempfile
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
BANDS = (7025.0, 14025.0, 21025.0, 28025.0)


def _quantiles(values: list[float]) -> str:
    values = sorted(values)
    p = statistics.quantiles(values, n=100) if len(values) > 1 else values * 99
    return f"median {statistics.median(values):8.1f}  p99 {p[98]:8.1f}  max {values[-1]:8.1f}"


async def _band_changes(changes: int, log_on: bool) -> tuple[list[float], list[float]]:
    """(hook µs per landing, act-to-box ms per change) in a running server."""
    from moas_gui.antenna_log.recorder import AntennaRecorder
    from moas_gui.app import ServerApp, ServerOptions
    from moas_gui.engine.operations import SetFrequency
    from moas_gui.hw.moas2.link import LinkTiming

    hook_us: list[float] = []
    original = AntennaRecorder.landed

    def timed(self: AntennaRecorder, *args: object) -> None:
        start = time.perf_counter_ns()
        original(self, *args)  # type: ignore[arg-type]
        hook_us.append((time.perf_counter_ns() - start) / 1000)

    AntennaRecorder.landed = timed  # type: ignore[method-assign]
    app = ServerApp(ServerOptions(
        bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
        start_rotator_program=False, antenna_log=log_on, relay_dwell=0.0,
        switch_timing=LinkTiming(ping_interval=1.0, answer_timeout=3.0)))
    to_box_ms: list[float] = []
    try:
        assert (await app.open(EXAMPLES / "small-station.moas")).ok
        box = app.emulators()[1]
        while app.status.state.name != "NORMAL":
            await asyncio.sleep(0.01)
        hook_us.clear()
        for i in range(changes):
            before = box.view().relays
            start = time.perf_counter()
            app.act(SetFrequency(1, 1, BANDS[i % len(BANDS)]))
            while box.view().relays == before:
                await asyncio.sleep(0)
            to_box_ms.append((time.perf_counter() - start) * 1000)
            await asyncio.sleep(0.005)  # the box's events come back; the hook runs
    finally:
        await app.close()
        AntennaRecorder.landed = original  # type: ignore[method-assign]
    return hook_us, to_box_ms


def _writer_cpu(directory: Path, rows: int) -> tuple[float, float]:
    """(µs of enqueue per row on the caller, µs of process CPU per row written)."""
    from moas_gui.antenna_log.journal import MAX_QUEUED, Journal

    journal = Journal(directory / "writer.sqlite")
    journal.flush()
    cpu = time.process_time()
    enqueue = 0.0
    for first in range(0, rows, MAX_QUEUED // 2):  # bursts within the queue's bound
        start = time.perf_counter()
        for i in range(first, min(rows, first + MAX_QUEUED // 2)):
            journal.antenna(1 + i % 4, 1, "tx", f"antenna {i % 9}",
                            path="switch 1 port 1 slot 3", at=1e9 + i)
        enqueue += time.perf_counter() - start
        journal.flush(60)
    enqueue = enqueue / rows * 1e6
    written = (time.process_time() - cpu) / rows * 1e6
    assert journal.stats().dropped == 0
    journal.close()
    return enqueue, written - enqueue


def _contest(directory: Path, hours: int, rate: int, seed: int = 34) -> tuple[int, int, float,
                                                                                float]:
    """(bytes on disk, rows, seconds to write, seconds to join every QSO)."""
    from moas_gui.antenna_log.journal import AntennaInfo, Journal
    from moas_gui.antenna_log.records import Period
    from moas_gui.sources.n1mm_contact import ContactPacket

    rng = random.Random(seed)
    path = directory / "contest.sqlite"
    start_time = 1_800_000_000.0
    journal = Journal(path, clock=lambda: start_time)
    antennas = [f"{band} m stack {n}" for band in (10, 15, 20, 40, 80, 160) for n in (1, 2)]
    journal.describe(AntennaInfo(a, f"Tower {i % 3}", 0.0) for i, a in enumerate(antennas))
    rows = 0
    began = time.perf_counter()
    end = start_time + hours * 3600
    t = start_time
    number = 0
    while t < end:
        t += rng.expovariate(rate / 3600)
        radio = rng.randint(1, 4)
        if rng.random() < 60 / rate:  # ~15 band changes per radio an hour, 4 radios
            for role in ("tx", "rx"):
                journal.antenna(1, radio, role, rng.choice(antennas),  # type: ignore[arg-type]
                                path="switch 1 port 1 slot 3", at=t)
                rows += 1
        for _ in range(rng.choice((1, 1, 2))):
            journal.keyed(1, radio, True, at=t - 8)
            journal.keyed(1, radio, False, at=t - 4)
            rows += 2
        if rng.random() < 20 / rate:
            journal.heading(f"Tower {rng.randint(0, 2)}", rng.randint(0, 359), at=t)
            rows += 1
        number += 1
        journal.contact(ContactPacket("contactinfo", f"{number:032x}", t, f"K{number}X", "14",
                                      "CW", 14025.0, 14025.0, radio, "RUN-PC", "OP", "TEST"),
                        1, radio, at=t + 0.2)
        rows += 1
        if number % 2_000 == 0:  # within the journal's queue bound (MAX_QUEUED)
            journal.flush(60)
    journal.flush(600)
    written = time.perf_counter() - began
    joined = time.perf_counter()
    qsos = journal.contacts(Period(start_time, t + 1))
    join_s = time.perf_counter() - joined
    assert len(qsos) == number
    journal.close()
    size = sum(p.stat().st_size for p in path.parent.glob(path.name + "*"))
    return size, rows, written, join_s


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--changes", type=int, default=400)
    parser.add_argument("--hours", type=int, default=48)
    parser.add_argument("--rate", type=int, default=200, help="QSOs an hour")
    parser.add_argument("--rows", type=int, default=50_000, help="rows of the writer burst")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-antenna-log-") as temp:
        directory = Path(temp)
        os.environ["XDG_DATA_HOME"] = str(directory / "data")
        os.environ["XDG_STATE_HOME"] = str(directory / "state")
        print("Figures need a quiet machine: nothing else running.\n")
        hook, with_log = asyncio.run(_band_changes(args.changes, True))
        _, without_log = asyncio.run(_band_changes(args.changes, False))
        print(f"on the loop per confirmed band change (µs): {_quantiles(hook)}"
              f"  ({len(hook)} landings)")
        print(f"band change to the box, log on (ms):      {_quantiles(with_log)}")
        print(f"band change to the box, log off (ms):     {_quantiles(without_log)}")
        enqueue, writer = _writer_cpu(directory, args.rows)
        print(f"journal enqueue per row (µs, caller):     {enqueue:8.2f}")
        print(f"writer CPU per row (µs, its thread):      {writer:8.2f}  ({args.rows} rows)")
        size, rows, written, join_s = _contest(directory, args.hours, args.rate)
        print(f"{args.hours} h at {args.rate} QSOs/h: {rows:,} rows, {size / 1e6:.1f} MB on "
              f"disk, written in {written:.1f} s, every QSO joined in {join_s:.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
