"""The headless server loads no Qt (issue 44): a tower computer without a desktop (a
Raspberry Pi OS Lite) runs ``moas-server --headless`` with PySide6 installed beside it but
never imported, so it needs none of Qt's libraries and none of its memory.  The whole run
is traced with ``python -X importtime``: start, a client's ``state`` answered, SIGTERM."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import free_port, wait_for

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="the server is stopped with SIGTERM"),
]

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "small-station.moas"
QT_ROOTS = ("PySide6", "shiboken6", "qasync")


def imported(trace: str) -> set[str]:
    """The modules an ``-X importtime`` trace (standard error) says were imported."""
    names = set()
    for line in trace.splitlines():
        if line.startswith("import time:") and line.count("|") == 2:
            name = line.rsplit("|", 1)[1].strip()
            if name != "imported package":
                names.add(name)
    return names


def qt_modules(trace: str) -> list[str]:
    return sorted(name for name in imported(trace) if name.split(".")[0] in QT_ROOTS)


def test_the_trace_reader_finds_qt_where_it_is_imported() -> None:
    """The check can fire: a program that imports Qt is seen to."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-c", "import PySide6.QtCore"],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert {"PySide6", "PySide6.QtCore", "shiboken6"} <= set(qt_modules(done.stderr))


def ask_state(port: int) -> dict[str, object] | None:
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
            conn.sendall(b'{"id": 1, "cmd": "state"}\n')
            reader = conn.makefile("rb")
            while True:
                message = json.loads(reader.readline())
                if message.get("id") == 1:
                    return message["result"]  # type: ignore[no-any-return]
    except (OSError, ValueError):
        return None


def traced_run(station: Path, env: dict[str, str], log: Path, *extra: str) -> str:
    """The ``-X importtime`` trace (standard error, kept in ``log``) of one headless server
    on ``station`` with ``extra`` options: its start, a client's ``state`` answered,
    SIGTERM.  The server must have served ``station`` and ended cleanly."""
    tcp = free_port()
    with log.open("w") as stderr:
        server = subprocess.Popen(
            [sys.executable, "-X", "importtime", "-m", "moas_gui.cli.server", str(station),
             "--headless", "--new-instance", "--bind", "127.0.0.1", "--tcp-port", str(tcp),
             "--udp-port", "0", "--udp-bind", "127.0.0.1", "--no-rotator-program", *extra],
            stderr=stderr, env=env)
    try:
        state = wait_for(lambda: server.poll() is not None or ask_state(tcp), timeout=60,
                         what="the headless server answering a client")
        assert server.poll() is None, log.read_text()[-3000:]
        assert isinstance(state, dict) and state.get("config") == station.name
        server.send_signal(signal.SIGTERM)
        server.wait(60)
    finally:
        if server.poll() is None:
            server.kill()
            server.wait()
    trace = log.read_text()
    assert server.returncode == 0, trace[-3000:]
    return trace


@pytest.mark.timeout(90)
def test_the_headless_server_serves_a_client_without_importing_qt(runtime_dir: Path,
                                                                 tmp_path: Path) -> None:
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime_dir), PYTHONUNBUFFERED="1")
    env.pop("QT_QPA_PLATFORM", None)
    trace = traced_run(EXAMPLE, env, tmp_path / "stderr.txt", "--web-port", "0")
    names = imported(trace)
    # the trace covers the serving path: the network server and the browser client's
    assert {"moas_gui.app", "moas_gui.net.server", "aiohttp"} <= names, sorted(names)[:50]
    assert qt_modules(trace) == []
