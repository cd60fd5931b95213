"""``moas-rotator`` run as programs: an emulator and the program, end to end over TCP."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytestmark = pytest.mark.realtime

COMMAND = [sys.executable, "-m", "moas_gui.cli.rotator"]


@pytest.fixture
def processes() -> Iterator[list[subprocess.Popen[str]]]:
    started: list[subprocess.Popen[str]] = []
    try:
        yield started
    finally:
        for process in started:  # the program first, then the emulators it talks to
            if process.poll() is None:
                process.kill()
            process.communicate()


def start(processes: list[subprocess.Popen[str]], *args: str) -> tuple[subprocess.Popen[str], str]:
    process = subprocess.Popen([*COMMAND, *args], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    processes.insert(0, process)
    assert process.stdout is not None
    first = process.stdout.readline().strip()
    assert first, process.stderr.read() if process.stderr else "no output"
    return process, first


def stop(process: subprocess.Popen[str]) -> tuple[int, str]:
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=10)
    return process.returncode, err


class Lines:
    """The program's lines as they come: each wait takes up to the line it wants, and
    what came after it in the same read stays for the next wait."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock, self.data = sock, b""
        sock.settimeout(0.1)

    def until(self, wanted: str, timeout: float = 15.0) -> list[str]:
        deadline = time.monotonic() + timeout
        while True:
            *lines, rest = self.data.decode("ascii").split("\r")
            if wanted in lines:
                taken = lines[:lines.index(wanted) + 1]
                self.data = "\r".join([*lines[len(taken):], rest]).encode("ascii")
                return taken
            if time.monotonic() >= deadline:
                raise AssertionError(f"no {wanted!r} in {self.data!r}")
            try:
                self.data += self.sock.recv(4096)
            except TimeoutError:
                pass


def test_emulator_and_program_work_together_end_to_end(
        processes: list[subprocess.Popen[str]], tmp_path: Path) -> None:
    link = tmp_path / "rotator0"
    emulator, path = start(processes, "--emulate", "Yaesu", "--link", str(link),
                           "--azimuth", "42", "--speed", "100")
    assert path.startswith("/dev/") and os.path.realpath(link) == path
    program, listening = start(processes, "--bind", "127.0.0.1", "--port", "0")
    assert listening.startswith("listening on 127.0.0.1:")
    port = int(listening.rsplit(":", 1)[1])

    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(f"VERSION\rCONFIGURE 0 4 {link} 200\r".encode())
        lines = Lines(sock)
        lines.until("VERSION 0.1")
        lines.until("0 42")
        sock.sendall(b"ROTATE 0 60\r")
        lines.until("0 60")
        sock.sendall(b"ROTATE 0 oops\r")

    code, err = stop(program)
    assert code == 0
    assert "rotator 0: bad command from the server 'ROTATE 0 oops'" in err
    assert f"rotator 0 (Yaesu on {link}): port open" in err
    code, _ = stop(emulator)
    assert code == 0
    assert not link.exists()


def test_an_unknown_model_to_emulate_is_refused_with_the_list(
        processes: list[subprocess.Popen[str]]) -> None:
    result = subprocess.run([*COMMAND, "--emulate", "Hygain"], check=False, capture_output=True,
                            text=True, timeout=10)
    assert result.returncode == 2
    assert "unknown rotator model 'Hygain' (known: 1 DCU1, 2 RotorEZ" in result.stderr


def test_a_port_already_in_use_is_explained(processes: list[subprocess.Popen[str]]) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        result = subprocess.run([*COMMAND, "--bind", "127.0.0.1", "--port", str(port)],
                                check=False, capture_output=True, text=True, timeout=10)
    assert result.returncode == 2
    assert f"cannot listen on 127.0.0.1:{port}" in result.stderr
    assert "another MOAS Rotator" in result.stderr


def test_the_program_says_it_listens_once(processes: list[subprocess.Popen[str]]) -> None:
    """The server relays the program's output to its log: one announcement, not two."""
    program, listening = start(processes, "--bind", "127.0.0.1", "--port", "0")
    assert listening.startswith("listening on 127.0.0.1:")
    code, err = stop(program)
    assert code == 0, err
    assert "listening on" not in err
