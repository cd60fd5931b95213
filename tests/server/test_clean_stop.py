"""One way to stop cleanly (:class:`moas_gui.aio.CleanStop`), for every program.

The first tests drive the helper itself: real signals on Linux, a loop without signal
handlers (qasync's), and the Windows branch with the platform faked (signal numbers,
Ctrl+Break, the console window closed and Windows held back until the program has
tidied up).  The last ones start each program as a real process, wait until it works,
send it a stop signal and see it end with status 0 after tidying up.
"""

from __future__ import annotations

import asyncio
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from helpers import free_port, short_runtime_dir, wait_for

from moas_gui import aio
from moas_gui.aio import (
    CTRL_CLOSE_EVENT,
    CTRL_LOGOFF_EVENT,
    CleanStop,
    run_until_stopped,
    stop_signals,
)
from moas_gui.sources.n1mm_packet import radio_info_packet

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
CTRL_C_EVENT = 0
CTRL_BREAK_EVENT = 1


# -- the helper ----------------------------------------------------------------------------


class FakeSignals:
    """Stands in for ``signal.signal``: records the handlers, returns the previous one."""

    def __init__(self) -> None:
        self.handlers: dict[int, Any] = {}
        self.calls: list[tuple[int, Any]] = []

    def __call__(self, number: int, handler: Any) -> Any:
        self.calls.append((number, handler))
        previous = self.handlers.get(number, signal.SIG_DFL)
        self.handlers[number] = handler
        return previous


class FakeConsole:
    """Stands in for ``SetConsoleCtrlHandler``."""

    def __init__(self) -> None:
        self.handler: Callable[[int], bool] | None = None
        self.removed = False

    def __call__(self, handler: Callable[[int], bool]) -> Callable[[], None]:
        self.handler = handler

        def remove() -> None:
            self.removed = True
        return remove


class NoSignalLoop(asyncio.SelectorEventLoop):
    """A loop without signal handlers, as qasync's Qt loop is."""

    def add_signal_handler(self, sig: int, callback: Any, *args: Any) -> None:
        raise NotImplementedError


def test_the_signals_asked_for_differ_by_platform() -> None:
    assert dict(stop_signals("win32")) == {"SIGINT": 2, "SIGBREAK": 21, "SIGTERM": 15}
    linux = dict(stop_signals("linux"))
    assert linux == {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM,
                     "SIGHUP": signal.SIGHUP}


@pytest.mark.asyncio
@pytest.mark.parametrize("number", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
async def test_a_real_signal_stops_through_the_loop(number: int) -> None:
    stop = asyncio.Event()
    before = signal.getsignal(number)
    with CleanStop(stop.set) as stopping:
        os.kill(os.getpid(), number)
        await asyncio.wait_for(stop.wait(), 30)
        assert stopping.reason == signal.Signals(number).name
    assert signal.getsignal(number) == before, "the loop's handler is gone again"


@pytest.mark.asyncio
async def test_a_hang_up_ignored_from_the_start_stays_ignored() -> None:
    """``nohup moas-server --headless ...``: closing the terminal must not stop it."""
    before = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with CleanStop(lambda: None):
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) is not signal.SIG_IGN
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, before)


def test_a_loop_without_signal_handlers_gets_plain_ones_that_hand_over() -> None:
    loop = NoSignalLoop()
    fake = FakeSignals()
    stopped: list[str] = []
    try:
        stopping = CleanStop(lambda: stopped.append("stop"), loop=loop, platform="linux",
                             set_signal=fake)
        stopping.install()
        assert sorted(fake.handlers) == sorted(n for _, n in stop_signals("linux"))
        # a signal arrives (on the main thread, between two steps of the loop)
        fake.handlers[signal.SIGTERM](signal.SIGTERM, None)
        assert stopped == []  # not yet: it runs on the loop
        loop.run_until_complete(asyncio.sleep(0))
        assert stopped == ["stop"] and stopping.reason == "SIGTERM"
        stopping.remove()
        assert all(fake.handlers[n] is signal.SIG_DFL for n in fake.handlers)
    finally:
        loop.close()


