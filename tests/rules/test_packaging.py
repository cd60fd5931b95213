"""What an installation of moas-gui holds and needs: the package's files and its requirements."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from helpers import wait_for
from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[2]


def pyside_allows(version: str, python: str) -> bool:
    """Whether the declared requirements let ``version`` of PySide6 install under ``python``."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    environment = {"python_version": python, "python_full_version": f"{python}.0"}
    wanted = [Requirement(text) for text in project["dependencies"]]
    applying = [r for r in wanted if r.name == "PySide6-Essentials"
                and (r.marker is None or r.marker.evaluate(environment))]
    assert len(applying) == 1, f"exactly one PySide6 requirement applies under {python}"
    return applying[0].specifier.contains(version)


def test_pyside_6_12_0_is_excluded_only_for_python_3_11() -> None:
    assert not pyside_allows("6.12.0", "3.11")
    for python in ("3.12", "3.13", "3.14"):
        assert pyside_allows("6.12.0", python)
    for python in ("3.11", "3.12", "3.13"):
        assert pyside_allows("6.11.3", python) and pyside_allows("6.12.1", python)
        assert not pyside_allows("6.5.3", python)


def test_the_oldest_pyside_allowed_is_the_oldest_tried() -> None:
    """6.8.0.2: what pip gives a Raspberry Pi OS bookworm (glibc 2.36, Python 3.11), tried
    there under emulation and with the suite's fast tier (docs/platforms.md)."""
    for python in ("3.11", "3.12", "3.13"):
        assert pyside_allows("6.8.0.2", python)
        assert not pyside_allows("6.8.0.1", python) and not pyside_allows("6.7.3", python)


def test_the_examples_manual_and_icons_are_installed_with_the_package(tmp_path: Path) -> None:
    source = tmp_path / "source"
    source.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(ROOT / name, source / name)
    ignore = shutil.ignore_patterns("__pycache__")
    shutil.copytree(ROOT / "moas_gui", source / "moas_gui", ignore=ignore)
    shutil.copytree(ROOT / "examples", source / "examples", ignore=ignore)
    built = tmp_path / "built"
    done = subprocess.run([sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(built)],
                          cwd=source, capture_output=True, text=True, check=False, timeout=120)
    assert done.returncode == 0, done.stderr
    installed = built / "moas_gui" / "examples"
    shipped = sorted(p.name for p in installed.iterdir())
    wanted = sorted(p.name for p in (ROOT / "examples").iterdir() if p.suffix in (".moas", ".md"))
    assert shipped == wanted and "big-station.moas" in shipped
    assert (installed / "big-station.moas").read_bytes() == \
        (ROOT / "examples" / "big-station.moas").read_bytes()
    assert (built / "moas_gui" / "resources" / "icons" / "application-x-moas.svg").is_file()
    for name in ("index.html", "app.js", "compass.js", "style.css"):  # the browser client
        assert (built / "moas_gui" / "resources" / "web" / name).is_file(), name
    assert (built / "moas_gui" / "config" / "loader.py").is_file()
    assert not (built / "examples").exists(), "no top-level package named examples"
    # Help > Manual opens the manual installed with the package
    manual = built / "moas_gui" / "manual"
    assert sorted(p.name for p in manual.glob("*.md")) == \
        sorted(p.name for p in (ROOT / "docs").glob("*.md"))
    assert (manual / "images" / "server-window.png").is_file()


def test_the_readme_runs_an_example_from_the_source_folder() -> None:
    readme = (ROOT / "README.md").read_text()
    assert "bash scripts/run-example.sh examples/big-station.moas" in readme
    assert (ROOT / "examples" / "big-station.moas").is_file()


@pytest.mark.realtime
def test_the_examples_rotator_links_go_into_the_runs_private_directory(tmp_path: Path) -> None:
    from moas_gui.config import RotatorControl, load_config

    private = tmp_path / "run"
    private.mkdir(mode=0o700)
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "example_rotators.py"),
                           str(ROOT / "examples" / "big-station.moas"), str(private)],
                          capture_output=True, text=True, check=True, timeout=60)
    pids = [int(line) for line in done.stdout.split()]
    try:
        config = load_config(ROOT / "examples" / "big-station.moas").config
        assert config is not None
        serial = {r.id for r in config.rotators if r.control is RotatorControl.SERIAL}
        moved = dict(line.split("=", 1)
                     for line in (private / "rotator-ports").read_text().splitlines())
        assert {int(i) for i in moved} == serial and len(pids) == 9
        assert all(Path(link).parent == private for link in moved.values())
        wait_for(lambda: all(Path(link).exists() for link in moved.values()), 20,
                 "every emulator's link")
        assert f"on {private}/moas-rotator-1" in done.stderr
        assert not (private / "big-station.moas").exists(), "the example is not copied"
    finally:
        for pid in pids:
            os.kill(pid, signal.SIGTERM)
    script = (ROOT / "scripts" / "run-example.sh").read_text()
    assert "--bind 127.0.0.1" in script and 'chmod 700 "$private"' in script
    assert 'opened="$example"' in script  # the example itself, never a copy
    assert '--rotator-port "$line"' in script
    assert "python -m moas_gui.ui.display" in script
