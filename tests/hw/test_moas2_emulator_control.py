"""``moas-emulator --headless --control``: keying stations without a window, from
another process, through a Unix socket, a TCP port on 127.0.0.1 or standard
input; the relays, the status and the record read the same way; and the info
log's relay lines with the key states."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial  # type: ignore[import-untyped]

SCRIPT = Path(sys.executable).with_name("moas-emulator")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "moas_gui.cli.emulator"]

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals and Unix sockets"),
]


class Emulator:
    """A ``moas-emulator --headless`` process and the lines it printed."""

    def __init__(self, *args: str, stdin: bool = False) -> None:
        self.proc = subprocess.Popen(
            [*COMMAND, "--headless", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            stdin=subprocess.PIPE if stdin else subprocess.DEVNULL, text=True)
        assert self.proc.stdout is not None
        self.port = self.proc.stdout.readline().strip()
        self.control = ""
        while not self.control:
            line = self.proc.stdout.readline()
            assert line, "the emulator ended: " + self.stop_and_read()
            if line.startswith("control at "):
                self.control = line.split("control at ", 1)[1].strip()

    def stop_and_read(self) -> str:
        if self.proc.poll() is None:
            self.proc.terminate()
        _, err = self.proc.communicate(timeout=10)
        return err


class Line:
    """One control connection, line by line."""

    def __init__(self, where: str) -> None:
        if where.startswith("127.0.0.1:"):
            self.sock = socket.create_connection(("127.0.0.1", int(where.rsplit(":", 1)[1])))
        else:
            self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            self.sock.connect(where)
        self.sock.settimeout(10)
        self.file = self.sock.makefile("r", encoding="utf-8")

    def ask(self, command: str) -> str:
        self.sock.sendall(command.encode() + b"\n")
        return self.read()

    def read(self) -> str:
        line = self.file.readline()
        assert line, "the control connection closed"
        return line.rstrip("\n")

    def record(self, after: int = 0) -> list[dict]:
        self.sock.sendall(f"record {after}\n".encode())
        entries = []
        while (line := self.read()).startswith("record "):
            entries.append(json.loads(line.split(" ", 1)[1]))
        assert line.startswith("end "), line
        return entries

    def close(self) -> None:
        self.file.close()
        self.sock.close()


def write_box(port: str, data: bytes) -> None:
    """Commands to the box on its serial port, and wait for the ping's answer
    (``!;`` active, ``.;`` inactive): every command before it is carried out."""
    with serial.Serial(port, 9600, timeout=0.1) as line:
        line.reset_input_buffer()
        line.write(data + b"';")
        got = b""
        end = time.monotonic() + 10
        while not got.endswith((b"!;", b".;")) and time.monotonic() < end:
            got += line.read(64)
        assert got.endswith((b"!;", b".;")), got


def test_a_station_keyed_through_a_unix_socket_holds_its_relays_and_the_record_says_so(
        tmp_path: Path, request: pytest.FixtureRequest) -> None:
    where = tmp_path / "moas1.ctl"
    emulator = Emulator("--control", str(where), "--log-level", "info")
    try:
        assert emulator.control == str(where)
        line = Line(emulator.control)
        request.addfinalizer(line.close)
        write_box(emulator.port, b"*1;&1;!1B112;")
        assert line.ask("relays") == "relays 1 2 (active)"
        assert line.ask("key 1") == "ok key 1"
        write_box(emulator.port, b"!1B234;")  # wait mode: held while station 1 transmits
        assert line.ask("relays") == "relays 1 2 (active, keyed 1)"
        status = json.loads(line.ask("status").split(" ", 1)[1])
        assert status["keyed"] == [1] and status["stations"][0]["pending"] == ["T2"]
        assert line.ask("unkey 1") == "ok unkey 1"
        assert line.ask("relays") == "relays 3 4 (active)"
        write_box(emulator.port, b"*0;")
        entries = line.record()
        events = [(e["event"], e["cause"], e["relays"], e["keyed"]) for e in entries]
        assert events == [
            ("relays", "!1B112;", [1, 2], []),
            ("key", "key 1", [1, 2], [1]),
            ("key", "unkey 1", [3, 4], []),
            ("reset", "*0;", [3, 4], []),
            ("relays", "*0;", [], []),
        ]
        assert [e["seq"] for e in entries] == [1, 2, 3, 4, 5]
        assert line.record(after=4)[0]["seq"] == 5
    finally:
        err = emulator.stop_and_read()
    assert emulator.proc.returncode == 0
    assert not where.exists()  # the socket goes with the emulator
    assert "relays 1 2 (active, keyed 1)" in err
    assert "reset (*0;) received" in err


def test_watch_streams_every_new_entry_and_a_reset_under_a_key_is_logged(
        request: pytest.FixtureRequest) -> None:
    emulator = Emulator("--control", "0", "--log-level", "info")
    try:
        assert emulator.control.startswith("127.0.0.1:")
        watcher, keyer = Line(emulator.control), Line(emulator.control)
        request.addfinalizer(watcher.close)
        request.addfinalizer(keyer.close)
        assert watcher.ask("watch") == "ok watch"
        assert keyer.ask("key 2") == "ok key 2"
        write_box(emulator.port, b"*0;")
        seen = [json.loads(watcher.read().split(" ", 1)[1]) for _ in range(2)]
        assert [(e["event"], e["keyed"]) for e in seen] == [("key", [2]), ("reset", [2])]
    finally:
        err = emulator.stop_and_read()
    assert "reset (*0;) received while station 2 was keyed" in err


def test_standard_input_takes_the_same_commands_and_bad_ones_are_explained() -> None:
    emulator = Emulator("--control", "-", stdin=True)
    assert emulator.control == "-"
    proc = emulator.proc
    assert proc.stdin is not None and proc.stdout is not None
    try:
        proc.stdin.write("key 3\nrelays\nkey 7\nflip 1\nunkey 3\nrecord\n")
        proc.stdin.flush()
        replies = [proc.stdout.readline().strip() for _ in range(8)]
        assert replies[:5] == [
            "ok key 3",
            "relays none (inactive, keyed 3)",
            "error key takes one station number, 1-6 (got '7')",
            replies[3],
            "ok unkey 3",
        ]
        assert replies[3].startswith("error unknown command 'flip 1'")
        assert [json.loads(r.split(" ", 1)[1])["cause"] for r in replies[5:7]] == [
            "key 3", "unkey 3"]
        assert replies[7] == "end 2"
        assert proc.poll() is None  # bad commands leave it running
    finally:
        emulator.stop_and_read()
    assert proc.returncode == 0


def test_a_control_path_that_is_a_real_file_is_not_replaced(tmp_path: Path) -> None:
    precious = tmp_path / "notes.txt"
    precious.write_text("keep me")
    done = subprocess.run([*COMMAND, "--headless", "--control", str(precious)],
                          capture_output=True, text=True, timeout=20, check=False)
    assert done.returncode == 2
    assert f"cannot listen for --control at {precious}" in done.stderr
    assert "not a socket" in done.stderr
    assert precious.read_text() == "keep me"
