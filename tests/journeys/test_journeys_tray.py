"""Journey with a real system tray: the server window under a virtual X display
(Xvfb) with a tray (trayer).  Closing the window hides it to the tray and the
server keeps serving; Exit in the tray menu ends the process within 2 s.

Needs the Debian packages xvfb and trayer (scripts/screenshots.sh lists them);
without them this journey is skipped and says so."""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers import wait_for
from test_journeys_server import Server, normal

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(
        shutil.which("Xvfb") is None or shutil.which("trayer") is None,
        reason="needs Xvfb and trayer (apt-get install xvfb trayer)"),
]


@pytest.fixture
def x_display(tmp_path: Path) -> Iterator[str]:
    number = 140
    while Path(f"/tmp/.X11-unix/X{number}").exists() or Path(f"/tmp/.X{number}-lock").exists():
        number += 1
    display = f":{number}"
    started: list[subprocess.Popen[bytes]] = []
    try:
        started.append(subprocess.Popen(
            ["Xvfb", display, "-screen", "0", "1280x800x24", "-nolisten", "tcp"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        wait_for(lambda: Path(f"/tmp/.X11-unix/X{number}").exists(), 10, "Xvfb")
        started.append(subprocess.Popen(
            ["trayer", "--edge", "bottom", "--align", "right", "--SetDockType", "true"],
            env=dict(os.environ, DISPLAY=display),
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        time.sleep(0.5)  # the tray claims its selection
        yield display
    finally:
        for process in reversed(started):
            process.terminate()
            process.wait(timeout=10)


def test_close_hides_to_the_tray_and_tray_exit_ends_the_server(
        tmp_path: Path, x_display: str) -> None:
    server = Server(tmp_path)
    server.env.update(QT_QPA_PLATFORM="xcb", DISPLAY=x_display)
    try:
        server.start("small-station.moas")
        seen = server.shows(normal("small-station.moas"), "small-station running", timeout=20)
        wait_for(lambda: server.look()["tray_visible"], 10, "the tray icon")
        assert seen["window_visible"]
        assert server.ask(do="close")["ok"]
        seen = server.shows(lambda s: not s["window_visible"], "the window hidden to the tray")
        assert "Show Window" in seen["tray_menu"]
        assert server.config() == "small-station.moas", "the server keeps serving"
        assert server.process is not None and server.process.poll() is None
        server.click("Tray", "Show Window")
        server.shows(lambda s: s["window_visible"], "the window back")
        server.click("Tray", "Exit")
        assert server.ends() == 0
        out = server.output()
        assert server.process.returncode == 0, out
        assert "Traceback" not in out
    finally:
        server.stop()
