"""``mypy --strict`` holds for the server core (app.py, running.py, source_intake.py, its
client backend, net/, engine/, config/) and for the command line (cli/), the sources
(sources/) and the hardware (hw/).

One mypy run checks them all, with its cache kept between runs under the repository's
``.mypy_cache`` (as tests/rules/test_rule_platforms.py does), so a run after a small change
reads only what changed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STRICT = ["moas_gui/app.py", "moas_gui/running.py", "moas_gui/source_intake.py",
          "moas_gui/server_view.py", "moas_gui/switch_events.py", "moas_gui/antenna_feed.py",
          "moas_gui/opening.py",
          "moas_gui/engine_backend.py", "moas_gui/net", "moas_gui/engine", "moas_gui/config",
          "moas_gui/errors.py", "moas_gui/cli", "moas_gui/sources", "moas_gui/hw",
          "moas_gui/line_framer.py", "moas_gui/testing", "moas_gui/operators.py",
          "moas_gui/rights.py", "moas_gui/tls.py"]
CORE = ["moas_gui/app.py", "moas_gui/running.py", "moas_gui/source_intake.py",
        "moas_gui/engine_backend.py", "moas_gui/server_view.py", "moas_gui/switch_events.py",
        "moas_gui/antenna_feed.py", "moas_gui/opening.py"]


def test_the_strict_parts_are_mypy_strict_clean() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--cache-dir",
         str(ROOT / ".mypy_cache" / "strict"), *STRICT],
        cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Success" in done.stdout


def test_the_server_core_has_no_any_on_its_fields() -> None:
    for name in CORE:
        text = (ROOT / name).read_text(encoding="utf-8")
        assert "Any" not in text.replace("Anything", ""), f"{name} names Any"


def test_the_command_line_silences_no_type_check() -> None:
    """cli/ has no ``type: ignore``: what it calls is typed (one crept in while the
    journal it imports was being written in parallel)."""
    found = [f"{path.relative_to(ROOT)}:{number}"
             for path in sorted((ROOT / "moas_gui" / "cli").glob("*.py"))
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if "type: ignore" in line]
    assert found == [], f"type: ignore in {found}"
