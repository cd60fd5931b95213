"""qasync runs on PySide6 even where another Qt binding is installed (a logger such as
not1mm brings PyQt6, which qasync would otherwise pick first)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ASK = ("from moas_gui.ui.qt import load_qasync; q = load_qasync(); "
       "print(q.QtModuleName)")

pytestmark = pytest.mark.realtime  # real processes, end to end


def test_qasync_is_loaded_on_pyside6_beside_a_pyqt6(tmp_path: Path) -> None:
    fake = tmp_path / "PyQt6"
    fake.mkdir()
    (fake / "__init__.py").write_text("")  # importable: qasync would take it
    env = dict(os.environ, PYTHONPATH=str(tmp_path), QT_API="pyqt6")
    plain = subprocess.run([sys.executable, "-c", "import qasync; print(qasync.QtModuleName)"],
                           env=env, capture_output=True, text=True, timeout=60, check=False)
    assert "PyQt6" in plain.stdout + plain.stderr, "the fake binding is what qasync would use"
    ours = subprocess.run([sys.executable, "-c", ASK], env=env, capture_output=True,
                          text=True, timeout=60, check=True)
    assert ours.stdout.strip() == "PySide6"
