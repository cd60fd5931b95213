"""A port named for another system is a warning at its place that says what this system
calls such a port (moas_gui.config.ports), and ``moas-server --check`` shows it."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from moas_gui.cli import server
from moas_gui.config import Severity
from moas_gui.config.loader import parse_config
from moas_gui.config.ports import WHAT_IT_IS_CALLED, foreign_port, system_of

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("port, system", [
    ("COM8", "win32"), ("com12", "win32"), (r"\\.\COM17", "win32"),
    ("/dev/ttyUSB0", "linux"), ("/dev/ttyACM1", "linux"), ("/dev/ttyS0", "linux"),
    ("/dev/serial/by-id/usb-FTDI_FT232R-if00-port0", "linux"), ("/dev/ttyAMA0", "linux"),
    ("/dev/cu.usbserial-A10K5TQZ", "darwin"), ("/dev/tty.usbmodem1421", "darwin"),
    ("emulator", None), ("COM", None), ("COM0", None), ("/tmp/moas-port", None),
    ("rfc2217://tower:4000", None),
])
def test_whose_name_a_port_is(port: str, system: str | None) -> None:
    assert system_of(port) == system


@pytest.mark.parametrize("port, platform, told", [
    ("COM8", "linux", "Linux calls them /dev/ttyUSB0"),
    ("COM8", "darwin", "macOS calls them /dev/cu.usbserial"),
    ("/dev/ttyUSB0", "win32", "Windows calls serial ports COM1"),
    ("/dev/cu.usbserial-A1", "win32", "Windows calls serial ports COM1"),
    ("/dev/cu.usbserial-A1", "linux", "Linux calls them"),
    ("/dev/ttyUSB0", "darwin", "macOS calls them"),
    ("COM8", "win32", None), ("/dev/ttyUSB0", "linux", None),
    ("/dev/cu.usbserial-A1", "darwin", None), ("emulator", "win32", None),
    ("COM8", "freebsd14", "Linux calls them"),
])
def test_what_is_told_about_a_port_on_each_system(port: str, platform: str,
                                                  told: str | None) -> None:
    said = foreign_port(port, platform)
    if told is None:
        assert said is None
    else:
        assert said is not None and told in said and f'"{port}"' in said


def station(switch_port: str, otrsp_port: str = "", rotator: dict | None = None) -> str:
    data = json.loads((EXAMPLES / "small-station.moas").read_text(encoding="utf-8"))
    data["Switches"][0]["Port"] = switch_port
    if otrsp_port:
        data["OTRSP"] = [{"Station": 1, "Port": otrsp_port}]
    if rotator is not None:
        data["Rotators"] = [rotator]
    return json.dumps(data, indent=2)


def port_warnings(text: str, platform: str) -> list[str]:
    result = parse_config(text, "station.moas", platform=platform)
    assert result.config is not None, result.problems  # a warning, never an error
    return [str(p) for p in result.problems
            if p.severity is Severity.WARNING and "port name" in p.message]


def test_a_windows_file_on_linux_is_warned_at_each_port_with_its_line() -> None:
    text = station("COM8", otrsp_port="COM9")
    warnings = port_warnings(text, "linux")
    lines = text.splitlines()
    assert len(warnings) == 2, warnings
    for warning, name in zip(sorted(warnings, key=lambda w: "OTRSP" in w), ("COM8", "COM9"),
                             strict=True):
        line = int(warning.split(":")[1])
        assert f'"{name}"' in lines[line - 1], (warning, lines[line - 1])
    assert warnings[0].startswith("station.moas:") and "switch 1" in warnings[0]
    assert port_warnings(text, "win32") == []


def test_a_linux_file_on_windows_is_warned() -> None:
    warnings = port_warnings(station("/dev/ttyUSB0"), "win32")
    assert len(warnings) == 1 and WHAT_IT_IS_CALLED["win32"] in warnings[0]


def test_a_rotator_port_counts_only_when_its_program_runs_here() -> None:
    local = {"ID": 1, "Control": "Serial", "Address": "127.0.0.1", "CommPort": "COM4",
             "Model": "4"}
    far = dict(local, Address="192.168.1.40")  # a Windows PC at the tower: its own names
    assert any("rotator 1" in w for w in port_warnings(station("emulator", rotator=local),
                                                       "linux"))
    assert port_warnings(station("emulator", rotator=far), "linux") == []


def test_check_says_what_this_computer_calls_the_port(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """On whatever system the suite runs: a name of another one is warned about, the file
    stays usable (exit status 0).  ``moas-server --check`` runs in this process (what it
    says is the test; tests/config/test_config_fuzz.py runs it as a process)."""
    here = "win32" if sys.platform == "win32" else "darwin" if sys.platform == "darwin" \
        else "linux"
    foreign = "/dev/ttyUSB0" if here == "win32" else "COM8"
    path = tmp_path / "from-elsewhere.moas"
    path.write_text(station(foreign), encoding="utf-8")
    capsys.readouterr()
    status = server.main(["--check", str(path)])
    out, err = capsys.readouterr()
    assert status == 0, out + err
    warned = [line for line in out.splitlines() if "port name" in line]
    assert len(warned) == 1, out
    assert warned[0].startswith(f"{path}:") and ": warning: switch 1: " in warned[0]
    assert WHAT_IT_IS_CALLED[here] in warned[0]
