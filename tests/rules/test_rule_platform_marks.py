"""Which test modules the Windows and macOS runners skip, and why (tests/conftest.py)."""

from __future__ import annotations

# platform: any (the POSIX names below are only text)
from pathlib import Path

from conftest import cannot_run_on

TESTS = Path(__file__).resolve().parents[1]


def test_modules_using_pseudo_terminals_or_posix_signals_are_skipped_on_windows() -> None:
    mark, reason = cannot_run_on(TESTS / "hw" / "test_moas2_link.py", "win32") or ("", "")
    assert mark == "posix" and "PtyEndpoint" in reason and "not on Windows" in reason
    mark, reason = cannot_run_on(TESTS / "server" / "test_clean_stop.py", "win32") or ("", "")
    assert mark == "posix" and "SIGHUP" in reason
    assert cannot_run_on(TESTS / "hw" / "test_moas2_link.py", "linux") is None
    assert cannot_run_on(TESTS / "hw" / "test_moas2_link.py", "darwin") is None


def test_modules_that_need_nothing_special_run_everywhere() -> None:
    for name in ("config/test_config_ports.py", "server/test_places.py",
                 "ui/test_desktop_windows.py", "engine/test_engine_api.py",
                 "rules/test_rule_platforms.py", "rules/test_rule_platform_marks.py"):
        for platform in ("win32", "darwin", "linux"):
            assert cannot_run_on(TESTS / name, platform) is None, (name, platform)


def test_on_windows_most_of_the_suite_still_runs() -> None:
    modules = sorted(TESTS.glob("*/test_*.py"))
    skipped = [m.name for m in modules if cannot_run_on(m, "win32") is not None]
    assert len(skipped) < len(modules) / 2, skipped
