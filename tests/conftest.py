"""Shared test set-up: Qt runs offscreen; example files are easy to find;
property tests are deterministic.

Hypothesis runs derandomized with no example database, so every run of the
suite tries the same examples: a submission cannot fail on an example nobody
wrote.  The wide random search is ``benchmarks/bench_properties.py``, which
selects the ``wide`` profile through ``HYPOTHESIS_PROFILE``; whatever it finds
becomes an explicit ``@example`` here.
"""

from __future__ import annotations

import gc
import itertools
import os
import re
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers import short_runtime_dir

# Hypothesis loads the plugins other packages register (trio's, installed for Selenium):
# none is used here, and finding and loading them cost every worker 0.08 s of processor time.
os.environ.setdefault("HYPOTHESIS_NO_PLUGINS", "1")
from hypothesis import settings

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

# The suite runs on several workers and starts many Python processes (servers,
# emulators, the rotator program): let them all keep compiled bytecode, and the
# rewritten test modules, instead of compiling everything again in each one.
sys.dont_write_bytecode = False
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

# no deadline: a wall-clock limit per example fails on a busy machine, not on a wrong result
settings.register_profile("deterministic", derandomize=True, database=None, print_blob=True,
                         deadline=None)
settings.register_profile("wide", derandomize=False, database=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


_TESTS_RUN = itertools.count()


@pytest.fixture(autouse=True)
def _own_state_directory(tmp_path_factory: pytest.TempPathFactory,
                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test's servers save and restore their state in a directory of the test's own,
    never the user's (and never one another's), and their antenna journals
    (moas_gui.antenna_log) in one of its own too.

    Numbered by a counter of the worker's, not by ``mktemp``, which lists the whole
    temporary folder to find the next number: with a few thousand tests a worker, that
    listing cost seconds of processor time in all."""
    own = tmp_path_factory.getbasetemp() / "xdg" / str(next(_TESTS_RUN))
    (own / "state").mkdir(parents=True)
    (own / "data").mkdir()
    monkeypatch.setenv("XDG_STATE_HOME", str(own / "state"))
    monkeypatch.setenv("XDG_DATA_HOME", str(own / "data"))


@pytest.fixture
def runtime_dir() -> Iterator[Path]:
    """A private XDG_RUNTIME_DIR with a short path (the server's sockets live there, and a
    socket path must stay under about 100 bytes, which a parallel run's tmp_path may not)."""
    path = short_runtime_dir()
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)



def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The slow tests (real processes, real clocks) are shared out among the workers and
    run first: xdist's ``worksteal`` hands each worker one contiguous share of the list,
    so each share starts with its part of the slow tests and the quick ones fill the
    rest, instead of one worker ending the run alone on a long test picked up last.
    The slow tests marked ``shared`` stay together, one after another on one worker:
    those of one module (they share what a module-scoped fixture started), or with
    ``shared(NAME)`` all those of that name (the worker's Chromium: :func:`chromium`)."""
    slow = [item for item in items if item.get_closest_marker("realtime") is not None]
    quick = [item for item in items if item.get_closest_marker("realtime") is None]
    workers = getattr(config, "workerinput", {}).get("workercount", 1)
    groups: dict[object, list[pytest.Item]] = {}
    for item in slow:
        shared = item.get_closest_marker("shared")
        key = item if shared is None else shared.args[0] if shared.args else item.module
        groups.setdefault(key, []).append(item)
    dealt: list[list[pytest.Item]] = [[] for _ in range(workers)]
    for group in groups.values():  # each to the worker with the fewest so far
        min(dealt, key=len).extend(group)
    ordered: list[pytest.Item] = []
    left = len(items)
    for worker in range(workers):  # the sizes worksteal's first split gives each worker
        share = left // (workers - worker)
        left -= share
        part = dealt[worker]
        take = max(0, share - len(part))
        ordered += part + quick[:take]
        quick = quick[take:]
    items[:] = ordered + quick



@pytest.fixture(scope="session")
def chromium(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """One headless Chromium for a worker's browser tests (starting one costs seconds of
    processor time); they are marked ``shared("chromium")`` so that one worker runs them
    one after another, and each cleans it first (``tests/web_station.py``'s ``blank``)."""
    from web_station import chrome

    driver = chrome(tmp_path_factory.mktemp("chromium"))
    try:
        yield driver
    finally:
        driver.quit()


@pytest.fixture
def browser(chromium: Any) -> Iterator[Any]:
    """The worker's Chromium, clean and at the first size (1024x600) before and after."""
    from web_station import blank

    blank(chromium)
    try:
        yield chromium
    finally:
        blank(chromium)  # the page leaves, so its server sees it go


# -- what some test modules need of the system -------------------------------------------
#
# On a system without it (the CI's Windows and macOS runners), such a module is skipped
# whole, with the reason in the report, and its tests carry the mark (``-m "not posix"``).

POSIX_ONLY = re.compile(
    r"PtyEndpoint|EmulatorHost|openpty|^import (?:pty|tty|termios|fcntl|resource)\b|"
    r"--emulate|/dev/pts|pty_bench|fault_harness|"
    r"^from faults|socat|AF_UNIX|start_unix_server|SIGHUP|SIGKILL|getuid|/proc/|"
    r"make_link|serve_control", re.MULTILINE)
"""What a module uses that only POSIX systems have: pseudo-terminals, Unix sockets, POSIX
signals, /proc.  Looked for in each module's text, so a new test is marked by itself."""
ANY_PLATFORM = "# platform: any"
"""A module holding this line only speaks of such things (in text): it runs everywhere."""
NEEDS_PROGRAMS: dict[str, tuple[str, ...]] = {
    "test_web_browser.py": ("chromium", "chromedriver"),
}
"""Modules that need programs installed (besides those that check for themselves)."""


def cannot_run_on(path: Path, platform: str = sys.platform) -> tuple[str, str] | None:
    """The mark and the reason the test module at ``path`` cannot run on ``platform``
    (this system by default), or None."""
    if platform == "win32":
        text = path.read_text(encoding="utf-8", errors="replace")
        used = sorted({m.group(0).split()[-1] for m in POSIX_ONLY.finditer(text)})
        if used and ANY_PLATFORM not in text:
            return "posix", f"POSIX only (uses {', '.join(used[:4])}): not on Windows"
    missing = [tool for tool in NEEDS_PROGRAMS.get(path.name, ()) if shutil.which(tool) is None]
    if missing:
        return "programs", f"needs {' and '.join(missing)}, not installed here"
    return None


class _SkippedModule(pytest.Module):
    """A test module this system cannot run: reported as skipped, with the reason."""

    reason = ""

    def collect(self) -> list[pytest.Item]:
        raise pytest.skip.Exception(self.reason, allow_module_level=True)


def pytest_pycollect_makemodule(module_path: Path, parent: pytest.Collector) -> Any:
    why = cannot_run_on(module_path) if module_path.name.startswith("test_") else None
    if why is None:
        return None
    module = _SkippedModule.from_parent(parent, path=module_path)
    module.reason = why[1]
    module.add_marker(why[0])
    return module


QT_FIXTURES = frozenset({"qapp", "qtbot"})


def pytest_collection_finish(session: pytest.Session) -> None:
    """What collection loaded (modules, Qt's wrappers) is kept out of later collections,
    so the collection after each Qt test costs a few milliseconds, not tens."""
    gc.collect()
    gc.freeze()


@pytest.fixture(autouse=True)
def _qt_garbage_collected_on_the_main_thread(request: pytest.FixtureRequest) -> Iterator[None]:
    """While a Qt test runs, no other thread it starts (an emulator's pump, a server's
    writer, Selenium) may collect garbage: a Qt object freed off Qt's thread leaves its
    timers behind, and they fire on freed memory later, a crash in a later test.  Its
    garbage is collected here, on the main thread, when it ends (the window programs
    do the same: moas_gui/ui/main_thread_gc.py)."""
    if QT_FIXTURES.isdisjoint(request.fixturenames):
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        gc.collect()
        gc.enable()
