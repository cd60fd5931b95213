"""Journeys: the real ``moas-server`` process with its window, on the real qasync loop,
driven as a person drives it (menus, tray menu, question dialogs, a second launch)
and checked as a person checks it: the client port answers, the switch shows the
right relays, the title, status bar and tray say the truth.

The clicks go through the process's control hook (``moas_gui/testing/control_hook.py``,
loaded only when the test names it in ``MOAS_GUI_CONTROL_HOOK``): it triggers the real
QActions and clicks the real dialog buttons from the Qt event loop.  The window
runs under ``QT_QPA_PLATFORM=offscreen`` (no system tray there, so the tray's
menu is triggered directly).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from helpers import free_port, short_runtime_dir, wait_for

pytestmark = pytest.mark.realtime

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
HANG = 30.0
"""Seconds after which a server that should have ended is taken to hang."""


class Server:
    """One real ``moas-server`` with a window and the control hook."""

    def __init__(self, tmp_path: Path, *, new_instance: bool = True) -> None:
        self.tmp_path = tmp_path
        self.runtime = short_runtime_dir()
        self.control = self.runtime / "control.sock"
        self.tcp = free_port()
        self.env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONUNBUFFERED="1",
                        XDG_RUNTIME_DIR=str(self.runtime),
                        XDG_CONFIG_HOME=str(tmp_path / "config"),
                        MOAS_GUI_CONTROL_HOOK="moas_gui.testing.control_hook",
                        MOAS_GUI_CONTROL_SOCKET=str(self.control))
        self.new_instance = new_instance
        self.process: subprocess.Popen[str] | None = None
        self._hook: socket.socket | None = None
        self._reader: Any = None

    def start(self, file: str, *extra: str, rotator_program: int | None = None) -> Server:
        """Starts the server on ``file``; with ``rotator_program`` (a port) it starts the
        MOAS Rotator program there as the file asks, else it runs none."""
        if self.process is not None:  # a restart: the ended process's hook and output go
            self.output()
        self.control.unlink(missing_ok=True)  # a restart waits for the new process's hook
        program = (["--no-rotator-program"] if rotator_program is None
                   else ["--rotator-program-port", str(rotator_program)])
        args = [sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / file),
                "--bind", "127.0.0.1", "--tcp-port", str(self.tcp), "--udp-port", "0",
                "--udp-bind", "127.0.0.1", *program, *extra]
        if self.new_instance:
            args.append("--new-instance")
        self.process = subprocess.Popen(args, env=self.env, stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, text=True)
        # the hook's file appears when it is bound, a moment before it listens: a refused
        # connection is "not yet"
        self._hook = wait_for(self._hook_connected, 20, "the control hook")
        self._reader = self._hook.makefile("rb")
        return self

    def _hook_connected(self) -> socket.socket | None:
        if not self.control.exists():
            return None
        hook = socket.socket(socket.AF_UNIX)
        hook.settimeout(5)
        try:
            hook.connect(str(self.control))
        except OSError:
            hook.close()
            return None
        return hook

    def ask(self, **request: Any) -> dict[str, Any]:
        assert self._hook is not None, "not started"
        self._hook.sendall(json.dumps(request).encode() + b"\n")
        reply: dict[str, Any] = json.loads(self._reader.readline())
        return reply

    def click(self, *path: str) -> None:
        reply = self.ask(do="menu", path=list(path))
        assert reply["ok"], reply

    def answer(self, button: str) -> None:
        reply = self.ask(do="answer", button=button)
        assert reply["ok"], reply

    def look(self) -> dict[str, Any]:
        return self.ask(do="look")

    def shows(self, predicate: Callable[[dict[str, Any]], bool], what: str,
              timeout: float = 10.0) -> dict[str, Any]:
        def seen_when_true() -> dict[str, Any] | None:
            seen = self.look()
            return seen if predicate(seen) else None

        return wait_for(seen_when_true, timeout, what)  # type: ignore[no-any-return]

    def client(self, request: dict[str, Any]) -> dict[str, Any]:
        """One request on the client port, as any client sends it; the reply.  (While a
        new configuration starts, its port opens a moment after the window names it:
        a refused connection is tried again, as a client does.)"""
        conn = wait_for(lambda: _connected(self.tcp), 20, "the client port")
        with conn:
            conn.sendall(json.dumps({"id": 1, **request}).encode() + b"\n")
            reader = conn.makefile("rb")
            while True:
                message = json.loads(reader.readline())
                if message.get("id") == 1:
                    return message  # type: ignore[no-any-return]

    def config(self) -> str | None:
        return self.client({"cmd": "state"})["result"]["config"]  # type: ignore[no-any-return]

    def ends(self) -> int:
        """Waits for the process to end by itself; its exit status.  (How soon it ends is
        measured by benchmarks/bench_server.py; the limit here only catches a hang.)"""
        assert self.process is not None
        try:
            return self.process.wait(timeout=HANG)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"the server still runs {HANG} s later: it hangs") from None

    def output(self) -> str:
        assert self.process is not None
        if self._hook is not None:
            self._hook.close()
            self._hook = None
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        if self.process.poll() is None:
            self.process.kill()
        out, _ = self.process.communicate(timeout=10)
        (self.tmp_path / "server-output.txt").write_text(out)
        return out

    def stop(self) -> None:
        if self._hook is not None:
            self._hook.close()
        if self._reader is not None:
            self._reader.close()
        if self.process is not None and self.process.poll() is None:
            # SIGTERM first: a server killed outright leaves the MOAS Rotator program it
            # started running (on port 13020, in the way of every later test)
            self.process.terminate()
            try:
                self.process.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.communicate(timeout=10)
        shutil.rmtree(self.runtime, ignore_errors=True)


def _connected(port: int) -> socket.socket | None:
    try:
        return socket.create_connection(("127.0.0.1", port), timeout=5)
    except ConnectionRefusedError:
        return None


@pytest.fixture
def server(tmp_path: Path) -> Iterator[Server]:
    running = Server(tmp_path)
    yield running
    running.stop()


def normal(name: str) -> Callable[[dict[str, Any]], bool]:
    """Title, status bar and tray all say ``name`` runs with its switches ok."""
    def check(seen: dict[str, Any]) -> bool:
        return (seen["title"] == f"{name} - MOAS Server"
                and name in seen["status"] and "ok" in seen["status"]
                and "stopped" not in seen["status"]
                and seen["tray_tooltip"] == f"MOAS Server: {seen['status']}")
    return check


def relays(seen: dict[str, Any], switch: int = 1) -> list[int]:
    return seen["emulators"].get(str(switch), [])  # type: ignore[no-any-return]


def test_stop_start_reset_restart_and_the_emulator_window(server: Server) -> None:
    server.start("small-station.moas")
    server.shows(normal("small-station.moas"), "small-station running")
    assert server.config() == "small-station.moas"
    assert server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7150})["ok"]
    server.click("View", "Emulator", "Switch 1")
    on = relays(server.shows(lambda s: relays(s), "the 40 m antenna's relays on switch 1"))

    server.click("File", "Stop Switches")
    seen = server.shows(lambda s: "stopped" in s["status"] and not relays(s), "relays off")
    assert "Start Switches" in seen["tray_menu"]
    refused = server.client({"cmd": "select", "station": 1, "radio": 1, "antenna": 3})
    assert not refused["ok"] and "stopped" in json.dumps(refused).lower()
    server.click("Tray", "Start Switches")
    assert relays(server.shows(lambda s: relays(s) == on, "the relays back")) == on
    assert "Stop Switches" in server.look()["tray_menu"]

    server.click("File", "Reset Switches")
    server.shows(lambda s: relays(s) == on and normal("small-station.moas")(s), "after reset")
    assert server.config() == "small-station.moas"

    server.click("File", "Restart")
    seen = server.shows(lambda s: any("Opened small-station.moas" in line for line in s["log"][-5:])
                        and normal("small-station.moas")(s), "restarted")
    assert "1" not in seen["emulators"], "the old switch's emulator window is closed"
    assert server.config() == "small-station.moas"
    server.click("View", "Emulator", "Switch 1")
    assert server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7150})["ok"]
    server.shows(lambda s: relays(s) == on, "the new switch shows the relays")

    server.click("Tray", "Exit")
    assert server.ends() == 0
    out = server.output()
    assert server.process is not None and server.process.returncode == 0, out
    assert "Traceback" not in out


def test_file_open_another_station_then_the_emulator_and_sigterm(server: Server) -> None:
    server.start("big-station.moas")
    server.shows(normal("big-station.moas"), "big-station running")
    server.click("View", "Emulator", "Switch 2")
    server.shows(lambda s: "2" in s["emulators"], "the emulator window of switch 2")

    server.click("File", "Open...")
    assert server.ask(do="choose", path=str(EXAMPLES / "small-station.moas"))["ok"]
    seen = server.shows(lambda s: s["dialogs"], "the question")
    assert "Stop big-station.moas and open small-station.moas?" in seen["dialogs"][0]["text"]
    server.answer("No")
    server.shows(lambda s: not s["dialogs"], "the question gone")
    assert server.config() == "big-station.moas"

    server.click("File", "Open...")
    assert server.ask(do="choose", path=str(EXAMPLES / "small-station.moas"))["ok"]
    server.shows(lambda s: s["dialogs"], "the question again")
    server.answer("Yes")
    seen = server.shows(normal("small-station.moas"), "small-station running")
    assert seen["emulators"] == {}, "big-station's emulator window is closed"
    assert server.config() == "small-station.moas"
    server.click("View", "Emulator", "Switch 1")
    assert server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 14025})["ok"]
    held = relays(server.shows(lambda s: relays(s), "small-station's relays on switch 1"))

    server.click("File", "Stop Switches")  # the client clicks while the switches are stopped
    server.shows(lambda s: not relays(s), "all relays off")
    refused = server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7150})
    assert server.client({"cmd": "state"})["ok"], "the client port still answers"
    server.click("File", "Start Switches")
    seen = server.shows(lambda s: relays(s) and normal("small-station.moas")(s), "started")
    if not refused["ok"]:
        assert relays(seen) == held, "a refused request changed nothing"

    assert server.process is not None
    server.process.send_signal(signal.SIGTERM)
    assert server.ends() == 0
    assert "Traceback" not in server.output()


def test_a_second_launch_with_another_file_asks_and_yes_switches_cleanly(tmp_path: Path) -> None:
    server = Server(tmp_path, new_instance=False)
    try:
        server.start("small-station.moas")
        server.shows(normal("small-station.moas"), "small-station running")
        server.click("View", "Emulator", "Switch 1")

        def launch(file: str, *extra: str, python: tuple[str, ...] = ()) -> \
                subprocess.CompletedProcess[str]:
            return subprocess.run(
                [sys.executable, *python, "-m", "moas_gui.cli.server", str(EXAMPLES / file),
                 *extra],
                env=server.env, capture_output=True, text=True, timeout=30, check=False)

        # the same file: the window comes forward (and the launch, which only hands the
        # file over, loads none of what serving needs: its imports are listed)
        same = launch("small-station.moas", python=("-X", "importtime"))
        assert same.returncode == 0, same.stderr
        loaded = {line.rsplit("|", 1)[-1].strip() for line in same.stderr.splitlines()
                  if line.startswith("import time:")}
        assert "moas_gui.single_instance" in loaded, same.stderr[-2000:]
        assert not loaded & {"moas_gui.hw.moas2", "moas_gui.hw.rotators", "moas_gui.net",
                             "moas_gui.app", "PySide6"}, sorted(loaded)
        seen = server.look()
        assert not seen["dialogs"]
        handed = [i for i, line in enumerate(seen["log"]) if "handed over" in line]
        already = [i for i, line in enumerate(seen["log"]) if "is already open" in line]
        assert handed and already and handed[-1] < already[-1], seen["log"][-6:]

        # two quick launches: one question, the newer's; only its answer counts
        assert launch("big-station.moas").returncode == 0
        server.shows(lambda s: len(s["dialogs"]) == 1, "the first question")
        assert launch("tribander-stack.moas").returncode == 0
        seen = server.shows(lambda s: len(s["dialogs"]) == 1
                            and "tribander-stack.moas?" in s["dialogs"][0]["text"],
                            "the newer question in place of the older")
        assert "big-station" not in seen["dialogs"][0]["text"]
        server.answer("No")
        server.shows(lambda s: not s["dialogs"], "no question left behind")
        assert server.config() == "small-station.moas"

        other = launch("2x6.moas")  # a double-click on another file
        assert other.returncode == 0 and "handed" in other.stderr, other.stderr
        seen = server.shows(lambda s: s["dialogs"], "the question")
        assert "open 2x6.moas?" in seen["dialogs"][0]["text"]
        assert server.config() == "small-station.moas", "the port answers while it asks"
        server.answer("No")
        server.shows(lambda s: not s["dialogs"], "the question gone")
        assert server.config() == "small-station.moas"

        launch("2x6.moas")
        server.shows(lambda s: s["dialogs"], "the question again")
        server.answer("Yes")
        seen = server.shows(normal("2x6.moas"), "2x6 running")
        assert "1" not in seen["emulators"], "small-station's emulator window is gone"
        assert server.config() == "2x6.moas"

        conflict = launch("2x6.moas", "--tcp-port", str(free_port()))
        assert conflict.returncode != 0 and "--tcp-port" in conflict.stderr, conflict.stderr
        web = launch("2x6.moas", "--web-port", str(free_port()))
        assert web.returncode != 0 and "--web-port" in web.stderr, web.stderr
        headless = launch("2x6.moas", "--headless")
        assert headless.returncode != 0 and "headless" in headless.stderr, headless.stderr
        broken = tmp_path / "broken.moas"
        broken.write_text("{")
        bad = launch(str(broken))
        assert bad.returncode != 0 and "broken.moas" in bad.stderr
        assert normal("2x6.moas")(server.look()) and server.config() == "2x6.moas"

        server.click("File", "Stop Switches")
        server.shows(lambda s: "stopped" in s["status"], "stopped")
        server.click("Tray", "Exit")
        assert server.ends() == 0
        out = server.output()
        assert "Traceback" not in out and "Cannot enter into task" not in out, out
    finally:
        server.stop()


def test_restart_on_a_file_with_a_typo_keeps_the_station_on_the_air(
        server: Server, tmp_path: Path) -> None:
    """Issue 30's first finding as a person meets it: the running file is edited with a
    typo and File > Restart is chosen.  The station stays up: the window still names
    the file, the client port answers, a band change still moves the relays; a dialog
    says why, with the line and column."""
    path = tmp_path / "station.moas"
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    # a rotator through the MOAS Rotator program, which the server starts (its
    # controller's port is missing: the rotator is offline, the program runs)
    data["Rotators"].append({"ID": 2, "ShortName": "Beam", "LongName": "Beam rotator",
                             "CCWLimit": 180, "Rotation": 360, "HasStop": True,
                             "Control": "Serial", "Address": "127.0.0.1",
                             "CommPort": str(tmp_path / "no-controller"),
                             "Model": "Prosistel D", "Poll": 2000})
    data["StartMOASRotator"] = True
    path.write_text(json.dumps(data, indent=2))
    program_port = free_port()
    server.start(str(path), rotator_program=program_port)
    server.shows(normal("station.moas"), "the station running")
    started = server.shows(lambda s: any("started the MOAS Rotator program (pid" in line
                                         for line in s["log"]), "the rotator program started")
    pid = int(next(line for line in started["log"] if "started the MOAS Rotator" in line)
              .split("(pid ")[1].split(")")[0])
    wait_for(lambda: _connected(program_port), 20, "the rotator program's port").close()
    server.click("View", "Emulator", "Switch 1")
    assert server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 7150})["ok"]
    on_40 = relays(server.shows(lambda s: relays(s), "the 40 m antenna's relays"))
    data = json.loads(path.read_text())
    data["Antennas"][0]["ID"] = "zero"  # the typo
    path.write_text(json.dumps(data, indent=2))
    server.click("File", "Restart")
    seen = server.shows(lambda s: any(d["title"] == "Not restarted: the file has errors"
                                      for d in s["dialogs"]), "the dialog about the typo")
    dialog = next(d for d in seen["dialogs"] if d["title"].startswith("Not restarted"))
    assert "carries on unchanged" in dialog["text"] and str(path) in dialog["text"]
    assert "Open Folder" in dialog["buttons"]
    assert normal("station.moas")(seen), seen["status"]
    assert server.config() == "station.moas"  # the client port answers as before
    assert server.client({"cmd": "frequency", "station": 1, "radio": 1, "khz": 14025})["ok"]
    server.shows(lambda s: relays(s) and relays(s) != on_40, "band-following goes on")
    # the MOAS Rotator program was not stopped: the same process, still answering
    os.kill(pid, 0)
    conn = _connected(program_port)
    assert conn is not None, "the rotator program's port answers after the refused Restart"
    conn.close()
    assert not any("stopped the MOAS Rotator program" in line for line in server.look()["log"])
    server.answer("OK")
    server.click("Tray", "Exit")
    assert server.ends() == 0
    assert "Traceback" not in server.output()

    def program_gone() -> bool:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        return False
    wait_for(program_gone, 20, "the rotator program stopped with the server")
