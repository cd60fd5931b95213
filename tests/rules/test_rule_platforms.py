"""The whole package type-checks for Windows and macOS as it does for Linux.

``mypy --platform win32`` (and ``darwin``) reads every ``sys.platform`` guard as that
system would: a POSIX-only call (``os.openpty``, ``AF_UNIX``, ``start_unix_server``,
``os.getuid``, ``select.poll``...) outside such a guard is an error there, which is a
crash the user would meet on that system.  Each guard raises a message saying what is
not on that system, or takes the way that is."""

from __future__ import annotations

# platform: any (the POSIX names below are only text)
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _mypy(platform: str, cache: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--platform", platform, "--cache-dir", str(cache),
         "--no-error-summary", "moas_gui"],
        cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
    )


@pytest.mark.parametrize("platform", ["win32", "darwin"])
def test_the_package_type_checks_on_each_platform(platform: str) -> None:
    """Linux's own run is as clean (``mypy moas_gui`` reports nothing), so nothing here is
    reported only for another system.  The cache is kept between runs (one per system)."""
    done = _mypy(platform, ROOT / ".mypy_cache" / f"platform-{platform}")
    assert done.returncode == 0, f"mypy --platform {platform}:\n{done.stdout}{done.stderr}"
    assert done.stdout.strip() == "", done.stdout


def test_a_posix_only_call_outside_a_guard_is_found_for_windows(tmp_path: Path) -> None:
    """The check itself can fail: an unguarded ``os.getuid`` is an error for win32 (and
    the same call behind a guard is not)."""
    module = tmp_path / "probe.py"
    module.write_text("import os\nimport sys\n\n\ndef who() -> int:\n    return os.getuid()\n\n\n"
                      "def guarded() -> int:\n    if sys.platform == 'win32':\n"
                      "        return 0\n    return os.getuid()\n", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--platform", "win32", "--cache-dir",
         str(ROOT / ".mypy_cache" / "platform-probe"), str(module)],
        capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode != 0, done.stdout
    errors = [line for line in done.stdout.splitlines() if ": error:" in line]
    assert len(errors) == 1 and "probe.py:6:" in errors[0] and "getuid" in errors[0], errors
