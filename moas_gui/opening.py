"""Opening a configuration file: loaded with its problems logged, and kept once it runs.

:meth:`ServerApp.open <moas_gui.app.ServerApp.open>` decides what runs; :func:`load`
reads the file (or its last good version, which :func:`opened` keeps beside its saved
state each time a file opens: :func:`~moas_gui.state_store.last_good_path`) and logs
every warning and error; :func:`opened` says it runs.
"""

from __future__ import annotations

import asyncio
import gc
import logging
import time
from pathlib import Path

from moas_gui import state_store
from moas_gui.config import LoadResult, load_config

log = logging.getLogger(__name__)


def load(path: Path, last_good: bool, carrying_on: bool) -> tuple[LoadResult, Path]:
    """``path`` loaded (``last_good``: its last good version), with the file read;
    its warnings and errors logged (``carrying_on``: a configuration runs, and will
    carry on when this one has errors)."""
    source = state_store.last_good_path(path) if last_good else path
    result = load_config(source)
    for problem in result.warnings:
        log.warning("%s", problem)
    if result.config is None:
        for problem in result.errors:
            log.error("%s", problem)
        log.error("%s was not opened: %d error%s%s", path, len(result.errors),
                  "s" if len(result.errors) != 1 else "",
                  "; the running configuration carries on" if carrying_on else "")
    return result, source


def opened(path: Path, source: Path, last_good: bool, started: float) -> None:
    """``path`` runs (since ``started``, a ``time.perf_counter()``), loaded from
    ``source``: said in the log; a file that opened is kept as its last good version
    (off the loop and not waited for: opening is done when the ports listen)."""
    log.info("Opened %s in %.0f ms", path.name, (time.perf_counter() - started) * 1000)
    if last_good:
        log.warning("RUNNING THE LAST GOOD VERSION of %s (kept %s): the file itself "
                    "has errors; fix it, then Restart", path,
                    time.strftime("%Y-%m-%d %H:%M", time.localtime(source.stat().st_mtime)))
    else:
        asyncio.get_running_loop().run_in_executor(None, state_store.keep_last_good, path)


def settle_garbage() -> None:
    """Once a configuration runs: freeze every object alive (the program's modules, the
    configuration, its engine and parts), so that Python's cyclic collector no longer
    scans them at each full collection (about 40,000 objects: 19 ms a full collection,
    on the loop, before; under 0.2 ms after).  The first opening leaves no garbage to
    freeze (reading a file makes no cycles); at a later one, what an earlier one froze
    is unfrozen and collected first, so the closed configuration's cycles are freed
    rather than kept (one full collection, at the opening)."""
    if gc.get_freeze_count():
        gc.unfreeze()
        gc.collect()
    gc.freeze()


__all__ = ["load", "opened", "settle_garbage"]
