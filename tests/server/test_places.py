"""Where the files go on each system (moas_gui.places), the output of a program that has
no console, and a rename that Windows refuses for a moment (moas_gui.files)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path, PurePosixPath, PureWindowsPath

import platformdirs.windows
import pytest

from moas_gui import files, places
from moas_gui.state_store import state_dir

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def test_linux_follows_the_xdg_directories(monkeypatch: pytest.MonkeyPatch,
                                           tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "xdg-state"))
    assert places.state_dir("linux") == tmp_path / "xdg-state" / "moas-gui"
    assert places.log_dir("linux") == tmp_path / "xdg-state" / "moas-gui" / "log"
    assert state_dir() == places.state_dir()  # the state store asks here
    monkeypatch.delenv("XDG_STATE_HOME")
    monkeypatch.setenv("HOME", "/home/op")
    assert places.state_dir("linux") == Path("/home/op/.local/state/moas-gui")


def test_macos_uses_the_library_folders(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("HOME", "/Users/op")
    monkeypatch.delenv("XDG_STATE_HOME")
    assert PurePosixPath(places.state_dir("darwin")) == PurePosixPath(
        "/Users/op/Library/Application Support/moas-gui")
    assert PurePosixPath(places.log_file("moas-server", "darwin")) == PurePosixPath(
        "/Users/op/Library/Logs/moas-gui/moas-server.log")
    monkeypatch.setenv("XDG_STATE_HOME", "/elsewhere")  # set: it wins (as the tests set it)
    assert PurePosixPath(places.state_dir("darwin")) == PurePosixPath("/elsewhere/moas-gui")


def test_windows_uses_local_appdata(monkeypatch: pytest.MonkeyPatch) -> None:
    """The folder Windows names for CSIDL_LOCAL_APPDATA (asked of the system there; a
    fake answers here)."""
    asked: list[str] = []

    def known_folder(csidl: str) -> str:
        asked.append(csidl)
        return {"CSIDL_LOCAL_APPDATA": r"C:\Users\op\AppData\Local",
                "CSIDL_APPDATA": r"C:\Users\op\AppData\Roaming"}[csidl]

    monkeypatch.setattr(platformdirs.windows, "get_win_folder", known_folder)
    monkeypatch.delenv("XDG_STATE_HOME")
    assert PureWindowsPath(places.state_dir("win32")) == PureWindowsPath(
        r"C:\Users\op\AppData\Local\moas-gui\state")
    assert PureWindowsPath(places.log_dir("win32")) == PureWindowsPath(
        r"C:\Users\op\AppData\Local\moas-gui\Logs")
    assert set(asked) == {"CSIDL_LOCAL_APPDATA"}  # never the roaming profile
    monkeypatch.setenv("XDG_STATE_HOME", "/elsewhere")  # set: it wins (as the tests set it)
    assert places.state_dir("win32") == Path("/elsewhere/moas-gui")
    assert places.log_dir("win32") == Path("/elsewhere/moas-gui/log")


@pytest.mark.realtime
def test_a_program_without_a_console_writes_its_output_to_its_log(tmp_path: Path) -> None:
    """As ``pythonw`` or a gui-script launcher starts it: no stdout, no stderr.
    ``moas-server --check`` then reports into ``moas-server.log``."""
    env = dict(os.environ, XDG_STATE_HOME=str(tmp_path / "state"))
    script = ("import sys; sys.stdout = sys.stderr = None\n"
              "from moas_gui.cli.server import main\n"
              f"raise SystemExit(main(['--check', {str(EXAMPLES / 'small-station.moas')!r}]))\n")
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "" and done.stderr == ""
    log = tmp_path / "state" / "moas-gui" / "log" / "moas-server.log"
    assert "Switch" in log.read_text(encoding="utf-8")  # the summary


def test_a_large_old_log_is_moved_aside(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path))
    log = tmp_path / "moas-gui" / "log" / "moas-client.log"
    log.parent.mkdir(parents=True)
    log.write_bytes(b"x" * (places.LOG_KEEP_BYTES + 1))
    monkeypatch.setattr(sys, "stderr", None)
    monkeypatch.setattr(sys, "stdout", None)
    assert places.output_without_console("moas-client") == log
    stream = sys.stderr
    assert stream is not None and sys.stdout is stream
    print("hello", file=stream)
    stream.close()
    assert log.read_text(encoding="utf-8") == "hello\n"
    assert log.with_name("moas-client.log.1").stat().st_size == places.LOG_KEEP_BYTES + 1


def test_a_program_with_a_console_keeps_it() -> None:
    assert places.output_without_console("moas-server") is None


# -- a rename Windows refuses for a moment --------------------------------------------------


class Refusing:
    """``os.replace`` that refuses the first ``times`` calls, as Windows does while a
    scanner holds the file, then renames for real."""

    def __init__(self, times: int) -> None:
        self.times = times
        self.calls = 0
        self.real = os.replace

    def __call__(self, source: object, target: object) -> None:
        self.calls += 1
        if self.calls <= self.times:
            raise PermissionError(13, "The process cannot access the file because it is "
                                      "being used by another process")
        self.real(source, target)  # type: ignore[arg-type]


def test_windows_refusing_twice_is_waited_out(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "station.state.json"
    target.write_text("old")
    refusing = Refusing(2)
    monkeypatch.setattr(files, "REFUSALS_PASS", True)
    monkeypatch.setattr(os, "replace", refusing)
    files.write_text_atomic(target, "new")
    assert target.read_text() == "new" and refusing.calls == 3
    assert [p.name for p in tmp_path.iterdir()] == [target.name]  # no temporary left


def test_the_pauses_between_tries_and_the_last_refusal(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    source, target = tmp_path / "new", tmp_path / "old"
    source.write_text("new")
    target.write_text("old")
    monkeypatch.setattr(files, "REFUSALS_PASS", True)
    refusing = Refusing(1000)
    monkeypatch.setattr(os, "replace", refusing)
    pauses: list[float] = []
    with pytest.raises(PermissionError):
        files.replace_patiently(source, target, sleep=pauses.append)
    assert pauses == list(files.RETRY_PAUSES_S)
    assert refusing.calls == len(files.RETRY_PAUSES_S) + 1
    assert target.read_text() == "old"


def test_elsewhere_a_refusal_is_final(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "station.state.json"
    target.write_text("old")
    monkeypatch.setattr(files, "REFUSALS_PASS", False)
    refusing = Refusing(1)
    monkeypatch.setattr(os, "replace", refusing)
    with pytest.raises(PermissionError):
        files.write_text_atomic(target, "new")
    assert refusing.calls == 1 and target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
