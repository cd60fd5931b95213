"""The engine's property job at benchmark size: random operator events on every example
station and on generated stations, every rule of ``tests/engine_invariants.py`` checked
after every event, plus the appendix F differential test on generated stations.

Run:  .venv/bin/python benchmarks/bench_engine_properties.py [--events N] [--seed S]

At least 10^5 events by default.  Prints events, refusals and time per station kind, and
exits with status 1 (naming the rule and the events that broke it) on the first failure.
The normal test suite runs a fast, derandomized subset of the same checks.
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from engine_invariants import Facts, operations, replay_matches, run_evening
from engine_stations import generated_station
from test_engine_appendix_f_differential import compare

from moas_gui.config import load_config

EXAMPLES = ["2x6", "small-station", "big-station", "tribander-stack", "multi-multi-20",
            "triplexer", "ms-one-amp"]
EVENING = 500
"""Events per evening (a fresh engine each)."""


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--events", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    configs = {name: load_config(ROOT / "examples" / f"{name}.moas").unwrap()
               for name in EXAMPLES}
    facts = {name: Facts.of(cfg) for name, cfg in configs.items()}
    share_examples = args.events * 6 // 10
    share_generated = args.events * 3 // 10
    share_differential = args.events - share_examples - share_generated
    total = refused = 0
    print(f"{'job':<22}{'events':>9}{'refused':>9}{'seconds':>9}{'us/event':>10}")
    try:
        for name in EXAMPLES:
            cfg = configs[name]
            start = time.perf_counter()
            n = r = 0
            while n < share_examples // len(EXAMPLES):
                ops = list(operations(cfg, random.Random(rng.random()), EVENING))
                r += run_evening(cfg, ops, facts[name])
                n += len(ops)
            assert replay_matches(cfg, ops), f"{name}: the same events gave another result"
            took = time.perf_counter() - start
            print(f"{name:<22}{n:>9}{r:>9}{took:>9.1f}{took / n * 1e6:>10.0f}")
            total += n
            refused += r
        start = time.perf_counter()
        n = r = stations = 0
        while n < share_generated:
            seed = rng.random()
            station_rng = random.Random(seed)
            cfg = generated_station(station_rng)
            ops = list(operations(cfg, station_rng, EVENING))
            try:
                r += run_evening(cfg, ops)
            except AssertionError as err:
                raise AssertionError(f"generated station (seed {seed!r}): {err}") from err
            n += len(ops)
            stations += 1
        took = time.perf_counter() - start
        print(f"{f'generated ({stations})':<22}{n:>9}{r:>9}{took:>9.1f}{took / n * 1e6:>10.0f}")
        total += n
        refused += r
        start = time.perf_counter()
        n = stations = 0
        while n < share_differential:
            compare(rng.randrange(2**32), 100)
            n += 100
            stations += 1
        took = time.perf_counter() - start
        print(f"{f'appendix F ({stations})':<22}{n:>9}{0:>9}{took:>9.1f}{took / n * 1e6:>10.0f}")
        total += n
    except AssertionError as err:
        print(f"FAILED: {err}")
        return 1
    print(f"{'total':<22}{total:>9}{refused:>9}   every rule held after every event")
    return 0


if __name__ == "__main__":
    sys.exit(main())
