"""How long the station plan takes: ``moas-server --plan`` on every example.

Run:  .venv/bin/python benchmarks/bench_plan.py [--repeat N]

Prints, per example, the best time of the plan made in this process (every scenario on a
fresh copy of a new engine, and the findings) and of the whole command as a user runs it
(a new process: Python starting, the file read, the plan printed).
Target: big-station under 2 s for the whole command.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

from moas_gui.plan import plan_file

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print("best of", args.repeat, "runs; scenarios = radios alone and pairs, band by band")
    for path in sorted((ROOT / "examples").glob("*.moas")):
        inside = float("inf")
        plan = None
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            plan, error = plan_file(path)
            inside = min(inside, time.perf_counter() - t0)
            assert plan is not None, error
        command = float("inf")
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--plan", str(path)],
                           check=True, capture_output=True)
            command = min(command, time.perf_counter() - t0)
        assert plan is not None
        scenarios = len(plan.alone) + sum(len(s) for _a, _b, _m, s in plan.pairs)
        print(f"{path.stem:18} {len(plan.bands):2} bands {scenarios:4} scenarios "
              f"{len(plan.findings):3} findings | plan {inside:6.3f} s | "
              f"moas-server --plan {command:6.3f} s")


if __name__ == "__main__":
    main()
