"""The README's first command as a newcomer runs it: ``scripts/run-example.sh`` with no
display serves the station headless, with the browser page, and says where to look
(the page's address and the desktop client's command) before the server starts."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest
from helpers import free_port, wait_for

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="a bash script"),
]

ROOT = Path(__file__).resolve().parents[2]


def _env(tmp_path: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.update(XDG_STATE_HOME=str(tmp_path / "state"), XDG_CONFIG_HOME=str(tmp_path / "config"),
               XDG_DATA_HOME=str(tmp_path / "data"), XDG_RUNTIME_DIR=str(tmp_path / "run"),
               QT_QPA_PLATFORM="xcb", PYTHONUNBUFFERED="1")
    (tmp_path / "run").mkdir(mode=0o700)
    return env


def test_the_helper_adds_a_web_port_only_when_none_is_named() -> None:
    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, str(ROOT / "scripts" / "example_addresses.py"),
                               *args], capture_output=True, text=True, timeout=60, check=True)
    plain = run(str(ROOT / "examples" / "small-station.moas"), "--bind", "127.0.0.1")
    assert plain.stdout.split() == ["--web-port", "8080"]
    assert "http://127.0.0.1:8080/" in plain.stderr and "moas-client 127.0.0.1:12059" in plain.stderr
    assert "--bind 0.0.0.0" in plain.stderr
    named = run(str(ROOT / "examples" / "small-station.moas"), "--bind", "127.0.0.1",
                "--web-port", "9000", "--tcp-port", "9001", "--tls")
    assert named.stdout == ""
    assert "https://127.0.0.1:9000/" in named.stderr
    assert "moas-client --tls 127.0.0.1:9001" in named.stderr


def test_run_example_without_a_display_serves_the_page_and_says_where(tmp_path: Path) -> None:
    tcp, web = free_port(), free_port()
    script = subprocess.Popen(
        ["bash", str(ROOT / "scripts" / "run-example.sh"), "examples/small-station.moas",
         "--new-instance", "--tcp-port", str(tcp), "--udp-port", "0", "--web-port", str(web),
         "--rotator-program-port", str(free_port())],
        cwd=ROOT, env=_env(tmp_path), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        text=True, start_new_session=True)
    lines: list[str] = []
    try:
        assert script.stdout is not None
        for line in script.stdout:
            lines.append(line)
            if "Accepting clients" in line or len(lines) > 400:
                break
        text = "".join(lines)
        assert f"web page:        http://127.0.0.1:{web}/" in text, text
        assert f"desktop client:  .venv/bin/moas-client 127.0.0.1:{tcp}" in text, text
        assert "running the server headless" in text, text

        def page() -> bool:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=5) as answer:
                    return answer.status == 200 and b"<html" in answer.read().lower()
            except OSError:
                return False
        wait_for(page, timeout=60)
    finally:
        os.killpg(script.pid, signal.SIGTERM)
        try:
            script.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(script.pid, signal.SIGKILL)
            script.wait()
        if script.stdout is not None:
            script.stdout.close()
