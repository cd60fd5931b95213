"""What ``scripts/run-example.sh`` does, as real processes: the example's serial
rotators get emulated controllers in a private directory and the server opens the
example itself, told where they are with ``--rotator-port`` (issue 30 point 6)."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import free_port, wait_for

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

ROOT = Path(__file__).resolve().parents[2]


def _state(port: int) -> dict:
    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(b'{"id": 1, "cmd": "hello", "client": "test"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("event") == "state":
                return message  # type: ignore[no-any-return]


def test_the_example_itself_runs_with_its_rotators_on_emulated_controllers(
        tmp_path: Path) -> None:
    private = tmp_path / "example-run"
    private.mkdir(mode=0o700)
    example = ROOT / "examples" / "big-station.moas"
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "example_rotators.py"),
                           str(example), str(private)],
                          capture_output=True, text=True, check=True, timeout=60)
    pids = [int(line) for line in done.stdout.split()]
    moved = (private / "rotator-ports").read_text().split()
    tcp = free_port()
    env = dict(os.environ, XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"), PYTHONUNBUFFERED="1")
    args = [sys.executable, "-m", "moas_gui.cli.server", "--headless", str(example),
            "--new-instance", "--bind", "127.0.0.1", "--udp-bind", "127.0.0.1",
            "--tcp-port", str(tcp), "--udp-port", "0",
            "--rotator-program-port", str(free_port())]
    for line in moved:
        args += ["--rotator-port", line]
    server = subprocess.Popen(args, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    try:
        def online() -> dict | None:
            try:
                state = _state(tcp)
            except OSError:
                return None
            serial = [r for r in state["rotators"] if r["id"] <= 9]
            return state if len(serial) == 9 and all(r["online"] for r in serial) else None
        state = wait_for(online, 40, "every emulated rotator online")
        # the example itself: its name, unchanged, no copy anywhere
        assert state["config"] == "big-station.moas"
        assert not (private / "big-station.moas").exists()
    finally:
        server.send_signal(signal.SIGTERM)
        output = server.communicate(timeout=30)[0]
        for pid in pids:
            os.kill(pid, signal.SIGTERM)
    assert "Traceback" not in output, output


def test_a_rotator_port_that_is_not_id_equals_device_is_refused_clearly() -> None:
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--rotator-port",
                           "two=/dev/ttyUSB1", "--check",
                           str(ROOT / "examples" / "small-station.moas")],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 2
    assert "'two=/dev/ttyUSB1' is not ID=DEVICE" in done.stderr
