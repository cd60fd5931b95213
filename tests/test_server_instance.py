"""A second ``moas-server FILE`` hands FILE to the server that runs instead of fighting
it for the serial ports: two real processes."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def free_port(kind: int) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def ask_state(port: int) -> dict:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 1:
                return message["result"]  # type: ignore[no-any-return]


def wait_for(condition: object, timeout: float = 15.0) -> None:
    end = time.monotonic() + timeout
    while True:
        try:
            if condition():  # type: ignore[operator]
                return
        except OSError:
            pass
        if time.monotonic() > end:
            raise AssertionError("condition not met in time")
        time.sleep(0.1)


def test_a_second_launch_hands_its_file_to_the_running_server(tmp_path: Path) -> None:
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700)
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), PYTHONUNBUFFERED="1")
    tcp = free_port(socket.SOCK_STREAM)
    common = ["--headless", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
              "--no-rotator-program"]
    first = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
         *common], env=env, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: ask_state(tcp)["config"] == "small-station.moas")
        second = subprocess.run(
            [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "2x6.moas"), *common],
            env=env, capture_output=True, text=True, check=False, timeout=30)
        assert second.returncode == 0, second.stderr
        assert "handed" in second.stderr and "already running" in second.stderr
        wait_for(lambda: ask_state(tcp)["config"] == "2x6.moas")
        assert first.poll() is None, "the first server keeps running"
    finally:
        first.terminate()
        _, stderr = first.communicate(timeout=15)
    assert first.returncode == 0
    assert "Another moas-server handed over" in stderr


def test_new_instance_does_not_hand_over(tmp_path: Path) -> None:
    runtime = tmp_path / "runtime"
    runtime.mkdir(mode=0o700)
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime))
    broken = tmp_path / "broken.moas"
    broken.write_text("{")
    done = subprocess.run(
        [sys.executable, "-m", "moas_gui.cli.server", "--headless", "--new-instance", str(broken)],
        env=env, capture_output=True, text=True, check=False, timeout=30)
    assert done.returncode == 1
    assert "never closed" in done.stderr and "Traceback" not in done.stderr
