"""The station builder's model on the example stations: what one edit costs.

    .venv/bin/python benchmarks/bench_builder.py [--edits 50]

For each example: opening it (read and positioned tree), one value set (the splice and
the reading again that every edit costs), undo, the checks of ``--check`` on the draft
(what the window runs a moment after each edit, off its thread), and the same with the
station plan's findings.  Times are this process's processor time (the work done, not
what else the machine runs), the median of ``--edits`` tries; the window stays
responsive as long as an edit is well under a tenth of a second on the largest example.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path

from moas_gui.builder import Document
from moas_gui.builder.checking import check_text

ROOT = Path(__file__).resolve().parent.parent


def cost(action: Callable[[], object], tries: int) -> float:
    """The median processor time of ``action``, in milliseconds."""
    times = []
    for _ in range(tries):
        started = time.process_time()
        action()
        times.append((time.process_time() - started) * 1000)
    return statistics.median(times)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--edits", type=int, default=50, help="tries of each step")
    args = parser.parse_args()
    print(f"{'example':24} {'bytes':>7} {'open':>7} {'edit':>7} {'undo':>7} {'check':>7} "
          f"{'+plan':>8}  (ms of processor time, median of {args.edits})")
    for path in sorted((ROOT / "examples").glob("*.moas")):
        doc = Document.open(path)
        where = ("Antennas", 0, "ShortName")
        edits, undos = [], []
        for n in range(args.edits):
            started = time.process_time()
            doc.set(where, f"edited {n}")
            edits.append((time.process_time() - started) * 1000)
            started = time.process_time()
            doc.undo()
            undos.append((time.process_time() - started) * 1000)
        opened = cost(lambda p=path: Document.open(p), args.edits)
        edited, undone = statistics.median(edits), statistics.median(undos)
        checked = cost(lambda d=doc, p=path: check_text(d.text, str(p), root=d.root),
                       max(1, args.edits // 5))
        planned = cost(lambda d=doc, p=path: check_text(d.text, str(p), root=d.root,
                                                        plan_seconds=30), 1)
        print(f"{path.name:24} {len(doc.text):7} {opened:7.1f} {edited:7.1f} {undone:7.1f} "
              f"{checked:7.1f} {planned:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
