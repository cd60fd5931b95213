"""The builder's Save and Restart from a process of its own (``moas-server --edit``): it
reaches this user's running server through the single-instance channel, asks first
naming the keyed stations, and says what the server answered.

Real processes: ``moas-emulator`` on a pseudo-terminal of its own (keyed through its
control socket), ``moas-server --headless`` on a copy of an example with that port,
started WITHOUT ``--new-instance`` (so the builder can reach it) but with private XDG
directories (so no other server is reached, and it reaches nothing else); the builder's
window in the test process, with the same XDG directories.  What the server runs is
read through its client port.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from helpers import EXAMPLES, free_port, short_runtime_dir, wait_for

from moas_gui.builder.apply import ServerAnswer
from moas_gui.builder.claims import release
from moas_gui.cli.builder_restart import ask_to_restart
from moas_gui.ui.builder_window import BuilderWindow, open_builder

pytestmark = [pytest.mark.realtime, pytest.mark.shared]

KEYED = "station 1 radio 1 (switch 1 port 1)"


def ask_state(port: int) -> dict[str, Any]:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 1:
                return message["result"]  # type: ignore[no-any-return]


def first_antenna(port: int) -> str:
    state = ask_state(port)
    return str(state["config"]) + ":" + str(state["antennas"][0]["short"])


def tune(port: int) -> None:
    """Radios 1/1 and 1/2 on 20 and 40 m through the client port (a started or restarted
    station has no frequencies until its loggers say them; till then the box inhibits its
    stations, which the server counts as maybe transmitting)."""
    requests = [{"cmd": "hello", "client": "test"},
                {"cmd": "frequency", "station": 1, "radio": 1, "khz": 14025},
                {"cmd": "frequency", "station": 1, "radio": 2, "khz": 7020}]
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        reader = conn.makefile("rb")
        for number, request in enumerate(requests, 1):
            conn.sendall(json.dumps({**request, "id": number}).encode() + b"\n")
            while (message := json.loads(reader.readline())).get("id") != number:
                pass
            assert message["ok"], message


def keyed(station: Path) -> tuple[str, ...]:
    """Who transmits, as the running server says it to the builder's look."""
    answer = ask_to_restart(station)
    assert answer.looked and answer.reached, answer
    return answer.keyed


class Answers:
    """The builder's questions, answered by the test in order."""

    def __init__(self) -> None:
        self.answers: list[bool] = []
        self.questions: list[str] = []

    def ask(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        self.questions.append(f"{title}: {text}")
        answered(self.answers.pop(0))

    def diff(self, _diff: str, answered: Callable[[bool], None]) -> None:
        answered(self.answers.pop(0))


@dataclass
class Rig:
    station: Path
    tcp: int
    log: Path
    control: Path
    env: dict[str, str]
    text: str
    """The station file as the rig started it (each test starts from it)."""
    since: int = 0
    """Lines of the server's log before the current test's (see :meth:`said`)."""

    def lines(self) -> list[str]:
        return self.log.read_text().splitlines()

    def said(self, text: str) -> int:
        """How many lines of the server's log since the test began hold ``text``."""
        return sum(text in line for line in self.lines()[self.since:])

    def key(self, on: bool) -> None:
        verb = "key" if on else "unkey"
        with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as conn:
            conn.settimeout(10)
            conn.connect(str(self.control))
            conn.sendall(f"{verb} 1\n".encode())
            reply = conn.makefile("rb").readline().decode()
        assert reply.strip() == f"ok {verb} 1", reply


def private_environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return {"XDG_RUNTIME_DIR": str(runtime), "XDG_CONFIG_HOME": str(tmp_path / "config"),
            "XDG_STATE_HOME": str(tmp_path / "state"), "XDG_DATA_HOME": str(tmp_path / "data")}


def end(process: subprocess.Popen[Any]) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=5)


