"""``--require-token`` closes every port, the rotctld ports too (their protocol has no
token): a real ``moas-server`` whose rotator has a rotctld-compatible port, reached from
127.0.0.1 (this computer) and from 127.0.0.2 and 127.0.0.3, which play the LAN (only
127.0.0.1 and ::1 count as this computer).  ``--rotctld-allow`` lets listed addresses
back in."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import EXAMPLES, free_port, wait_for

pytestmark = pytest.mark.realtime

HOST = "127.0.0.1"


def start(tmp_path: Path, runtime: Path, *options: str) -> tuple[subprocess.Popen[bytes], int,
                                                                    Path]:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    port = free_port(socket.SOCK_STREAM)
    data["Rotators"][0]["RotctldPort"] = port
    station = tmp_path / "station.moas"
    station.write_text(json.dumps(data))
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
               XDG_STATE_HOME=str(tmp_path / "state"), PYTHONUNBUFFERED="1")
    log = tmp_path / "server.log"
    with log.open("w") as sink:
        process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.server", str(station), "--headless",
             "--bind", HOST, "--tcp-port", str(free_port(socket.SOCK_STREAM)),
             "--udp-port", "0", "--no-rotator-program", "--new-instance", *options],
            env=env, stderr=sink, stdout=subprocess.DEVNULL)
    try:
        wait_for(lambda: answered(port, HOST), timeout=60, what="the rotctld port")
    except BaseException:
        stop(process)
        raise
    return process, port, log


def stop(process: subprocess.Popen[bytes]) -> None:
    process.terminate()
    try:
        process.wait(timeout=15)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait(timeout=15)


def answered(port: int, source: str) -> bool:
    """A rotctld ``_`` (get_info) from ``source`` is answered; ``False`` when the
    connection is closed without an answer."""
    with socket.create_connection((HOST, port), timeout=30,
                                  source_address=(source, 0)) as conn:
        try:
            conn.sendall(b"_\n")
            return conn.recv(1024) != b""
        except ConnectionError:
            return False


def test_require_token_leaves_the_rotctld_ports_to_this_computer(
        tmp_path: Path, runtime_dir: Path) -> None:
    process, port, log = start(tmp_path, runtime_dir, "--require-token")
    try:
        assert answered(port, HOST)
        assert not answered(port, "127.0.0.2")
        assert not answered(port, "127.0.0.3")
        assert answered(port, HOST)  # and this computer is still served
    finally:
        stop(process)
    text = log.read_text()
    assert "The rotctld ports take only this computer (--require-token" in text
    refusals = [line for line in text.splitlines() if "Refused a rotctld connection" in line]
    assert len(refusals) == 1 and "127.0.0.2" in refusals[0], refusals
    assert "--rotctld-allow" in refusals[0]


def test_rotctld_allow_lets_listed_addresses_in_and_no_others(
        tmp_path: Path, runtime_dir: Path) -> None:
    process, port, log = start(tmp_path, runtime_dir, "--require-token",
                               "--rotctld-allow", "127.0.0.2,10.0.0.0/8")
    try:
        assert answered(port, "127.0.0.2")
        assert not answered(port, "127.0.0.3")
        assert answered(port, HOST)
    finally:
        stop(process)
    assert "this computer and 127.0.0.2, 10.0.0.0/8 (--rotctld-allow)" in log.read_text()


def test_without_require_token_the_rotctld_ports_take_whoever_reaches_them(
        tmp_path: Path, runtime_dir: Path) -> None:
    process, port, log = start(tmp_path, runtime_dir)
    try:
        assert answered(port, "127.0.0.2")
    finally:
        stop(process)
    assert "Refused a rotctld connection" not in log.read_text()
