"""The model-based fault test of issue 19 at length: random interleavings of keying and
unkeying each station, band changes from the logger (N1MM RadioInfo packets),
``kill -9`` and restart of the server, the cable pulled and plugged back, stalls
(SIGSTOP, SIGCONT after longer than every link timeout), garbage, cut-short, swapped
and lost replies, silence, and a state file that cannot be written -- against
``moas-emulator`` in its own process on a pseudo-terminal and the real
``moas-server --headless --new-instance`` (its own XDG directories, the fault tests'
short switch clocks).

After every step the emulator's own record is checked: no relay of a keyed station
moved between its key and its unkey, no ``*0`` reached the box while a station was
keyed.  Now and then (and at the end) everything settles -- faults over, stations
unkeyed, the logger moves each radio once more -- and the box must then hold what the
engine says.  The rig and the checks are ``tests/faults/keyed_resync.py``; a
fixed-seed share of this walk runs in the suite
(``tests/faults/test_fault_keyed_resync.py``).

Prints the steps, the steps of each kind (the faults among them) and the violations;
exits 1 if there was any.  Linux and macOS (pseudo-terminals, signals).

Run: ``.venv/bin/python benchmarks/bench_resync_model.py [--steps 10000] [--seed N]``
(10,000 steps take about an hour; ``--steps 300`` a few minutes;
``--no-faults`` keeps to keys and band changes).
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "faults"))

from keyed_resync import FAULTS, STEPS, Figures, ModelRun, Rig


async def main(steps: int, seed: int, faults: bool, pause: float) -> Figures:
    kinds = dict(STEPS) if faults else {k: w for k, w in STEPS.items() if k not in FAULTS}
    last = [time.monotonic()]

    def progress(figures: Figures) -> None:
        if figures.steps % 250 == 0 or time.monotonic() - last[0] > 60:
            last[0] = time.monotonic()
            print(f"... {figures.steps} steps, {figures.seconds:.0f} s, "
                  f"{len(figures.violations)} violations", flush=True)

    with tempfile.TemporaryDirectory(prefix="moas-resync-") as where:
        async with Rig.up(Path(where)) as rig:
            run = ModelRun(rig, seed, kinds=kinds, pause=pause)
            return await run.run(steps, progress=progress)


def run() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=10_000)
    p.add_argument("--seed", type=int, default=None, help="default: from the clock (printed)")
    p.add_argument("--pause", type=float, default=0.15,
                   help="the most time between two steps, seconds (each is random)")
    p.add_argument("--no-faults", dest="faults", action="store_false",
                   help="keys, band changes and settling only")
    args = p.parse_args()
    seed = args.seed if args.seed is not None else int(time.time())
    print(f"seed {seed}, {args.steps} steps{'' if args.faults else ', no faults'}", flush=True)
    figures = asyncio.run(main(args.steps, seed, args.faults, args.pause))
    print(figures.report())
    print("PASS" if not figures.violations else "FAIL")
    return 0 if not figures.violations else 1


if __name__ == "__main__":
    sys.exit(run())