@pytest.fixture(scope="module")
def started(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Rig]:
    """The emulator and the server, started once for the tests of this module that use
    :func:`rig` (each of those begins with the station file as it was, running)."""
    tmp_path = tmp_path_factory.mktemp("rig")
    runtime = short_runtime_dir()
    private = private_environment(tmp_path, runtime)
    env = dict(os.environ, **private, PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")
    box, control = tmp_path / "box", tmp_path / "box.ctl"
    emulator = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.emulator", "--headless", "--link", str(box),
         "--control", str(control)], env=env, stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL)
    server: subprocess.Popen[bytes] | None = None
    try:
        wait_for(lambda: box.exists() and control.exists(), 30, "the emulator's port")
        station = tmp_path / "station.moas"
        text = (EXAMPLES / "small-station.moas").read_text()
        assert text.count('"Port": "emulator"') == 1
        text = text.replace('"Port": "emulator"', f'"Port": {json.dumps(str(box))}')
        station.write_text(text)
        tcp = free_port()
        log = tmp_path / "server.log"
        with log.open("wb") as out:
            server = subprocess.Popen(
                [sys.executable, "-m", "moas_gui.cli.server", str(station), "--headless",
                 "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
                 "--no-rotator-program"], env=env, stderr=out, stdout=subprocess.DEVNULL)
        wait_for(lambda: first_antenna(tcp) == "station.moas:Tribander", 60, "the server")
        yield Rig(station, tcp, log, control, env, text)
        assert server.poll() is None, "the server kept running\n" + log.read_text()
    finally:
        if server is not None:
            end(server)
        end(emulator)
        shutil.rmtree(runtime, ignore_errors=True)


@pytest.fixture
def rig(started: Rig, monkeypatch: pytest.MonkeyPatch) -> Rig:
    """The started rig as a test wants it: the builder in this process in the rig's
    directories, the server running the station file as it was (restarted on it by the
    builder's own request when a test before changed it), radios tuned, nobody keyed."""
    for name in ("XDG_RUNTIME_DIR", "XDG_CONFIG_HOME", "XDG_STATE_HOME", "XDG_DATA_HOME"):
        monkeypatch.setenv(name, started.env[name])  # the builder in this process: the same
    if started.station.read_text() != started.text or \
            first_antenna(started.tcp) != "station.moas:Tribander":
        started.station.write_text(started.text)
        tune(started.tcp)
        wait_for(lambda: keyed(started.station) == (), 60, "nobody transmitting")
        answer = ask_to_restart(started.station, ())
        assert answer.restarted, answer.said
        wait_for(lambda: first_antenna(started.tcp) == "station.moas:Tribander", 60,
                 "the server on the station file as it was")
    tune(started.tcp)
    wait_for(lambda: keyed(started.station) == (), 60, "nobody transmitting")
    started.since = len(started.lines())
    return started


@pytest.fixture
def builder(qtbot: Any, rig: Rig) -> Iterator[tuple[BuilderWindow, Answers]]:
    refused: list[str] = []
    window = open_builder(rig.station, None, refused.append, ask_to_restart)
    assert window is not None, refused
    answers = Answers()
    window.ask = answers.ask
    window.show_diff = answers.diff
    yield window, answers
    window.closing_confirmed = True
    window.close()
    release(rig.station)


def restart(qtbot: Any, window: BuilderWindow) -> ServerAnswer:
    """Save and Restart, and the server's answer once the builder has it."""
    window.server_answer = None
    assert window.action_apply.isEnabled()
    window.action_apply.trigger()
    qtbot.waitUntil(lambda: window.server_answer is not None, timeout=90_000)
    assert window.server_answer is not None
    return window.server_answer


def test_save_and_restart_reaches_the_running_server_and_a_broken_file_is_refused(
        qtbot: Any, rig: Rig, builder: tuple[BuilderWindow, Answers]) -> None:
    window, answers = builder
    window.doc.set(("Antennas", 0, "ShortName"), "Yagi")
    answers.answers.append(True)  # the diff before the first save
    answer = restart(qtbot, window)
    assert answer.restarted and answer.said == "The running server restarted on station.moas."
    assert first_antenna(rig.tcp) == "station.moas:Yagi"  # the new file runs
    assert answers.questions == []  # nobody transmits: no question
    assert rig.said("The station builder asked to restart on") == 1
    tune(rig.tcp)
    wait_for(lambda: keyed(rig.station) == (), 60, "nobody transmitting")

    # a file with errors in the builder is not saved for a restart: nothing is sent
    window.doc.set(("Antennas", 0, "Rotator"), 7)
    window.server_answer = None
    window.action_apply.trigger()
    assert "the running server would refuse it" in window.statusBar().currentMessage()
    assert window.server_answer is None and b'"Rotator": 7' not in rig.station.read_bytes()
    window.doc.undo()

    # the file broken on disk behind the builder's back: the server's own check refuses
    # it, and the old file keeps running
    good = rig.station.read_text()
    rig.station.write_text(good.replace('"Rotator": 1,', '"Rotator": 7,', 1))
    window.server_answer = None
    window.restart_on_server(rig.station)
    qtbot.waitUntil(lambda: window.server_answer is not None, timeout=90_000)
    refused = window.server_answer
    assert refused is not None and not refused.restarted and refused.reached
    assert refused.said.startswith("The running server refused: station.moas has 1 error, "
                                   "so it was not restarted: station.moas carries on unchanged.")
    assert "rotator 7" in refused.said, refused.said
    assert window.dialog is not None and "carries on unchanged" in window.dialog.text()
    assert first_antenna(rig.tcp) == "station.moas:Yagi"
    rig.station.write_text(good)

    # a headless server (a service) restarts only on its own file: another is refused
    # at the look, before anything is asked or sent
    other = rig.station.with_name("other.moas")
    other.write_text(good)
    window.server_answer = None
    window.restart_on_server(other)
    qtbot.waitUntil(lambda: window.server_answer is not None, timeout=90_000)
    assert window.server_answer is not None and not window.server_answer.restarted
    assert window.server_answer.said == (
        "The running server refused: it runs station.moas headless and restarts only on "
        "that file, not on other.moas; stop it (or its service) to run another file")
    assert answers.questions == [] and first_antenna(rig.tcp) == "station.moas:Yagi"
    assert rig.said("The station builder asked to restart on") == 2


