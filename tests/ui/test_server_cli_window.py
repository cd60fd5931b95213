"""``moas-server FILE`` with its window, as a separate process: it opens the file at once
(what a double-click does) and ends cleanly on SIGTERM, as Exit does."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

pytestmark = pytest.mark.realtime  # real processes, end to end


def test_the_window_server_opens_its_file_and_stops_cleanly_on_sigterm(tmp_path: Path) -> None:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_CONFIG_HOME=str(tmp_path),
               PYTHONUNBUFFERED="1")
    process = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
         "--tcp-port", "0", "--udp-port", "0", "--bind", "127.0.0.1", "--udp-bind", "127.0.0.1",
         "--no-rotator-program", "--new-instance"],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        settings = tmp_path / "moas-gui" / "moas-server.conf"
        deadline = time.monotonic() + 20
        while not (settings.exists() and "small-station.moas" in settings.read_text()):
            assert process.poll() is None, process.stdout.read() if process.stdout else ""
            assert time.monotonic() < deadline, "the file never appeared in Recent Files"
            time.sleep(0.1)
        process.send_signal(signal.SIGTERM)
        output, _ = process.communicate(timeout=20)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 0, output
    assert "Traceback" not in output
