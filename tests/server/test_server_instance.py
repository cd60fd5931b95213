"""A second ``moas-server FILE`` hands FILE to the server that runs instead of fighting
it for the serial ports: two real processes."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import free_port, wait_for

pytestmark = pytest.mark.realtime

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def ask_state(port: int) -> dict:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 1:
                return message["result"]  # type: ignore[no-any-return]


def start_headless(tmp_path: Path, runtime: Path, name: str = "small-station") -> tuple[
        subprocess.Popen[str], dict[str, str], list[str], int]:
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path),
               PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")
    tcp = free_port(socket.SOCK_STREAM)
    common = ["--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
              "--no-rotator-program"]
    first = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / f"{name}.moas"),
         "--headless", *common], env=env, stderr=subprocess.PIPE, text=True)
    wait_for(lambda: ask_state(tcp)["config"] == f"{name}.moas")
    return first, env, common, tcp


def second_launch(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args],
                          env=env, capture_output=True, text=True, check=False, timeout=30)


def stop(first: subprocess.Popen[str]) -> str:
    first.terminate()
    _, stderr = first.communicate(timeout=15)
    assert first.returncode == 0, stderr
    return stderr


def test_a_headless_server_is_never_taken_over_by_a_double_click(tmp_path: Path,
                                                                 runtime_dir: Path) -> None:
    first, env, common, tcp = start_headless(tmp_path, runtime_dir)
    try:
        for args in ([str(EXAMPLES / "big-station.moas")],                 # a double-click
                     [str(EXAMPLES / "2x6.moas"), "--headless", *common]):  # another service
            second = second_launch(env, *args)
            assert second.returncode != 0, second.stderr
            assert "refused" in second.stderr and "headless" in second.stderr, second.stderr
            assert ask_state(tcp)["config"] == "small-station.moas"
        assert first.poll() is None, "the headless server keeps running"
    finally:
        stderr = stop(first)
    assert "Refused a hand-over" in stderr and "Another moas-server handed over" not in stderr


def test_a_refused_window_launch_shows_the_reason_in_a_message_window(
        tmp_path: Path, runtime_dir: Path) -> None:
    first, env, _common, tcp = start_headless(tmp_path, runtime_dir)
    try:
        double_click = [str(EXAMPLES / "big-station.moas")]
        for args, what in ((double_click, "big-station.moas was not opened"),
                           ([], "no window opened")):  # a menu entry: no file
            second = second_launch(env, *args)
            assert second.returncode == 1, second.stderr
            lines = second.stderr.splitlines()
            refusal = next(line for line in lines if line.startswith("moas-server: "))
            assert refusal.startswith(f"moas-server: {what}: the moas-server that is already "
                                      "running refused: it runs small-station.moas headless")
            assert "stop it first" in refusal
            assert "moas-server: showed a message window" in second.stderr, second.stderr
            assert "None" not in second.stderr, second.stderr
        assert ask_state(tcp)["config"] == "small-station.moas"
    finally:
        stop(first)


def test_a_window_launch_without_a_display_says_so_instead_of_aborting(
        tmp_path: Path, runtime_dir: Path) -> None:
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime_dir), XDG_CONFIG_HOME=str(tmp_path),
               DISPLAY=":917", WAYLAND_DISPLAY="")
    env.pop("QT_QPA_PLATFORM", None)
    for display in (":917", ""):
        env["DISPLAY"] = display
        done = second_launch(env, str(EXAMPLES / "small-station.moas"), "--new-instance",
                             "--no-rotator-program", "--tcp-port", "0", "--bind", "127.0.0.1")
        assert done.returncode == 1, (done.returncode, done.stderr)
        assert done.stderr.startswith(f"moas-server: cannot open the display {display}".rstrip()
                                      ), done.stderr
        assert "--headless" in done.stderr and "xcb" not in done.stderr.split(";")[0]


def test_a_broken_or_missing_file_is_refused_by_the_new_process_alone(
        tmp_path: Path, runtime_dir: Path) -> None:
    first, env, _common, tcp = start_headless(tmp_path, runtime_dir)
    broken = tmp_path / "broken.moas"
    broken.write_text('{"Switches": [}')
    try:
        for path, why in ((broken, "broken.moas:1"), (tmp_path / "missing.moas", "missing.moas")):
            second = second_launch(env, str(path))
            assert second.returncode != 0
            assert why in second.stderr and "goes on untouched" in second.stderr, second.stderr
            assert "Traceback" not in second.stderr
            assert "where the lines below say" in second.stderr, "what to do"
            assert "moas-server --check" not in second.stderr  # no command to a double-click
            assert "moas-server: showed a message window" in second.stderr
        assert ask_state(tcp)["config"] == "small-station.moas"
    finally:
        stderr = stop(first)
    assert "hand-over" not in stderr, "the running server never heard of the bad files"


def test_new_instance_does_not_hand_over(tmp_path: Path, runtime_dir: Path) -> None:
    runtime = runtime_dir
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime))
    broken = tmp_path / "broken.moas"
    broken.write_text("{")
    done = subprocess.run(
        [sys.executable, "-m", "moas_gui.cli.server", "--headless", "--new-instance", str(broken)],
        env=env, capture_output=True, text=True, check=False, timeout=30)
    assert done.returncode == 1
    assert "never closed" in done.stderr and "Traceback" not in done.stderr


@pytest.mark.parametrize(("module", "words"), [
    ("moas_gui.cli.client", "moas-client --headless"),
    ("moas_gui.cli.emulator", "--headless"),
])
def test_the_other_window_programs_say_when_there_is_no_display(
        tmp_path: Path, module: str, words: str) -> None:
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path), DISPLAY=":917", WAYLAND_DISPLAY="")
    env.pop("QT_QPA_PLATFORM", None)
    done = subprocess.run([sys.executable, "-m", module], env=env, capture_output=True,
                          text=True, check=False, timeout=30)
    assert done.returncode == 1, (done.returncode, done.stderr)
    assert "cannot open the display :917: no X server answers there" in done.stderr
    assert words in done.stderr and "Aborted" not in done.stderr