def test_while_a_station_transmits_it_asks_first_naming_it_and_no_sends_nothing(
        qtbot: Any, rig: Rig, builder: tuple[BuilderWindow, Answers]) -> None:
    window, answers = builder
    rig.key(True)
    wait_for(lambda: keyed(rig.station) == (KEYED,), 60, "the server to see station 1 keyed")
    window.doc.set(("Antennas", 0, "ShortName"), "Beam")
    answers.answers += [True, False]  # the diff; then No to the question
    answer = restart(qtbot, window)
    assert not answer.restarted
    assert answer.said.startswith("Not restarted on station.moas: nothing was sent")
    assert len(answers.questions) == 1
    assert answers.questions[0].startswith("Restart while transmitting?")
    assert f"Transmitting now:\n  {KEYED}" in answers.questions[0]
    # the builder looked (which changes nothing), asked, and the No sent no request: the
    # old file runs
    assert rig.said("The station builder asked to restart on") == 0
    assert first_antenna(rig.tcp) == "station.moas:Tribander"
    assert b'"Beam"' in rig.station.read_bytes()  # saved, not run

    answers.answers.append(True)  # Yes this time: the request goes again, confirmed
    answer = restart(qtbot, window)
    assert answer.restarted, answer.said
    assert len(answers.questions) == 2 and f"  {KEYED}\n" in answers.questions[1]
    assert rig.said("The station builder asked to restart on") == 1
    assert rig.said(f"Restart while {KEYED} transmits, confirmed by the operator") == 1
    assert first_antenna(rig.tcp) == "station.moas:Beam"
    rig.key(False)


