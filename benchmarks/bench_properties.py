"""The wide random search behind the suite's property tests.

Run:  .venv/bin/python benchmarks/bench_properties.py [--seconds 600] [-k EXPR]

The suite runs Hypothesis derandomized (tests/conftest.py), so every run
tries the same examples.  This job runs every property test of the suite
again and again under the ``wide`` profile (random, no example database),
each round with a new seed, until the time is up.  It prints, per test, how
many examples passed, and for every failure the seed, the command that
reproduces it and Hypothesis's falsifying example: copy that example into an
``@example(...)`` on the test so the suite keeps it for good.

Exit status 1 when something failed.  Not part of the suite (it runs for
minutes); the tests it runs start no server.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import random
import re
import shlex
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PASSING = re.compile(r"(\d+) passing, (\d+) failing")
TEST_HEADER = re.compile(r"^(tests/\S+::\S+):$")


class _Collector:
    """A pytest plugin that keeps the node ids of the property tests."""

    def __init__(self) -> None:
        self.ids: list[str] = []

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        for item in session.items:
            function = getattr(item, "obj", None)
            if getattr(function, "is_hypothesis_test", False):
                self.ids.append(item.nodeid)


def property_tests(keyword: str | None) -> list[str]:
    collector = _Collector()
    quiet = io.StringIO()
    args = ["--collect-only", "-q", "-p", "no:cacheprovider", "tests"]
    if keyword:
        args += ["-k", keyword]
    with contextlib.redirect_stdout(quiet):
        code = pytest.main(args, plugins=[collector])
    if code not in (0, 5):
        raise SystemExit(f"collecting the tests failed (pytest exit {code}):\n{quiet.getvalue()}")
    return collector.ids


def run_round(ids: list[str], seed: int) -> tuple[int, str, Counter[str]]:
    env = {**os.environ, "HYPOTHESIS_PROFILE": "wide", "QT_QPA_PLATFORM": "offscreen"}
    command = [
        sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
        f"--hypothesis-seed={seed}", "--hypothesis-show-statistics", *ids,
    ]
    done = subprocess.run(
        command, check=False, cwd=ROOT, env=env, capture_output=True, text=True
    )
    passed: Counter[str] = Counter()
    current, generating = "", False
    for line in done.stdout.splitlines():
        if header := TEST_HEADER.match(line):
            current = header.group(1)
        elif "during " in line and " phase" in line:
            generating = "generate phase" in line
        elif (counts := PASSING.search(line)) and current and generating:
            passed[current] += int(counts.group(1))
    return done.returncode, done.stdout, passed


def failures(output: str) -> list[str]:
    """Each falsifying example (and its ``@reproduce_failure`` line) in
    pytest's output, without pytest's ``E`` margin."""
    found: list[str] = []
    block: list[str] | None = None
    indent = 0
    for raw in output.splitlines():
        line = raw[1:] if raw.startswith("E ") else raw
        text = line.lstrip()
        if re.match(r"(Failing test case|Falsifying (explicit )?example): ", text):
            block, indent = [text], len(line) - len(text)
        elif block is not None:
            block.append(line[indent:])
            if text == ")":
                found.append("\n".join(block))
                block = None
        elif "@reproduce_failure(" in text and found:
            found[-1] += "\n" + text
    return found


def failure_report(output: str) -> str:
    """pytest's FAILURES section, for a failure with no falsifying example
    (an error in the test itself, a health check)."""
    start = output.find("= FAILURES =")
    end = output.find("= Hypothesis Statistics =")
    return output[max(start, 0):end if end > start else None][-4000:]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=600.0, help="time budget")
    parser.add_argument("-k", dest="keyword", help="only tests matching this pytest -k expression")
    parser.add_argument("--seed", type=int, help="first seed (default: random)")
    options = parser.parse_args()

    ids = property_tests(options.keyword)
    if not ids:
        print("no property tests selected")
        return 1
    print(f"{len(ids)} property tests")
    seed = options.seed if options.seed is not None else random.randrange(2**32)
    started = time.monotonic()
    rounds = 0
    total: Counter[str] = Counter()
    failed: list[tuple[int, str]] = []
    while time.monotonic() - started < options.seconds:
        code, output, passed = run_round(ids, seed)
        rounds += 1
        total.update(passed)
        if code != 0:
            failed.append((seed, output))
            failing = re.findall(r"^FAILED (.+?)(?: - |$)", output, re.MULTILINE) or ids
            print(f"\nFAIL with seed {seed}; reproduce with:")
            print(f"  HYPOTHESIS_PROFILE=wide .venv/bin/python -m pytest -q "
                  f"--hypothesis-seed={seed} {shlex.join(failing)}")
            for text in failures(output) or [failure_report(output)]:
                print()
                print(text.rstrip())
        seed += 1
    elapsed = time.monotonic() - started
    print(f"\n{rounds} rounds in {elapsed:.0f} s, seeds from "
          f"{seed - rounds} to {seed - 1}")
    print(f"{'examples passed':>16}  test")
    for test in ids:
        print(f"{total[test]:>16}  {test}")
    print(f"{sum(total.values()):>16}  in all ({sum(total.values()) / elapsed:.0f} per second)")
    verdict = f"FAIL: {len(failed)} failing rounds" if failed else "PASS: no failure"
    print(verdict)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
