"""How much work the engine's decision is, counted in machine instructions, not time.

Run:  .venv/bin/python benchmarks/bench_engine_instructions.py --compare REV [--ops N]

On a shared machine the wall-clock and CPU-time figures of ``bench_engine.py`` move by
10-30 % from one run to the next, far more than a change to the engine's code does.
This counts the instructions a run executes under valgrind (cachegrind, no cache
simulation), which does not depend on the other load: the same operations on five
examples (band changes, tuning and button presses, from a fixed seed), once with no
operation and once with ``--ops`` per example, so start-up cancels out (a plain run
first compiles the modules, so neither counted run compiles any).  Both trees run with
the same hash seed.  Needs ``valgrind``; takes about a minute per tree.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_engine import tree_at  # the same extraction of an older revision

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ("small-station", "ms-one-amp", "triplexer", "big-station", "multi-multi-20")

OPERATIONS = """
import random, sys
from pathlib import Path
from moas_gui.config import load_config
from moas_gui.engine import Engine, EngineError
n = int(sys.argv[1])
bands = [(1800, 2000), (3500, 4000), (7000, 7300), (14000, 14350), (21000, 21450),
         (28000, 29700)]
for name in %r:
    cfg = load_config(Path(%r) / "examples" / f"{name}.moas").unwrap()
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios() if cfg.radio(v.station, v.radio)]
    antennas = [a.id for a in cfg.antennas]
    rng = random.Random(7)
    now = 0.0
    for _ in range(n):
        now += 0.05
        s, r = rng.choice(radios)
        k = rng.random()
        try:
            if k < 0.4:
                e.set_frequency(s, r, rng.uniform(*rng.choice(bands)), now=now)
            elif k < 0.7:
                e.set_frequency(s, r, 14025.0 + rng.random() * 5, now=now)
            else:
                e.select(s, r, rng.choice(antennas), exclusive=rng.random() < 0.2, now=now)
        except EngineError:
            pass
"""


def instructions(tree: Path, ops: int, workdir: Path, counted: bool = True) -> int:
    """Instructions of one run of the operations with the engine of ``tree`` (with
    ``counted`` False: a plain run, which leaves the compiled modules for the next)."""
    script = workdir / "operations.py"
    script.write_text(OPERATIONS % (EXAMPLES, str(ROOT)), encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(tree), PYTHONHASHSEED="0",
               PYTHONPYCACHEPREFIX=str(workdir / "pycache" / tree.name))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    valgrind = ["valgrind", "--tool=cachegrind", "--cache-sim=no",
                "--cachegrind-out-file=/dev/null"] if counted else []
    done = subprocess.run(valgrind + [sys.executable, str(script), str(ops)],
                          env=env, cwd=workdir, capture_output=True, text=True, check=True)
    if not counted:
        return 0
    found = re.search(r"I\s+refs:\s+([\d,]+)", done.stderr)
    if found is None:
        raise SystemExit(f"valgrind printed no instruction count:\n{done.stderr[-2000:]}")
    return int(found.group(1).replace(",", ""))


def per_operation(tree: Path, ops: int, workdir: Path) -> float:
    """Instructions per operation: both counted runs find every module compiled (by a
    first plain run), so neither pays for compiling what the other does not."""
    instructions(tree, ops, workdir, counted=False)
    started = instructions(tree, 0, workdir)
    return (instructions(tree, ops, workdir) - started) / (ops * len(EXAMPLES))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", metavar="REV", required=True,
                        help="the git revision to count against (say, the commit before a change)")
    parser.add_argument("--ops", type=int, default=400, help="operations per example")
    args = parser.parse_args()
    if shutil.which("valgrind") is None:
        raise SystemExit("valgrind is not installed")
    with tempfile.TemporaryDirectory(prefix="moas-instructions-") as tmp:
        base = tree_at(args.compare, Path(tmp))
        before = per_operation(base, args.ops, Path(tmp))
        after = per_operation(ROOT, args.ops, Path(tmp))
    print(f"instructions per engine operation ({args.ops} per example on "
          f"{', '.join(EXAMPLES)}; band changes, tuning, presses)")
    print(f"before ({args.compare}) {before:10,.0f}")
    print(f"after (this tree)  {after:10,.0f}   {(after / before - 1) * 100:+.1f} %")


if __name__ == "__main__":
    main()