def test_with_the_loop_gone_a_signal_is_a_keyboard_interrupt() -> None:
    loop = NoSignalLoop()
    fake = FakeSignals()
    CleanStop(lambda: None, loop=loop, platform="linux", set_signal=fake).install()
    loop.close()
    with pytest.raises(KeyboardInterrupt):
        fake.handlers[signal.SIGINT](signal.SIGINT, None)


def test_on_windows_ctrl_c_ctrl_break_and_sigterm_get_plain_handlers() -> None:
    """Windows' loops have no signal handlers: every signal goes through signal.signal,
    SIGBREAK (Ctrl+Break, 21) among them; the loop's own is never asked for."""
    loop = asyncio.new_event_loop()  # has add_signal_handler here: must not be used
    fake, console = FakeSignals(), FakeConsole()
    stopped: list[str] = []
    try:
        stopping = CleanStop(lambda: stopped.append("stop"), loop=loop, platform="win32",
                             set_signal=fake, console=console).install()
        assert [n for n, _ in fake.calls] == [2, 21, 15]
        assert not loop._signal_handlers  # type: ignore[attr-defined]
        fake.handlers[21](21, None)
        loop.run_until_complete(asyncio.sleep(0))
        assert stopped == ["stop"] and stopping.reason == "SIGBREAK"
        # Ctrl+C and Ctrl+Break reach the console handler first: it leaves them to Python
        assert console.handler is not None
        assert console.handler(CTRL_C_EVENT) is False
        assert console.handler(CTRL_BREAK_EVENT) is False
        stopping.remove()
        assert console.removed
        assert [n for n, _ in fake.calls[3:]] == [15, 21, 2]  # put back, last first
    finally:
        loop.close()


def test_on_windows_closing_the_console_waits_for_the_tidying_up() -> None:
    """Windows ends the process when the console handler returns: the handler asks the
    loop to stop and returns only once the program has finished (``remove``)."""
    loop = asyncio.new_event_loop()
    console = FakeConsole()
    order: list[str] = []
    answers: list[bool] = []

    async def program(stopping: CleanStop, stop: asyncio.Event) -> None:
        await stop.wait()
        order.append("stopping")
        await asyncio.sleep(0.05)  # writing the state
        order.append("state written")
        stopping.remove()

    try:
        stop = asyncio.Event()
        stopping = CleanStop(stop.set, loop=loop, platform="win32", set_signal=FakeSignals(),
                             console=console, close_grace=60).install()
        assert console.handler is not None
        handler = console.handler

        def windows_thread() -> None:  # Windows calls the handler on a thread of its own
            answers.append(handler(CTRL_CLOSE_EVENT))
            order.append("handler returned")

        thread = threading.Thread(target=windows_thread)
        thread.start()
        loop.run_until_complete(program(stopping, stop))
        thread.join(30)
        assert order == ["stopping", "state written", "handler returned"]
        assert answers == [True] and stopping.reason == "console closed"
    finally:
        loop.close()


def test_on_windows_the_console_handler_gives_up_after_its_grace() -> None:
    loop = asyncio.new_event_loop()
    console = FakeConsole()
    try:
        stopping = CleanStop(lambda: None, loop=loop, platform="win32",
                             set_signal=FakeSignals(), console=console,
                             close_grace=0.01).install()
        assert console.handler is not None
        assert console.handler(CTRL_LOGOFF_EVENT) is True  # returns though never removed
        loop.run_until_complete(asyncio.sleep(0))
        assert stopping.reason == "logging off"
    finally:
        loop.close()


def test_a_window_program_without_a_console_still_gets_its_signals() -> None:
    def no_console(_handler: Callable[[int], bool]) -> Callable[[], None]:
        raise OSError("the handle is invalid")

    loop = asyncio.new_event_loop()
    fake = FakeSignals()
    try:
        stopping = CleanStop(lambda: None, loop=loop, platform="win32", set_signal=fake,
                             console=no_console).install()
        assert sorted(fake.handlers) == [2, 15, 21]
        stopping.remove()
    finally:
        loop.close()


def test_the_real_console_hook_is_windows_only() -> None:
    with pytest.raises(OSError, match="Windows only"):
        aio._windows_console_hook(lambda event: False)