def test_a_server_started_with_new_instance_is_not_reachable_and_the_builder_says_so(
        qtbot: Any, tmp_path: Path, runtime_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    private = private_environment(tmp_path, runtime_dir)
    for name, value in private.items():
        monkeypatch.setenv(name, value)
    env = dict(os.environ, **private, PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")
    station = tmp_path / "station.moas"
    station.write_bytes((EXAMPLES / "small-station.moas").read_bytes())
    tcp = free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "moas_gui.cli.server", str(station), "--headless",
         "--new-instance", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--no-rotator-program"], env=env, stderr=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL)
    try:
        wait_for(lambda: first_antenna(tcp) == "station.moas:Tribander", 60, "the server")
        window = open_builder(station, None, lambda _reason: None, ask_to_restart)
        assert window is not None
        answers = Answers()
        window.ask, window.show_diff = answers.ask, answers.diff
        window.doc.set(("Antennas", 0, "ShortName"), "Yagi")
        answers.answers.append(True)
        answer = restart(qtbot, window)
        assert not answer.restarted and not answer.reached
        assert "No moas-server of this user answers the builder" in answer.said
        assert "A server started with --new-instance takes no requests from the builder" in \
            answer.said
        assert first_antenna(tcp) == "station.moas:Tribander"
        window.closing_confirmed = True
        window.close()
        release(station)
    finally:
        end(server)


def test_the_window_server_restarts_on_the_builder_s_file_and_on_another_after_asking(
        qtbot: Any, tmp_path: Path, runtime_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The server with its window (offscreen), reached the same way: File > Restart's path
    for its own file, File > Open's for another (asked about in the builder first)."""
    private = private_environment(tmp_path, runtime_dir)
    for name, value in private.items():
        monkeypatch.setenv(name, value)
    env = dict(os.environ, **private, PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")
    station, other = tmp_path / "station.moas", tmp_path / "other.moas"
    station.write_bytes((EXAMPLES / "small-station.moas").read_bytes())
    other.write_bytes((EXAMPLES / "small-station.moas").read_bytes())
    tcp = free_port()
    log = tmp_path / "server.log"
    with log.open("wb") as out:
        server = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.server", str(station), "--bind", "127.0.0.1",
             "--tcp-port", str(tcp), "--udp-port", "0", "--no-rotator-program"],
            env=env, stderr=out, stdout=subprocess.DEVNULL)
    windows: list[BuilderWindow] = []
    try:
        wait_for(lambda: first_antenna(tcp) == "station.moas:Tribander", 60, "the server")
        for path, short in ((station, "Yagi"), (other, "Quad")):
            tune(tcp)
            wait_for(lambda: keyed(station) == (), 60, "nobody transmitting")
            window = open_builder(path, None, lambda _reason: None, ask_to_restart)
            assert window is not None
            windows.append(window)
            answers = Answers()
            window.ask, window.show_diff = answers.ask, answers.diff
            window.doc.set(("Antennas", 0, "ShortName"), short)
            answers.answers += [True] if path == station else [True, True]  # the diff; Yes
            answer = restart(qtbot, window)
            assert answer.restarted, answer.said
            assert first_antenna(tcp) == f"{path.name}:{short}"
        assert answers.questions[0].startswith("Restart on another file?: The running server "
                                               f"runs {station}, not {other}.")
        assert answer.said == ("The running server restarted on other.moas "
                               "(it ran station.moas).")
        # broken on disk: the window server's own check refuses it and carries on
        window = windows[-1]
        tune(tcp)
        wait_for(lambda: keyed(other) == (), 60, "nobody transmitting")
        other.write_text(other.read_text().replace('"Rotator": 1,', '"Rotator": 7,', 1))
        window.server_answer = None
        window.restart_on_server(other)
        qtbot.waitUntil(lambda: window.server_answer is not None, timeout=90_000)
        assert window.server_answer is not None and not window.server_answer.restarted
        assert "other.moas has 1 error, so it was not restarted: other.moas carries on " \
            "unchanged" in window.server_answer.said
        assert first_antenna(tcp) == "other.moas:Quad"
        assert server.poll() is None, log.read_text()
    finally:
        for window in windows:
            window.closing_confirmed = True
            window.close()
            if window.doc.path is not None:
                release(window.doc.path)
        end(server)


class Editing:
    """``moas-server --edit`` as a process of its own, its hands the test's hook
    (tests/ui/builder_edit_hook.py), one round of Save and Restart at a time."""

    def __init__(self, rig: Rig) -> None:
        here = str(Path(__file__).resolve().parent)
        env = dict(rig.env, MOAS_GUI_CONTROL_HOOK="builder_edit_hook",
                   PYTHONPATH=os.pathsep.join([here, rig.env.get("PYTHONPATH", "")]))
        self.process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.server", "--edit", str(rig.station)], env=env,
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def round(self, short: str, answers: str) -> tuple[list[str], str]:
        """Antenna 0 named ``short``, Save and Restart, the questions answered with
        ``answers``: the questions it asked and the server's answer it said."""
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(f"{short} {answers}\n")
        self.process.stdin.flush()
        questions: list[str] = []
        for line in self.process.stdout:  # (the test's timeout bounds the wait)
            if line.startswith("QUESTION "):
                questions.append(json.loads(line.split(" ", 1)[1]))
            elif line.startswith("ANSWER "):
                return questions, json.loads(line.split(" ", 1)[1])
        raise AssertionError(f"the builder ended without an answer: {self.finish()}")

    def finish(self) -> str:
        """Closes the window (an empty line); what the process said on standard error."""
        _, said = self.process.communicate("\n", timeout=60)
        assert self.process.returncode == 0, said
        return said


def test_moas_server_edit_as_a_process_restarts_the_running_server(rig: Rig) -> None:
    editing = Editing(rig)
    try:
        questions, said = editing.round("Yagi", "")
        assert said == "The running server restarted on station.moas." and questions == []
        assert first_antenna(rig.tcp) == "station.moas:Yagi"
        tune(rig.tcp)
        rig.key(True)
        wait_for(lambda: keyed(rig.station) == (KEYED,), 60, "the server to see station 1 keyed")
        questions, said = editing.round("Beam", "no")
        assert said.startswith("Not restarted on station.moas: nothing was sent")
        assert len(questions) == 1 and f"Transmitting now:\n  {KEYED}\n" in questions[0]
        assert rig.said("The station builder asked to restart on") == 1  # the first one only
        assert first_antenna(rig.tcp) == "station.moas:Yagi"
        editing.finish()
    finally:
        end(editing.process)
    rig.key(False)
