"""Configuration fuzzing at scale, and the checker's time on long lists.

    .venv/bin/python benchmarks/bench_config_fuzz.py [--count 100000] [--seed 15]

Part 1 reads ``--count`` mutated files (truncations, byte flips, deletions, insertions,
type swaps of every example and of generated stations; ``tests/config_fuzzing.py``)
and prints mutations per second, problems found, the worst time per file, and the
crashes (exceptions) and unplaced problems (no line and column), which must be 0.

Part 2 times one ``Relays`` list, one ``InUse`` list and one circle of systems as they
grow: the time per item must stay flat (linear), and each makes a few problems, not
one per item.

The verdict is PASS when nothing crashed, every problem had a place, no file took a
second, and the long lists stayed linear.  Figures: docs/reliability.md.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from config_fuzzing import corpus, mutations, read

from moas_gui.config import parse_config

LIMIT_S = 1.0


def fuzz(count: int, seed: int, generated: int) -> bool:
    files = corpus(generated)
    sizes = ", ".join(f"{name} {len(data) / 1024:.0f} KiB" for name, data in files.items())
    print(f"corpus: {len(files)} files ({sizes})")
    per_kind: Counter[str] = Counter()
    broken: Counter[str] = Counter()
    worst: dict[str, float] = defaultdict(float)
    problems = crashes = unplaced = 0
    crash_lines: Counter[str] = Counter()
    started = time.perf_counter()
    reading = 0.0
    for done, (name, kind, data) in enumerate(mutations(files, count, seed), 1):
        outcome = read(data, name)
        reading += outcome.seconds
        per_kind[kind] += 1
        broken[kind] += not outcome.usable
        problems += outcome.problems
        worst[name] = max(worst[name], outcome.seconds)
        if outcome.crash:
            crashes += 1
            crash_lines[outcome.crash.strip().splitlines()[-1][:160]] += 1
        if outcome.unplaced:
            unplaced += 1
            print(f"  unplaced: {outcome.unplaced}")
        if done % 10_000 == 0:
            print(f"  {done:,} read, {crashes} crashes, {time.perf_counter() - started:.0f} s",
                  flush=True)
    wall = time.perf_counter() - started
    print(f"mutations: {count:,} in {wall:.1f} s = {count / wall:,.0f} mutations/s "
          f"(reading alone {count / reading:,.0f}/s; mean {reading / count * 1000:.2f} ms)")
    for kind in sorted(per_kind):
        print(f"  {kind:<11} {per_kind[kind]:>7,} files, {broken[kind]:>7,} unusable")
    print(f"problems found: {problems:,} ({problems / count:.1f} per mutated file)")
    print("worst time per file (ms): " + ", ".join(
        f"{name} {worst[name] * 1000:.0f}" for name in sorted(worst)))
    slowest = max(worst.values())
    print(f"crashes: {crashes}; problems without line and column: {unplaced}; "
          f"slowest file {slowest * 1000:.0f} ms (limit {LIMIT_S * 1000:.0f} ms)")
    for line, times in crash_lines.most_common(10):
        print(f"  {times} x {line}")
    return crashes == 0 and unplaced == 0 and slowest < LIMIT_S


def long_lists() -> bool:
    base = json.loads((ROOT / "examples" / "small-station.moas").read_text())

    def relays(data: dict, n: int) -> None:
        data["Antennas"][0]["Control"][0]["Stations"][0]["Relays"] = list(range(n))

    def in_use(data: dict, n: int) -> None:
        data["Antennas"][0]["InUse"] = list(range(1000, 1000 + n))

    def circle(data: dict, n: int) -> None:
        data["Systems"] = [{"ID": i, "ExclusiveSystems": [(i + 1) % n]} for i in range(n)]

    ok = True
    print("long lists: items, file size, seconds, microseconds per item, problems")
    for label, grow, sizes in (("Relays", relays, (1000, 4000, 16000, 64_000)),
                               ("InUse", in_use, (1000, 4000, 16000, 64_000)),
                               ("systems circle", circle, (1000, 4000, 16000))):
        per_item = []
        for n in sizes:
            data = json.loads(json.dumps(base))
            grow(data, n)
            text = json.dumps(data, indent=1)
            started = time.perf_counter()
            result = parse_config(text, "long.moas")
            seconds = time.perf_counter() - started
            per_item.append(seconds / n)
            print(f"  {label:<14} {n:>7,} {len(text) / 1e6:5.2f} MB {seconds:7.3f} s "
                  f"{seconds / n * 1e6:6.1f} us {len(result.problems):>3}")
            ok = ok and len(result.problems) < 10
        ok = ok and per_item[-1] < 3 * per_item[0]
    return ok


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=100_000, help="mutations (default 1e5)")
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--generated", type=int, default=3,
                        help="generated stations in the corpus besides the examples")
    args = parser.parse_args()
    fuzzed = fuzz(args.count, args.seed, args.generated)
    linear = long_lists()
    print(f"verdict: {'PASS' if fuzzed and linear else 'FAIL'}")
    sys.exit(0 if fuzzed and linear else 1)


if __name__ == "__main__":
    main()
