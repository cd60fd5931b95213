"""The engine's property job at benchmark size: random operator events on every example
station and on generated stations, every rule of ``tests/engine_invariants.py`` checked
after every event, plus the appendix F differential test on generated stations.

Run:  .venv/bin/python benchmarks/bench_engine_properties.py [--events N] [--seed S]

At least 10^5 events by default, more than half of them on generated multi-operator
stations (shared transmit antennas, partners, alternate paths, alternate antennas, sub
receivers: ``engine_stations.multiop_station``), 40 % on the ones of issue 29 (every radio
with an ``Alternate`` rule whose alternate is a ``SharedTX`` antenna interlocked radios
transmit on, three or more radios on one antenna now and then: ``shared_alternates``)
-- 30 % since issue 39, whose stations take 10 %: partners each with a sub receiver of one
of the three kinds (its own port; riding on the main radio's port with or without
``PersistSubReceiver``: ``partner_subs``), evenings that press the partners onto the shared
transmit and receive antennas and the sub receivers onto receive antennas.
Prints events, refusals and time per station kind, how many stations used each feature,
how many checks of each multi-operator rule actually ran and after how many events, and
the violations (0), and exits with status 1 (naming the rule and the events that broke it)
on the first failure.  The line "shared alternate armed" counts the events after which a
receiver was switched to its alternate (the switch's ``@`` list) by a radio transmitting
then, while that alternate (or its rule's antenna) was an antenna radios may share; the
three lines in brackets after "partner alternate beside sub" count, per kind of sub
receiver, the checks that found it beside its partner's alternate.  The normal test suite
runs a fast,
derandomized subset of the same checks.
"""

from __future__ import annotations

import argparse
import random
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "engine"))

from collections import Counter

from engine_invariants import MULTIOP_RULES, Facts, Op, operations, replay_matches, run_evening
from engine_stations import (
    features,
    frequencies_for,
    generated_station,
    multiop_station,
    partner_sub_evening,
)
from test_engine_appendix_f_differential import compare

from moas_gui.config import load_config
from moas_gui.config.model import Config

EXAMPLES = ["2x6", "small-station", "big-station", "tribander-stack", "multi-multi-20",
            "triplexer", "ms-one-amp", "two-op-shared-tx"]
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
    share_examples = args.events * 25 // 100
    share_generated = args.events * 10 // 100
    share_multiop = args.events * 15 // 100
    share_shared_alt = args.events * 30 // 100
    share_partner_subs = args.events * 10 // 100
    share_differential = (args.events - share_examples - share_generated - share_multiop
                          - share_shared_alt - share_partner_subs)
    total = refused = 0
    counts: Counter[str] = Counter()
    applied: Counter[str] = Counter()
    used: Counter[str] = Counter()
    multiop_events = 0
    print(f"{'job':<26}{'events':>9}{'refused':>9}{'seconds':>9}{'us/event':>10}")
    try:
        for name in EXAMPLES:
            cfg = configs[name]
            start = time.perf_counter()
            n = r = 0
            while n < share_examples // len(EXAMPLES):
                ops = list(operations(cfg, random.Random(rng.random()), EVENING))
                r += run_evening(cfg, ops, facts[name], counts, applied)
                n += len(ops)
            assert replay_matches(cfg, ops), f"{name}: the same events gave another result"
            took = time.perf_counter() - start
            print(f"{name:<26}{n:>9}{r:>9}{took:>9.1f}{took / n * 1e6:>10.0f}")
            total += n
            refused += r
        start = time.perf_counter()
        n = r = stations = 0
        for job, make, share in (("generated", generated_station, share_generated),
                                 ("multi-operator", multiop_station, share_multiop),
                                 ("shared alternates", _shared_alternates, share_shared_alt),
                                 ("partner sub receivers", _partner_subs, share_partner_subs)):
            start = time.perf_counter()
            n = r = stations = 0
            while n < share:
                seed = rng.random()
                station_rng = random.Random(seed)
                cfg = make(station_rng)
                found = features(cfg)
                used.update(found)
                if make is _shared_alternates:
                    ops = _listening_evening(cfg, station_rng)
                elif make is _partner_subs:
                    ops = partner_sub_evening(cfg, station_rng, EVENING)
                else:
                    ops = list(operations(cfg, station_rng, EVENING, frequencies_for(cfg)))
                try:
                    r += run_evening(cfg, ops, counts=counts, applied=applied)
                except AssertionError as err:
                    raise AssertionError(f"{job} station (seed {seed!r}): {err}") from err
                n += len(ops)
                if {"SharedTX", "alternate paths"} <= found:
                    multiop_events += len(ops)
                stations += 1
            took = time.perf_counter() - start
            print(f"{f'{job} ({stations})':<26}{n:>9}{r:>9}{took:>9.1f}"
                  f"{took / n * 1e6:>10.0f}")
            total += n
            refused += r
        start = time.perf_counter()
        n = stations = 0
        while n < share_differential:
            compare(rng.randrange(2**32), 100)
            n += 100
            stations += 1
        took = time.perf_counter() - start
        print(f"{f'appendix F ({stations})':<26}{n:>9}{0:>9}{took:>9.1f}{took / n * 1e6:>10.0f}")
        total += n
    except AssertionError as err:
        print(f"FAILED: {err}")
        return 1
    print(f"{'total':<26}{total:>9}{refused:>9}   every rule held after every event")
    print(f"\nevents on multi-operator stations: {multiop_events} of {total} "
          f"({multiop_events / total:.0%})")
    print(f"{'stations using':<36}{'stations':>9}")
    for feature, number in sorted(used.items()):
        print(f"{feature:<36}{number:>9}")
    print(f"\n{'multi-operator rule':<52}{'checks':>9}{'events':>9}{'violations':>12}")
    for rule in MULTIOP_RULES:
        counted_only = rule == "shared alternate armed" or rule.startswith("(")
        print(f"{rule:<52}{counts[rule]:>9}{applied[rule]:>9}{'-' if counted_only else 0:>12}")
    return 0


def _shared_alternates(rng: random.Random) -> Config:
    return multiop_station(rng, shared_alternates=True)


def _partner_subs(rng: random.Random) -> Config:
    return multiop_station(rng, partner_subs=True)


def _listening_evening(cfg: Config, rng: random.Random) -> list[Op]:
    """An evening on a station of issue 29: frequencies in its configured ranges only and
    fewer presses (most of a random press is refused), so that radios share a band and
    transmit while others listen."""
    ops = operations(cfg, rng, EVENING, frequencies_for(cfg, only_configured=True))
    return [op for op in ops if op[0] not in ("select", "relative", "function")
            or rng.random() < 0.3]


if __name__ == "__main__":
    sys.exit(main())
