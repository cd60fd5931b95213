"""How fast the engine answers: frequency changes and button presses on the examples.

Run:  .venv/bin/python benchmarks/bench_engine.py [--ops N]
      .venv/bin/python benchmarks/bench_engine.py --compare REV [--rounds N]

Prints, per configuration, the median and 99th percentile time from an input
to the new switch states, both wall-clock and CPU time of this thread (on a
busy shared machine the wall-clock tail is the scheduler's, not the engine's).
Targets (big-station, multi-multi-20): median under 0.5 ms, p99 under 2 ms.

``--compare REV`` measures band changes of this tree and of git revision REV (say, the
commit before a change) in the same run: the two take turns, in separate processes, for
``--rounds`` rounds, and the best median CPU time of each is printed with the ratio.
Explaining each decision (the reasons in ``engine/why.py``) may cost at most 10 %.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from moas_gui.config import load_config
from moas_gui.config.model import (
    Antenna,
    Config,
    ControlRange,
    FrequencyRange,
    Radio,
    RadioRef,
    StationRelays,
    Switch,
    SwitchPort,
)
from moas_gui.engine import Engine, EngineError

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ["2x6", "small-station", "ms-one-amp", "tribander-stack", "triplexer",
            "big-station", "multi-multi-20"]
BANDS = [(1800, 2000), (3500, 4000), (7000, 7300), (14000, 14350), (21000, 21450),
         (28000, 29700)]


def synthetic(antennas: int = 150, radios: int = 6) -> Config:
    """A six-radio station with many antennas on one switch (more keys than slots)."""
    out = []
    for i in range(antennas):
        lo, hi = BANDS[i % len(BANDS)]
        stations = tuple(StationRelays(1, r, relays=frozenset({(i + r) % 64}))
                         for r in range(1, radios + 1))
        out.append(Antenna(i, short_name=f"A{i}", conflicts=(i,), fast=(i,),
                           control=(ControlRange(FrequencyRange(lo, hi), stations),)))
    rs = tuple(Radio(1, r, switches=(SwitchPort(1, r),),
                     always=tuple(RadioRef(1, o) for o in range(1, radios + 1) if o != r))
               for r in range(1, radios + 1))
    return Config(antennas=tuple(out), radios=rs,
                  switches=(Switch(1, "emulator", indicate_tr=True),))


def measure(fn: Callable[[], object], count: int) -> tuple[list[float], list[float]]:
    wall: list[float] = []
    cpu: list[float] = []
    for _ in range(count):
        c0 = time.thread_time()
        t0 = time.perf_counter()
        try:
            fn()
        except EngineError:
            pass
        wall.append(time.perf_counter() - t0)
        cpu.append(time.thread_time() - c0)
    return wall, cpu


def pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(len(ordered) * q))] * 1000


def bench(name: str, cfg: Config, ops: int, rng: random.Random) -> None:
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios()
              if cfg.radio(v.station, v.radio) is not None]
    bands = [b for b in BANDS if any(
        cr.range.contains((b[0] + b[1]) / 2) for a in cfg.antennas for cr in a.control)]
    now = [0.0]

    def frequency() -> object:
        now[0] += 0.05
        s, r = rng.choice(radios)
        lo, hi = rng.choice(bands)
        return e.set_frequency(s, r, rng.uniform(lo, hi), now=now[0])

    def tune() -> object:
        now[0] += 0.05
        s, r = rng.choice(radios)
        view = e.radio_view(s, r)
        khz = (view.khz or 14025.0) + rng.uniform(-0.5, 0.5)
        return e.set_frequency(s, r, khz, now=now[0])

    pressed = [0, 0]

    def press() -> object:
        """A press on an antenna covering the radio's frequency (as a layout would show)."""
        now[0] += 0.05
        s, r = rng.choice(radios)
        khz = e.radio_view(s, r).khz or 14025.0
        shown = [a.id for a in cfg.antennas if any(
            cr.range.contains(khz) and any(x.applies_to(s, r) for x in cr.stations)
            for cr in a.control)] or [cfg.antennas[0].id]
        pressed[0] += 1
        changes = e.select(s, r, rng.choice(shown), exclusive=rng.random() < 0.2, now=now[0])
        pressed[1] += 1
        return changes

    for s, r in radios:
        e.set_frequency(s, r, 14025.0 + s + r)
    results = {}
    for label, fn in (("band change", frequency), ("tuning", tune), ("button press", press)):
        measure(fn, ops // 10)
        results[label] = measure(fn, ops)
    lay_wall, _ = measure(lambda: e.layout(radios[0][0], radios[0][1], 4, 3), max(20, ops // 20))
    print(f"{name:16} {len(cfg.antennas):4} ant {len(radios):2} radios", end="")
    for label, (wall, cpu) in results.items():
        print(f" | {label}: {statistics.median(wall) * 1000:.3f}/{pct(wall, .99):.2f} ms wall,"
              f" {statistics.median(cpu) * 1000:.3f}/{pct(cpu, .99):.2f} ms cpu", end="")
    print(f" | layout {statistics.median(lay_wall) * 1000:.2f} ms"
          f" | presses accepted {pressed[1]}/{pressed[0]}")


BAND_CHANGES = """
import json, random, statistics, sys, time
from pathlib import Path
from moas_gui.config import load_config
from moas_gui.engine import Engine
bands = %r
out = {}
for name in %r:
    cfg = load_config(Path(%r) / "examples" / f"{name}.moas").unwrap()
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios() if cfg.radio(v.station, v.radio)]
    rng = random.Random(4)
    ops = [(*rng.choice(radios), rng.uniform(*rng.choice(bands))) for _ in range(%d)]
    now = 0.0
    cpu = []
    for i, (s, r, khz) in enumerate(ops):
        now += 0.05
        c0 = time.thread_time()
        e.set_frequency(s, r, khz, now=now)
        if i >= len(ops) // 10:
            cpu.append(time.thread_time() - c0)
    out[name] = statistics.median(cpu) * 1e6
print(json.dumps(out))
"""
COMPARED = ("small-station", "big-station", "multi-multi-20")


def tree_at(rev: str, work: Path) -> Path:
    """The files of git revision ``rev``, extracted into ``work/base`` (for a comparison
    of this tree with an older one in the same run)."""
    base = work / "base"
    base.mkdir()
    tar = work / "base.tar"
    tar.write_bytes(subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", rev],
                                   check=True, capture_output=True).stdout)
    with tarfile.open(tar) as t:
        t.extractall(base, filter="data")
    return base


def compare(rev: str, rounds: int, ops: int) -> None:
    """Band changes of this tree against revision ``rev``, taking turns (see the docstring)."""
    with tempfile.TemporaryDirectory(prefix="moas-bench-") as tmp:
        base = tree_at(rev, Path(tmp))
        best: dict[str, dict[str, float]] = {"before": {}, "after": {}}
        ratios: dict[str, list[float]] = {name: [] for name in COMPARED}
        for turn in range(rounds):
            seen: dict[str, dict[str, float]] = {}
            order = (("before", base), ("after", ROOT))
            for label, tree in order if turn % 2 == 0 else order[::-1]:
                code = BAND_CHANGES % (BANDS, COMPARED, str(ROOT), ops)
                env = dict(os.environ, PYTHONPATH=str(tree))
                done = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp,
                                      check=True, capture_output=True, text=True)
                seen[label] = json.loads(done.stdout)
                for name, us in seen[label].items():
                    best[label][name] = min(best[label].get(name, float("inf")), us)
            for name in COMPARED:
                ratios[name].append(seen["after"][name] / seen["before"][name])
    print(f"band change, median CPU time per change, {rounds} rounds of {ops} changes, "
          f"before = {rev}; best of the rounds, and the median of each round's after/before")
    for name in COMPARED:
        before, after = best["before"][name], best["after"][name]
        print(f"{name:16} before {before:7.1f} us  after {after:7.1f} us  "
              f"best {(after / before - 1) * 100:+5.1f} %  "
              f"per round {(statistics.median(ratios[name]) - 1) * 100:+5.1f} %")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ops", type=int, default=2000)
    parser.add_argument("--compare", metavar="REV",
                        help="compare band changes with git revision REV, in the same run")
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    if args.compare:
        compare(args.compare, args.rounds, args.ops)
        return
    rng = random.Random(4)
    print("median/p99 per operation; cpu = this thread's CPU time")
    for name in EXAMPLES:
        bench(name, load_config(ROOT / "examples" / f"{name}.moas").unwrap(), args.ops, rng)
    bench("synthetic-150x6", synthetic(), args.ops, rng)


if __name__ == "__main__":
    main()
