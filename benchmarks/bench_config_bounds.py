"""The worst files for ``moas-server --check``: time and memory stay bounded.

    .venv/bin/python benchmarks/bench_config_bounds.py [--megabytes 10]

Generates a set of files, each just under the reader's size limit (10 MB), made to cost
the reader as much as possible: nesting far deeper than allowed (groups, lists, groups
with names in the wrong quotes), mistakes on every few bytes (four kinds), more values
than allowed, a valid station as large as the value limit lets it be, the same station
with one mistake at its very end, and a station padded with blanks or one long text.
Each is checked by ``moas-server --check`` as its own process; the benchmark prints
its wall time, its peak memory (resident set), the lines printed and the first problem.

The verdict is PASS when every file took under 2 s and 200 MB, printed at most a few
hundred lines, and the valid station was found valid.  The seconds judged are the
processor's (user and system) of the checking process: on the shared machine the wall
time also counts whatever else runs, and is printed beside them.  Figures:
docs/reliability.md.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from config_fuzzing import station

from moas_gui.config import parse_config
from moas_gui.config.jsontree import MAX_VALUES

LIMIT_S = 2.0
LIMIT_MB = 200.0
MAX_LINES = 400


def fill(piece: str, size: int, head: str = "{", tail: str = "") -> str:
    """``head``, then ``piece`` repeated to just under ``size`` characters, then ``tail``."""
    times = (size - len(head) - len(tail)) // len(piece)
    return head + piece * times + tail


def largest_valid_station(size: int) -> str:
    """The valid generated station with the most antennas within the value limit (and
    ``size``), written with indentation."""
    low, high = 100, 20_000
    best = station(1, antennas=low, stations=1, radios=2)
    while low < high:
        middle = (low + high + 1) // 2
        text = station(1, antennas=middle, stations=1, radios=2)
        if len(text) < size and count_values(json.loads(text)) <= MAX_VALUES \
                and parse_config(text).ok:
            low, best = middle, text
        else:
            high = middle - 1
    return best


def widest(text: str, size: int) -> str:
    """``text`` written with the deepest indentation that stays within ``size``."""
    data = json.loads(text)
    for indent in range(64, 0, -1):
        wide = json.dumps(data, indent=indent)
        if len(wide) < size:
            return wide
    return text


def count_values(value: object) -> int:
    if isinstance(value, dict):
        return 1 + sum(count_values(v) for v in value.values())
    if isinstance(value, list):
        return 1 + sum(count_values(v) for v in value)
    return 1


def files(size: int) -> dict[str, Callable[[], str]]:
    big = largest_valid_station(size)
    return {
        "deep groups": lambda: fill('{"a":', size, ""),
        "deep lists": lambda: fill("[", size, ""),
        "deep groups, names unquoted": lambda: fill("{a:", size, ""),
        "a mistake every 4 bytes": lambda: fill("a{,}", size),
        "a mistake every 2 bytes": lambda: fill("a ", size),
        "comments": lambda: fill("//\n", size),
        "missing colons": lambda: fill('"a" ', size),
        "too many values": lambda: fill("1,", size, '{"A": [', "1]}"),
        "many wrong values": lambda: fill('"x",', size, '{"Antennas": [', '"x"]}'),
        "largest valid station": lambda: big,
        "the same without blanks": lambda: json.dumps(json.loads(big), separators=(",", ":")),
        "the same, one mistake at the end": lambda: big[:-1] + ",}",
        "the same, one mistake deep inside": lambda: big.replace('"Relays": [', '"Relays": [,', 1),
        "wrong values in every antenna": lambda: re.sub(r'"ShortName": "A(\d+)"',
                                                        r'"ShortName": \1', big),
        "90,000 wrong antennas": lambda: '{"Antennas": [' + ", ".join(['"x"'] * 90_000) + "]}",
        "a station padded with blanks": lambda: fill(" ", size, big[:-1], "}"),
        "blanks between all its values": lambda: widest(big, size),
        "one long text": lambda: fill("x", size, '{"Name": "', '"}'),
    }


def check(path: Path, env: dict[str, str]) -> tuple[float, float, float, list[str], int]:
    """Wall seconds, processor seconds, peak memory in MB, printed lines and exit status
    of ``--check``."""
    started = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, "-c", _MEASURED, str(path)], env=env,
                          capture_output=True, check=False)
    seconds = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    lines = done.stdout.decode(errors="replace").splitlines()
    peak = int(done.stderr.decode().strip().splitlines()[-1].split()[1]) / 1024
    return seconds, cpu, peak, lines, done.returncode


_MEASURED = """
import sys
from moas_gui.cli.server import main
try:
    code = main(["--check", sys.argv[1]])
finally:
    # the peak of this process alone (a child's rusage would count its parent's memory)
    with open("/proc/self/status") as status:
        print([line for line in status if line.startswith("VmHWM")][0], file=sys.stderr)
sys.exit(code)
"""
"""``moas-server --check FILE`` in a process that says its own peak memory at the end."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--megabytes", type=float, default=10.0,
                        help="size of each generated file (default 10, the reader's limit)")
    args = parser.parse_args()
    size = int(args.megabytes * 1024 * 1024) - 1024
    ok = True
    worst_s = worst_cpu = worst_mb = 0.0
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, XDG_CONFIG_HOME=folder, XDG_DATA_HOME=folder,
                   XDG_STATE_HOME=folder, XDG_RUNTIME_DIR=folder)
        baseline = Path(folder) / "baseline.moas"
        baseline.write_text((ROOT / "examples" / "small-station.moas").read_text())
        seconds, cpu, megabytes, _lines, _code = check(baseline, env)
        print(f"baseline (small-station.moas): {seconds:.2f} s ({cpu:.2f} s of processor), "
              f"{megabytes:.0f} MB")
        print(f"{'file':<36} {'MB':>5} {'wall s':>6} {'cpu s':>6} {'peak MB':>7} "
              f"{'lines':>5}  first line")
        for name, make in files(size).items():
            path = Path(folder) / "worst.moas"
            path.write_text(make())
            seconds, cpu, megabytes, lines, code = check(path, env)
            worst_s, worst_mb = max(worst_s, seconds), max(worst_mb, megabytes)
            worst_cpu = max(worst_cpu, cpu)
            first = lines[0] if lines else ""
            first = first.split(": ", 1)[-1][:60] if "error" in first or "warning" in first \
                else first[:60]
            print(f"{name:<36} {path.stat().st_size / 1e6:5.2f} {seconds:6.2f} {cpu:6.2f} "
                  f"{megabytes:7.0f} {len(lines):5}  {first}")
            valid = code == 0
            ok = ok and cpu < LIMIT_S and megabytes < LIMIT_MB and len(lines) <= MAX_LINES
            if name == "largest valid station":
                ok = ok and valid
    print(f"worst: {worst_cpu:.2f} s of processor (limit {LIMIT_S:g} s), {worst_s:.2f} s of "
          f"wall time, {worst_mb:.0f} MB (limit {LIMIT_MB:g} MB)")
    print(f"verdict: {'PASS' if ok else 'FAIL'}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
