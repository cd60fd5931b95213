"""``mypy --strict`` holds for the server core: app.py, running.py, source_intake.py, its client
backend, net/, engine/, config/."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STRICT = ["moas_gui/app.py", "moas_gui/running.py", "moas_gui/source_intake.py", "moas_gui/engine_backend.py", "moas_gui/net",
          "moas_gui/engine", "moas_gui/config", "moas_gui/errors.py"]


def test_the_server_core_is_mypy_strict_clean(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--cache-dir", str(tmp_path / "cache"),
         *STRICT],
        cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Success" in done.stdout


def test_the_server_core_has_no_any_on_its_fields() -> None:
    for name in ("moas_gui/app.py", "moas_gui/running.py", "moas_gui/source_intake.py",
                 "moas_gui/engine_backend.py"):
        text = (ROOT / name).read_text(encoding="utf-8")
        assert "Any" not in text.replace("Anything", ""), f"{name} names Any"
