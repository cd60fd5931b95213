"""``moas-emulator --headless`` started as a real process: the port path on
its first line, the ``--link`` name, the unit id, clean exits, bad
arguments, and a switch link that survives the emulator being stopped and a
new one started at the same ``--link`` path."""

from __future__ import annotations

import asyncio
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial  # type: ignore[import-untyped]
from helpers import until
from switch_support import Heard

from moas_gui.engine.switchstate import StationAntennas, SwitchState
from moas_gui.hw.moas2.link import LinkOptions, LinkStatus, LinkTiming, SwitchLink

SCRIPT = Path(sys.executable).with_name("moas-emulator")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "moas_gui.cli.emulator"]

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]


def start(*args: str) -> tuple[subprocess.Popen[str], str]:
    proc = subprocess.Popen(
        [*COMMAND, "--headless", *args],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    assert proc.stdout is not None
    first = proc.stdout.readline().strip()
    return proc, first


def stop(proc: subprocess.Popen[str]) -> int:
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    proc.communicate(timeout=10)  # also closes the pipes
    return proc.returncode


def talk(path: str, data: bytes, expect: int) -> bytes:
    with serial.Serial(path, 9600, timeout=0.1) as port:
        port.write(data)
        got = b""
        end = time.monotonic() + 3
        while len(got) < expect and time.monotonic() < end:
            got += port.read(expect - len(got))
        return got


def test_headless_prints_the_port_first_and_answers_on_it(tmp_path: Path) -> None:
    link = tmp_path / "moas1"
    proc, path = start("--link", str(link), "--unit-id", "5")
    try:
        assert path.startswith("/dev/")
        assert os.path.realpath(link) == os.path.realpath(path)
        assert talk(str(link), b":;';*1;';", 10) == b":1005;.;!;"
    finally:
        assert stop(proc) == 0
    assert not link.exists() and not link.is_symlink()


def test_headless_without_link_serves_its_own_port(tmp_path: Path) -> None:
    proc, path = start("--firmware", "1A2")
    try:
        assert talk(path, b":;", 6) == b":1A20;"
    finally:
        assert stop(proc) == 0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--unit-id", "100"], "--unit-id must be 0-99"),
        (["--firmware", "10"], "--firmware must be three"),
        (["--port", "/nonexistent/port"], "cannot open serial port /nonexistent/port"),
    ],
)
def test_bad_arguments_are_explained_and_exit_2(args: list[str], message: str) -> None:
    done = subprocess.run([*COMMAND, "--headless", *args], capture_output=True, text=True,
                          timeout=20, check=False)
    assert done.returncode == 2
    assert message in done.stderr


def test_a_link_path_that_is_a_real_file_is_not_replaced(tmp_path: Path) -> None:
    precious = tmp_path / "notes.txt"
    precious.write_text("keep me")
    done = subprocess.run([*COMMAND, "--headless", "--link", str(precious)],
                          capture_output=True, text=True, timeout=20, check=False)
    assert done.returncode == 2
    assert "is not a symbolic link" in done.stderr
    assert precious.read_text() == "keep me"


@pytest.mark.asyncio
async def test_link_survives_the_emulator_process_being_replaced(tmp_path: Path) -> None:
    link_path = tmp_path / "moas1"
    state = SwitchState(stations=(
        StationAntennas(tx=1, tx_relays=frozenset({1, 2}), rx=1, rx_relays=frozenset({1, 2})),
        *(StationAntennas(),) * 5,
    ))
    timing = LinkTiming(ping_interval=0.1, answer_timeout=1.0, retry_first=0.1, retry_max=0.3)
    statuses: list[LinkStatus] = []
    proc, _ = await asyncio.to_thread(start, "--link", str(link_path))
    link = SwitchLink(1, str(link_path), options=LinkOptions(timing=timing),
                      listener=Heard(status=statuses.append))
    link.apply(state)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        assert await link.ask_relays() == {1, 2}
        assert await asyncio.to_thread(stop, proc) == 0
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE)
        moved = SwitchState(stations=(
            StationAntennas(tx=2, tx_relays=frozenset({5}), rx=2, rx_relays=frozenset({5})),
            *(StationAntennas(),) * 5,
        ))
        link.apply(moved)
        proc, _ = await asyncio.to_thread(start, "--link", str(link_path))
        await until(lambda: link.status is LinkStatus.OK)
        assert await link.ask_relays() == {5}
        assert statuses == [LinkStatus.OK, LinkStatus.UNRESPONSIVE, LinkStatus.OK]
    finally:
        await link.close()
        await asyncio.to_thread(stop, proc)
