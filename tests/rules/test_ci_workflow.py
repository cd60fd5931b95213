"""The CI workflow (.github/workflows/ci.yml) cannot run here; it is checked here: against
GitHub's workflow schema (check-jsonschema's copy, offline) and by zizmor's security
audits (offline), and for what it must do (the suite on three systems, the frozen app)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WORKFLOW = ROOT / ".github" / "workflows" / "ci.yml"
BIN = Path(sys.executable).parent


def tool(name: str) -> str:
    found = shutil.which(name, path=str(BIN)) or shutil.which(name)
    assert found, f"{name} is installed by the test extra (pyproject.toml)"
    return found


def check_schema(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([tool("check-jsonschema"), "--builtin-schema",
                           "vendor.github-workflows", str(path)],
                          capture_output=True, text=True, timeout=120, check=False)


def audit(path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([tool("zizmor"), "--offline", "--no-progress", str(path)],
                          capture_output=True, text=True, timeout=120, check=False)


def test_the_workflow_fits_githubs_schema() -> None:
    done = check_schema(WORKFLOW)
    assert done.returncode == 0, done.stdout + done.stderr


def test_zizmor_finds_nothing_in_the_workflow() -> None:
    done = audit(WORKFLOW)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "No findings" in done.stdout + done.stderr


def test_both_checks_can_fail(tmp_path: Path) -> None:
    text = WORKFLOW.read_text(encoding="utf-8")
    unpinned = tmp_path / "unpinned.yml"
    unpinned.write_text(text.replace(
        "actions/checkout@11bd71901bbe5b1630ceea73d27597364c9af683", "actions/checkout@v4"),
        encoding="utf-8")
    done = audit(unpinned)
    assert done.returncode != 0 and "unpinned-uses" in done.stdout + done.stderr
    broken = tmp_path / "broken.yml"
    broken.write_text(text.replace("runs-on: ${{ matrix.os }}", "runs-onn: ${{ matrix.os }}", 1),
                      encoding="utf-8")
    done = check_schema(broken)
    assert done.returncode != 0, done.stdout


@pytest.mark.parametrize("wanted", [
    "os: [ubuntu-latest, windows-latest, macos-latest]",
    "bash scripts/setup.sh --test",
    ".venv/bin/python -m pytest -q -p no:cacheprovider",
    ".venv/Scripts/python -m pytest -q -p no:cacheprovider",
    "bash scripts/build-frozen.sh",
    "actions/upload-artifact@",
    "persist-credentials: false",
])
def test_the_workflow_runs_the_suite_and_builds_the_frozen_app(wanted: str) -> None:
    assert wanted in WORKFLOW.read_text(encoding="utf-8")
