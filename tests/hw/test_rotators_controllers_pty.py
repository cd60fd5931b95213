"""The emulator host: emulators served on real pseudo-terminals, read through pyserial."""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import serial  # type: ignore[import-untyped]

from moas_gui.hw.rotators.controllers.models import find_model
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost

pytestmark = pytest.mark.realtime


@pytest.fixture
def host() -> Iterator[EmulatorHost]:
    with EmulatorHost() as running:
        yield running


def read_until(port: serial.Serial, end: bytes, timeout: float = 2.0) -> bytes:
    data = b""
    deadline = time.monotonic() + timeout
    while not data.endswith(end) and time.monotonic() < deadline:
        data += port.read(port.in_waiting or 1)
    return data


def test_an_emulator_answers_through_a_pseudo_terminal(host: EmulatorHost) -> None:
    served = host.add(find_model("Yaesu").make_emulator(azimuth=123.0))
    with serial.Serial(served.path, 9600, timeout=0.2) as port:
        port.write(b"C2\r")
        assert read_until(port, b"\r\n") == b"AZ=123  EL=000\r\n"


def test_the_link_points_at_the_pseudo_terminal_and_goes_away_with_it(
        host: EmulatorHost, tmp_path: Path) -> None:
    link = tmp_path / "rotator"
    served = host.add(find_model("RotorEZ").make_emulator(azimuth=45.0), link=str(link))
    assert os.path.realpath(link) == served.path
    with serial.Serial(str(link), 4800, timeout=0.2) as port:
        port.write(b"AI1;")
        assert read_until(port, b"045") == b";045"
    host.remove(served)
    assert not link.exists()


def test_unsolicited_reports_come_out_while_turning(host: EmulatorHost) -> None:
    served = host.add(find_model("RC2800P-A").make_emulator(azimuth=0.0, speed=100.0,
                                                            now=host.clock()))
    with serial.Serial(served.path, 9600, timeout=0.2) as port:
        port.write(b"A\r90\r")
        data = read_until(port, b"A P=  90.0 S=9 ST\n\r", timeout=4.0)
    assert data.count(b"MV") >= 5
    assert data.endswith(b"A P=  90.0 S=9 ST\n\r")


def test_a_removed_port_fails_its_reader(host: EmulatorHost) -> None:
    served = host.add(find_model("Yaesu").make_emulator())
    with serial.Serial(served.path, 9600, timeout=0.2) as port:
        host.remove(served)
        with pytest.raises((serial.SerialException, OSError)):
            for _ in range(5):
                port.write(b"C\r")
                port.read(10)


def test_call_moves_the_antenna_by_hand_from_another_thread(host: EmulatorHost) -> None:
    served = host.add(find_model("Prosistel D").make_emulator(azimuth=10.0))
    host.call(served, lambda emulator, now: emulator.turn_by_hand(250.0, now))
    with serial.Serial(served.path, 9600, timeout=0.2) as port:
        port.write(b"\x02A?\r")
        assert read_until(port, b"\r") == b"\x02A,?,250,R\r"
