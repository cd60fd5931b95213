"""Shared test set-up: Qt runs offscreen; example files are easy to find;
property tests are deterministic.

Hypothesis runs derandomized with no example database, so every run of the
suite tries the same examples: a submission cannot fail on an example nobody
wrote.  The wide random search is ``benchmarks/bench_properties.py``, which
selects the ``wide`` profile through ``HYPOTHESIS_PROFILE``; whatever it finds
becomes an explicit ``@example`` here.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

settings.register_profile("deterministic", derandomize=True, database=None, print_blob=True)
settings.register_profile("wide", derandomize=False, database=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


@pytest.fixture(autouse=True)
def _own_state_directory(tmp_path_factory: pytest.TempPathFactory,
                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test's servers save and restore their state in a directory of the test's own,
    never the user's (and never one another's)."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path_factory.mktemp("state")))
