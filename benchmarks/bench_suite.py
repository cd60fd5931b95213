"""Where the test suite's time goes: processor time per test file, not only wall time.

Run:  .venv/bin/python benchmarks/bench_suite.py [--top N] [--by cpu|wall|idle] [PYTEST ARGS...]

Runs the suite (or the tests named) as ``.ci/run`` does, with this file loaded into every
worker as a pytest plugin, and prints:

* the load average before and after (other work on the machine inflates every figure);
* per worker, what starting and collecting cost (processor seconds and wall seconds);
* per test file, its wall time, the processor time of the worker running it (``self``)
  and of the child processes the tests started and waited for (``children``: servers,
  emulators, ``--check`` runs ...), and ``idle``: wall minus both (sleeps, waits on
  other processes, and waits for a core);
* the slowest single tests the same way.

Wall figures lie while other work shares the cores; processor time says what a test
costs whoever else is busy.  What this cannot see: processes a test started but did not
wait for (Chromium's renderers, which chromedriver leaves to the system), so a browser
test's figure is low.  Example:  bench_suite.py --top 15 tests/net/test_web_browser.py -n 0
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Generator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
OUT = "MOAS_BENCH_SUITE_DIR"
"""Where each worker writes its lines (set by :func:`main` for the run it starts)."""

# -- the plugin, in each worker ---------------------------------------------------------

_lines: Any = None
_started = time.monotonic()


def _cpu() -> tuple[float, float]:
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, children.ru_utime + children.ru_stime


def _write(record: dict[str, Any]) -> None:
    if _lines is not None:
        _lines.write(json.dumps(record) + "\n")
        _lines.flush()


def pytest_configure(config: Any) -> None:
    global _lines
    folder = os.environ.get(OUT)
    if not folder:
        return
    worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
    _lines = open(Path(folder) / f"{worker}.jsonl", "w", encoding="utf-8")  # noqa: SIM115
    own, _ = _cpu()
    _write({"event": "configured", "worker": worker, "cpu": own,
            "wall": time.monotonic() - _started})


def pytest_collection_finish(session: Any) -> None:
    own, _ = _cpu()
    _write({"event": "collected", "cpu": own, "wall": time.monotonic() - _started})


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: Any, nextitem: Any) -> Generator[None, None, None]:
    own, children = _cpu()
    began = time.monotonic()
    yield
    own_after, children_after = _cpu()
    _write({"test": item.nodeid, "wall": time.monotonic() - began,
            "self": own_after - own, "children": children_after - children})



def pytest_unconfigure(config: Any) -> None:
    if _lines is not None:
        _lines.close()


# -- the report ---------------------------------------------------------------------------

def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def report(folder: Path, top: int, by: str) -> None:
    tests: list[dict[str, Any]] = []
    for path in sorted(folder.glob("*.jsonl")):
        events = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()]
        tests += [e for e in events if "test" in e]
        marks = {e["event"]: e for e in events if "event" in e}
        if "configured" in marks and "collected" in marks:
            start, done = marks["configured"], marks["collected"]
            print(f"{path.stem}: started in {start['wall']:.1f} s ({start['cpu']:.1f} s cpu), "
                  f"collected in {done['wall'] - start['wall']:.1f} s "
                  f"({done['cpu'] - start['cpu']:.1f} s cpu)")
    files: dict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0, 0.0])
    for test in tests:
        row = files[test["test"].split("::")[0]]
        row[0] += test["wall"]
        row[1] += test["self"]
        row[2] += test["children"]
        row[3] += 1

    def key(row: list[float]) -> float:
        cpu = row[1] + row[2]
        return {"cpu": cpu, "wall": row[0], "idle": row[0] - cpu}[by]

    total = [sum(row[i] for row in files.values()) for i in range(3)]
    print(f"\n{len(tests)} tests: wall {total[0]:.1f} s summed over the workers, "
          f"cpu {total[1] + total[2]:.1f} s (self {total[1]:.1f}, children {total[2]:.1f})")
    header = f"{'wall':>7} {'self':>6} {'child':>6} {'cpu':>6} {'idle':>7} {'tests':>5}"
    print(f"\nper file, by {by}:\n{header}  file")
    for name, row in sorted(files.items(), key=lambda kv: -key(kv[1]))[:top]:
        cpu = row[1] + row[2]
        print(f"{row[0]:7.2f} {row[1]:6.2f} {row[2]:6.2f} {cpu:6.2f} {row[0] - cpu:7.2f} "
              f"{int(row[3]):5d}  {name}")
    print(f"\nper test, by {by}:\n{header[:-6]}  test")
    for test in sorted(tests, key=lambda t: -key([t["wall"], t["self"], t["children"]]))[:top]:
        cpu = test["self"] + test["children"]
        print(f"{test['wall']:7.2f} {test['self']:6.2f} {test['children']:6.2f} {cpu:6.2f} "
              f"{test['wall'] - cpu:7.2f}  {test['test']}")


def main() -> int:
    args = sys.argv[1:]
    top, by = 25, "cpu"
    while args and args[0] in ("--top", "--by"):
        if args[0] == "--top":
            top = int(args[1])
        else:
            by = args[1]
        args = args[2:]
    if by not in ("cpu", "wall", "idle"):
        raise SystemExit("--by takes cpu, wall or idle")
    with tempfile.TemporaryDirectory(prefix="bench-suite-") as folder:
        here = str(Path(__file__).resolve().parent)
        env = dict(os.environ, **{OUT: folder})
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [here, env.get("PYTHONPATH")]))
        print(f"load average before: {_load()}")
        began = time.monotonic()
        done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                               "-p", "bench_suite", *args], cwd=ROOT, env=env, check=False)
        wall = time.monotonic() - began
        whole = resource.getrusage(resource.RUSAGE_CHILDREN)
        print(f"\nthe run: {wall:.1f} s wall, exit status {done.returncode}; "
              f"load average after: {_load()}")
        print(f"the whole run's processor time (pytest, its workers and every process they "
              f"waited for): {whole.ru_utime + whole.ru_stime:.1f} s "
              f"(user {whole.ru_utime:.1f}, system {whole.ru_stime:.1f})")
        report(Path(folder), top, by)
    return done.returncode


if __name__ == "__main__":
    sys.exit(main())
