"""``scripts/pi-check.sh`` tries the wheel in arm64 Debian roots under emulation; it takes
minutes and root, so ``scripts/setup.sh --test`` runs it only with ``MOAS_PI_CHECK=1``
(docs/platforms.md).  What it runs in each root, ``scripts/pi_probe.py``, is tried here on
every run against this checkout's own programs, so the probe cannot rot unseen: the
examples checked and planned, the headless server on a socat cable to the emulator, logger
band changes answered with relay bytes, no Qt in the headless server and Qt in the window
server, the service unit verified."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(not sys.platform.startswith("linux"),
                       reason="the probe reads /proc and uses socat and systemd-analyze"),
]


def test_the_setup_runs_the_pi_check_only_when_asked() -> None:
    setup = (ROOT / "scripts" / "setup.sh").read_text()
    guarded = [line for line in setup.splitlines() if "MOAS_PI_CHECK" in line
               and line.startswith("if ")]
    assert guarded == ['if [ "$want_test" = 1 ] && [ "${MOAS_PI_CHECK:-}" = 1 ]; then']
    assert (ROOT / ".ci" / "run").read_text().count("scripts/setup.sh --test") == 1
    done = subprocess.run(["bash", "-n", str(ROOT / "scripts" / "pi-check.sh")],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr


@pytest.mark.timeout(300)
def test_the_probe_passes_on_this_machine(runtime_dir: Path) -> None:
    """(The probe's folder holds the server's sockets: a short path, ``runtime_dir``.)"""
    assert shutil.which("socat") and shutil.which("systemd-analyze")
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "pi_probe.py"), "--label", "here",
         "--bin", str(BIN), "--examples", str(ROOT / "examples"),
         "--emulator", str(BIN / "moas-emulator"), "--work", str(runtime_dir / "probe"),
         "--window"],
        capture_output=True, text=True, timeout=280, check=False,
        env={k: v for k, v in os.environ.items() if not k.startswith("XDG_")})
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-4000:]
    figures = json.loads(done.stdout.rsplit("FIGURES ", 1)[1])
    assert figures["examples"] == len(list((ROOT / "examples").glob("*.moas")))
    assert figures["band_changes"] == 40 and "!" in figures["first_relay_bytes"]
    assert figures["rss_mb"] > 0 and figures["cpu_per_band_change_ms"] >= 0
    assert "no Qt library mapped into the headless server" in done.stdout
    assert "Qt libraries mapped, and stopped with status 0" in done.stdout
    assert "systemd-analyze verify --user accepts the unit" in done.stdout