def test_a_keyboard_interrupt_before_the_handlers_still_runs_the_tidying_up() -> None:
    tidied: list[str] = []

    async def program() -> int:
        try:
            raise KeyboardInterrupt  # as Ctrl+C during the start
        finally:
            tidied.append("closed")

    assert run_until_stopped(program()) == 0
    assert tidied == ["closed"]

    async def finishes() -> int:
        return 3

    assert run_until_stopped(finishes()) == 3


# -- each program, as a real process ------------------------------------------------------


class Running:
    """A program started as a child process; its output (both streams) read line by line."""

    def __init__(self, args: list[str], env: dict[str, str]) -> None:
        self.lines: list[str] = []
        self.process = subprocess.Popen(
            [sys.executable, *args], env=env, cwd=ROOT, stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT, text=True)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.append(line.rstrip("\n"))

    def said(self, text: str) -> bool:
        assert self.process.poll() is None or any(text in line for line in self.lines), \
            "\n".join(self.lines)
        return any(text in line for line in self.lines)

    def stop(self, number: int) -> tuple[int, str]:
        self.process.send_signal(number)
        try:
            code = self.process.wait(30)
        finally:
            if self.process.poll() is None:
                self.process.kill()
                self.process.wait()
        self._reader.join(10)
        return code, "\n".join(self.lines)

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self._reader.join(10)
        if self.process.stdout is not None:
            self.process.stdout.close()


@pytest.fixture
def env(tmp_path: Path) -> Any:
    runtime = short_runtime_dir()
    yield dict(os.environ, PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen",
               XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "config"),
               XDG_STATE_HOME=str(tmp_path / "state"), XDG_DATA_HOME=str(tmp_path / "data"))
    shutil.rmtree(runtime, ignore_errors=True)


@pytest.fixture
def start(env: dict[str, str]) -> Any:
    """Starts a program (``start(args)``); whatever still runs at the end is killed."""
    started: list[Running] = []

    def starter(args: list[str]) -> Running:
        started.append(Running(args, env))
        return started[-1]

    yield starter
    for program in started:
        program.close()


SERVER = ["-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"), "--new-instance",
          "--bind", "127.0.0.1", "--udp-bind", "127.0.0.1", "--tcp-port", "0", "--udp-port", "0",
          "--no-rotator-program"]


def _radio_khz(state_dir: Path, station: int, radio: int) -> float | None:
    """Radio ``station/radio``'s frequency in the small station's state file, if any."""
    for path in state_dir.glob("small-station-*.state.json"):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None  # (written by rename: never half a file; gone between glob and read)
        for entry in data["engine"]["radios"]:
            if entry["radio"] == [station, radio]:
                return float(entry["khz"]) if entry["khz"] is not None else None
    return None


@pytest.mark.realtime
def test_a_change_still_waiting_to_be_saved_is_written_before_the_server_exits(
        start: Any, tmp_path: Path) -> None:
    # saves are coalesced (a change within a second of the last write waits for the
    # next, issue 41): a SIGTERM in that second still writes it before the process ends
    port = free_port(socket.SOCK_DGRAM)
    args = list(SERVER)
    args[args.index("--udp-port") + 1] = str(port)
    program = start([*args, "--headless"])
    wait_for(lambda: program.said("Serving"), 30, "the server serving")
    saved = tmp_path / "state" / "moas-gui"
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as logger:
        logger.sendto(radio_info_packet(1, 14025.0), ("127.0.0.1", port))
        wait_for(lambda: _radio_khz(saved, 1, 1) == 14025.0, 30, "the first change saved")
        logger.sendto(radio_info_packet(1, 7025.0), ("127.0.0.1", port))  # within the second
        wait_for(lambda: program.said("7025"), 30, "the second change taken")
        pending = _radio_khz(saved, 1, 1) == 14025.0
        code, output = program.stop(signal.SIGTERM)
    assert code == 0 and "Stopping (SIGTERM)" in output, output
    assert _radio_khz(saved, 1, 1) == 7025.0, (pending, output)


