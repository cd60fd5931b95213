"""A second ``moas-server FILE`` hands FILE to the server that runs instead of fighting
it for the serial ports: two real processes."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from helpers import free_port, wait_for
from logged_server import LoggedServer, module_server

pytestmark = [pytest.mark.realtime, pytest.mark.shared]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def ask_state(port: int) -> dict:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 1:
                return message["result"]  # type: ignore[no-any-return]


class First(LoggedServer):
    """The headless server a second launch meets: started once for the tests of this module
    that take :func:`first` (none of them changes what it runs)."""

    def __init__(self, root: Path, runtime: Path, name: str = "small-station") -> None:
        env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(root),
                   PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")
        tcp = free_port(socket.SOCK_STREAM)
        self.common = ["--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
                       "--no-rotator-program"]
        super().__init__([sys.executable, "-m", "moas_gui.cli.server",
                          str(EXAMPLES / f"{name}.moas"), "--headless", *self.common], env, tcp)
        wait_for(lambda: ask_state(self.tcp)["config"] == f"{name}.moas")


@pytest.fixture(scope="module")
def started(tmp_path_factory: pytest.TempPathFactory) -> Iterator[First]:
    yield from module_server(First, tmp_path_factory, "first")


@pytest.fixture
def first(started: First) -> First:
    """The module's headless server, still running what it started with; what it says
    from here on is the test's (:meth:`First.said`)."""
    started.begin()
    assert ask_state(started.tcp)["config"] == "small-station.moas"
    return started


def second_launch(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args],
                          env=env, capture_output=True, text=True, check=False, timeout=30)


def test_a_headless_server_is_never_taken_over_by_a_double_click(first: First) -> None:
    for args in ([str(EXAMPLES / "big-station.moas")],                      # a double-click
                 [str(EXAMPLES / "2x6.moas"), "--headless", *first.common]):  # another service
        second = second_launch(first.env, *args)
        assert second.returncode != 0, second.stderr
        assert "refused" in second.stderr and "headless" in second.stderr, second.stderr
        assert ask_state(first.tcp)["config"] == "small-station.moas"
    assert first.process.poll() is None, "the headless server keeps running"
    stderr = first.said()
    assert "Refused a hand-over" in stderr and "Another moas-server handed over" not in stderr


def test_a_refused_window_launch_shows_the_reason_in_a_message_window(first: First) -> None:
    double_click = [str(EXAMPLES / "big-station.moas")]
    for args, what in ((double_click, "big-station.moas was not opened"),
                       ([], "no window opened")):  # a menu entry: no file
        second = second_launch(first.env, *args)
        assert second.returncode == 1, second.stderr
        lines = second.stderr.splitlines()
        refusal = next(line for line in lines if line.startswith("moas-server: "))
        assert refusal.startswith(f"moas-server: {what}: the moas-server that is already "
                                  "running refused: it runs small-station.moas headless")
        assert "stop it first" in refusal
        assert "moas-server: showed a message window" in second.stderr, second.stderr
        assert "None" not in second.stderr, second.stderr
    assert ask_state(first.tcp)["config"] == "small-station.moas"


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
        tmp_path: Path, first: First) -> None:
    broken = tmp_path / "broken.moas"
    broken.write_text('{"Switches": [}')
    for path, why in ((broken, "broken.moas:1"), (tmp_path / "missing.moas", "missing.moas")):
        second = second_launch(first.env, str(path))
        assert second.returncode != 0
        assert why in second.stderr and "goes on untouched" in second.stderr, second.stderr
        assert "Traceback" not in second.stderr
        assert "where the lines below say" in second.stderr, "what to do"
        assert "moas-server --check" not in second.stderr  # no command to a double-click
        assert "moas-server: showed a message window" in second.stderr
    assert ask_state(first.tcp)["config"] == "small-station.moas"
    assert "hand-over" not in first.said(), "the running server never heard of the bad files"


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
