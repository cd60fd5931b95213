"""``moas-server --check`` as a user runs it: a separate process, its output and exit status
(every example checked through the same ``main`` in this process, one process in all for
them: what a process adds, the exit status and the streams, the other tests see)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.cli import server

pytestmark = pytest.mark.realtime  # each check is a moas-server process

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def run_check(path: Path | str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--check", str(path)],
                          capture_output=True, text=True, check=False, timeout=60)


def test_every_example_is_usable_and_summarised(capsys: pytest.CaptureFixture[str]) -> None:
    examples = sorted(EXAMPLES.glob("*.moas"))
    assert examples, "the examples folder holds the example stations"
    first = run_check(examples[0])  # as a user runs it ...
    assert first.returncode == 0, first.stdout + first.stderr
    assert server.main(["--check", str(examples[0])]) == 0  # ... and as this test does
    assert capsys.readouterr().out == first.stdout
    for example in examples:
        status = server.main(["--check", str(example)])
        out, err = capsys.readouterr()
        assert status == 0, out + err
        assert "Switches:" in out and "Antennas per band:" in out
        assert "error" not in out


def test_a_broken_file_lists_every_problem_with_its_place_and_exits_1(tmp_path: Path) -> None:
    path = tmp_path / "broken.moas"
    path.write_text('{\n  "Switches": [ { "ID": 1, "Port": "emulator" } ]\n  "TCPPort": True\n}\n')
    done = run_check(path)
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert lines[0] == f'{path}:1:1: warning: there are no "Radios": no antenna can be selected'
    assert lines[1] == f"{path}:2:50: error: missing comma after the value that ends on line 2?"
    assert lines[2] == f"{path}:3:14: error: write true in lowercase, not True"
    assert "3 errors; the configuration cannot be used." in lines[-1]
    assert "must be a whole number, not true" in lines[3]
    assert "Traceback" not in done.stderr


def test_a_missing_file_is_one_sentence_not_a_traceback(tmp_path: Path) -> None:
    done = run_check(tmp_path / "nowhere.moas")
    assert done.returncode == 1
    assert "there is no such file" in done.stdout
    assert "Traceback" not in done.stdout + done.stderr


def test_check_without_a_file_is_a_usage_error() -> None:
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--check"],
                          capture_output=True, text=True, check=False, timeout=60)
    assert done.returncode == 2 and "needs a configuration file" in done.stderr


def test_a_client_allow_open_to_the_internet_is_a_warning_with_its_line(tmp_path: Path) -> None:
    text = (EXAMPLES / "small-station.moas").read_text()
    path = tmp_path / "open.moas"
    path.write_text(text.replace("{\n", '{\n  "ClientAllow": ["127.0.0.1/0"],\n', 1))
    done = run_check(path)
    assert done.returncode == 0, done.stdout
    assert done.stdout.splitlines()[0].startswith(
        f'{path}:2:19: warning: "ClientAllow" has "127.0.0.1/0", which lets in every address '
        "of the internet")