@pytest.mark.realtime
@pytest.mark.parametrize("number", [signal.SIGHUP, signal.SIGINT])
def test_the_headless_server_writes_its_state_on_a_stop(number: int, start: Any,
                                                       tmp_path: Path) -> None:
    program = start([*SERVER, "--headless"])
    wait_for(lambda: program.said("Serving"), 30, "the server serving")
    code, output = program.stop(number)
    name = signal.Signals(number).name
    assert code == 0, output
    assert f"Stopping ({name})" in output and "the relays keep their state" in output
    saved = list((tmp_path / "state" / "moas-gui").glob("small-station-*.state.json"))
    assert len(saved) == 1, output
    assert json.loads(saved[0].read_text(encoding="utf-8"))["config"]
    assert "Traceback" not in output


@pytest.mark.realtime
def test_the_window_server_stops_on_sighup_as_on_exit(start: Any,
                                                      tmp_path: Path) -> None:
    """Qt's loop has no signal handlers: the plain ones hand the stop over."""
    program = start(SERVER)
    wait_for(lambda: list((tmp_path / "state" / "moas-gui").glob("small-station-*")), 30,
             "the window server's state file")
    code, output = program.stop(signal.SIGHUP)
    assert code == 0, output
    assert "Traceback" not in output


@pytest.mark.realtime
def test_the_rotator_program_stops_on_sigterm(start: Any) -> None:
    program = start(["-m", "moas_gui.cli.rotator", "--bind", "127.0.0.1", "--port", "0"])
    wait_for(lambda: program.said("listening on"), 30, "the rotator program listening")
    code, output = program.stop(signal.SIGTERM)
    assert code == 0, output
    assert "Stopping (SIGTERM)" in output and "stopped" in output.splitlines()[-1]


@pytest.mark.realtime
@pytest.mark.parametrize("args", [
    ["-m", "moas_gui.cli.rotator", "--emulate", "4"],
    ["-m", "moas_gui.cli.emulator", "--headless", "--log-level", "info"],
], ids=["rotator-emulator", "switch-emulator"])
def test_the_emulators_remove_their_links_on_sigterm(args: list[str], start: Any,
                                                     tmp_path: Path) -> None:
    link = tmp_path / "port"
    program = start([*args, "--link", str(link)])
    # the port's name is printed once a stop signal would be handled
    wait_for(lambda: program.said("/dev/"), 30, "the emulator's port")
    assert link.is_symlink()
    code, output = program.stop(signal.SIGTERM)
    assert code == 0, output
    assert not link.is_symlink(), "the link is removed on the way out"
    assert "Stopping (SIGTERM)" in output


@pytest.fixture
def listener() -> Any:
    """A TCP listener on 127.0.0.1 standing in for the server a client tells."""
    with socket.create_server(("127.0.0.1", 0)) as sock:
        sock.settimeout(30)
        yield sock


@pytest.mark.realtime
@pytest.mark.parametrize("headless", [True, False], ids=["headless", "window"])
def test_the_client_stops_on_sigterm(headless: bool, start: Any,
                                     listener: socket.socket) -> None:
    port = listener.getsockname()[1]
    args = ["-m", "moas_gui.cli.client", "-v", f"127.0.0.1:{port}", "--station", "1"]
    if headless:
        args += ["--headless", "--source", "rigctld:1,retry=5"]
    program = start(args)
    connection, _ = listener.accept()  # the client is up and reaching for the server
    with connection:
        code, output = program.stop(signal.SIGTERM)
    assert code == 0, output
    assert "Stopping (SIGTERM)" in output and "Traceback" not in output


@pytest.mark.realtime
@pytest.mark.parametrize("args, ready", [
    (["-m", "moas_gui.testing.fake_server", "--port", "0"], "port "),
    (["-m", "moas_gui.testing.fake_moas_rotator", "--port", "0"],
     "fake MOAS Rotator listening on"),
], ids=["fake-server", "fake-moas-rotator"])
def test_the_stand_ins_stop_on_sigterm(args: list[str], ready: str, start: Any) -> None:
    program = start(args)
    # the line the stand-in prints once it would stop cleanly (its log's "Accepting
    # clients on TCP port ..." comes before, and a stop then would kill it outright)
    wait_for(lambda: program.said(ready) and any(line.startswith(ready)
                                                 for line in program.lines),
             30, "the stand-in listening")
    code, output = program.stop(signal.SIGTERM)
    assert code == 0, output
    assert "Stopping (SIGTERM)" in output and "Traceback" not in output
