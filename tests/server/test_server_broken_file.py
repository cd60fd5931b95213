"""A broken configuration given to ``moas-server`` as a station meets it (a file cut short,
numbers no file needs): one clear message with its place, a non-zero exit, no traceback,
and a server that already runs keeps what it runs.  Real processes."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import free_port, wait_for
from test_server_instance import ask_state

pytestmark = pytest.mark.realtime

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

BROKEN = {
    "cut-after-colon": ('{"TCPPort":', "1:12: error: the file ends where a value was expected"),
    "cut-after-name": ('{"Antennas"', '1:12: error: the file ends after the name "Antennas"'),
    "huge-integer": ('{"TCPPort": ' + "7" * 5000 + "}",
                     '1:13: error: "TCPPort" of the configuration is far too large'),
    "zeros-and-exponent": ('{"TCPPort": 01e999}',
                           "1:13: error: numbers cannot have leading zeros: write 1e999"),
}


def environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
                PYTHONUNBUFFERED="1")


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_headless_on_a_broken_file_says_where_and_exits_1(tmp_path: Path, runtime_dir: Path, name: str) -> None:
    text, expected = BROKEN[name]
    path = tmp_path / f"{name}.moas"
    path.write_text(text)
    done = subprocess.run(
        [sys.executable, "-m", "moas_gui.cli.server", "--headless", "--new-instance",
         "--no-rotator-program", str(path)],
        env=environment(tmp_path, runtime_dir), capture_output=True, text=True, check=False,
        timeout=30)
    assert done.returncode == 1
    assert f"{path}:{expected}" in done.stderr
    assert "was not opened" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout


def test_a_broken_file_is_not_handed_to_the_running_server(tmp_path: Path,
                                                          runtime_dir: Path) -> None:
    env = environment(tmp_path, runtime_dir)
    tcp = free_port(socket.SOCK_STREAM)
    common = ["--headless", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
              "--no-rotator-program"]
    first = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
         *common], env=env, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: ask_state(tcp)["config"] == "small-station.moas")
        for name, (text, expected) in sorted(BROKEN.items()):
            path = tmp_path / f"{name}.moas"
            path.write_text(text)
            second = subprocess.run(
                [sys.executable, "-m", "moas_gui.cli.server", str(path), *common],
                env=env, capture_output=True, text=True, check=False, timeout=30)
            assert second.returncode == 1, second.stderr
            assert f"{path}:{expected}" in second.stderr
            assert "not handed" in second.stderr and f"handed {path}" not in second.stderr
            assert "Traceback" not in second.stderr
        assert ask_state(tcp)["config"] == "small-station.moas"
        assert first.poll() is None, "the running server keeps running"
    finally:
        first.terminate()
        _, stderr = first.communicate(timeout=15)
    assert first.returncode == 0
    assert "Traceback" not in stderr
    assert "handed over" not in stderr


def test_the_server_warns_at_load_about_a_client_allow_open_to_the_internet(
        tmp_path: Path, runtime_dir: Path) -> None:
    path = tmp_path / "open.moas"
    text = (EXAMPLES / "small-station.moas").read_text()
    path.write_text(text.replace("{\n", '{\n  "ClientAllow": ["127.0.0.1/0"],\n', 1))
    tcp = free_port(socket.SOCK_STREAM)
    server = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", "--headless", "--new-instance",
         "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--no-rotator-program", str(path)],
        env=environment(tmp_path, runtime_dir), stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: ask_state(tcp)["config"] == "open.moas")
    finally:
        server.terminate()
        _, stderr = server.communicate(timeout=15)
    assert f'{path}:2:19: warning: "ClientAllow" has "127.0.0.1/0", which lets in every ' \
           "address of the internet" in stderr
