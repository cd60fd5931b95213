"""Tries the frozen app in FOLDER (dist/moas-gui): every program answers ``--version``;
``moas-server --check`` passes on a shipped example; ``moas-server --headless`` on that
example accepts a client, answers it and the browser client's page, and stops cleanly on
SIGTERM (CTRL_BREAK on Windows); ``moas-server-gui`` starts its window (offscreen where
there is no display) with the example and accepts a client too; the emulator makes a
pseudo-terminal (not on Windows).  Prints each step, its time, and the folder's size;
exits 1 at the first failure.

    python scripts/smoke_frozen.py dist/moas-gui
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

WINDOWS = sys.platform == "win32"


def exe(folder: Path, name: str) -> Path:
    return folder / (name + ".exe" if WINDOWS else name)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def step(what: str, started: float) -> None:
    print(f"  ok  {what} ({time.monotonic() - started:.2f} s)", flush=True)


def ask_state(port: int) -> dict[str, object]:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "hello", "client": "smoke"}\n'
                     b'{"id": 2, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 2:
                return message["result"]  # type: ignore[no-any-return]


def wait_for_state(process: subprocess.Popen[bytes], port: int, timeout: float = 60) -> dict:
    end = time.monotonic() + timeout
    while True:
        if process.poll() is not None:
            raise SystemExit(f"FAIL: the server ended with status {process.returncode}")
        try:
            return ask_state(port)
        except (OSError, ValueError):
            if time.monotonic() > end:
                raise SystemExit("FAIL: the server never answered a client") from None
            time.sleep(0.2)


def stop(process: subprocess.Popen[bytes]) -> int:
    process.send_signal(signal.CTRL_BREAK_EVENT if WINDOWS else signal.SIGTERM)  # type: ignore[attr-defined]
    try:
        return process.wait(60)
    finally:
        if process.poll() is None:
            process.kill()


def size_of(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file() and not p.is_symlink())


def main() -> int:
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else "dist/moas-gui").resolve()
    if not exe(folder, "moas-server").is_file():
        print(f"smoke: no frozen app in {folder}", file=sys.stderr)
        return 2
    examples = next(folder.rglob("examples/small-station.moas")).parent
    home = Path(tempfile.mkdtemp(prefix="moas-smoke-"))
    runtime = home / "run"
    runtime.mkdir(mode=0o700)
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_STATE_HOME=str(home / "state"),
               XDG_CONFIG_HOME=str(home / "config"), XDG_DATA_HOME=str(home / "data"),
               LOCALAPPDATA=str(home / "local"), PYTHONUNBUFFERED="1")
    if not WINDOWS and sys.platform != "darwin" and not env.get("DISPLAY"):
        env["QT_QPA_PLATFORM"] = "offscreen"
    group = {"creationflags": subprocess.CREATE_NEW_PROCESS_GROUP} if WINDOWS else {}  # type: ignore[attr-defined]
    print(f"smoke: {folder} ({size_of(folder) / 1e6:.0f} MB)")

    for name in ("moas-server", "moas-server-gui", "moas-client", "moas-client-gui",
                 "moas-emulator", "moas-rotator"):
        started = time.monotonic()
        done = subprocess.run([exe(folder, name), "--version"], env=env, capture_output=True,
                              text=True, timeout=120, check=False)
        said = (done.stdout + done.stderr).strip()
        if WINDOWS and name.endswith("-gui"):  # no console: what it says goes to its log
            log = home / "state" / "moas-gui" / "log" / f"{name.removesuffix('-gui')}.log"
            said = log.read_text(encoding="utf-8").strip() if log.is_file() else ""
        if done.returncode != 0 or "0." not in said:
            print(f"FAIL: {name} --version: {done.returncode} {said!r}")
            return 1
        step(f"{name} --version: {said}", started)

    started = time.monotonic()
    done = subprocess.run([exe(folder, "moas-server"), "--check",
                           examples / "small-station.moas"], env=env, capture_output=True,
                          text=True, timeout=120, check=False)
    if done.returncode != 0 or "Switch" not in done.stdout:
        print(f"FAIL: --check: {done.returncode}\n{done.stdout}{done.stderr}")
        return 1
    step("moas-server --check examples/small-station.moas", started)

    tcp, web = free_port(), free_port()
    started = time.monotonic()
    server = subprocess.Popen(
        [exe(folder, "moas-server"), examples / "small-station.moas", "--headless",
         "--new-instance", "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--udp-bind", "127.0.0.1", "--web-port", str(web), "--no-rotator-program"],
        env=env, **group)  # type: ignore[call-overload]
    state = wait_for_state(server, tcp)
    if state.get("config") != "small-station.moas":
        print(f"FAIL: the headless server runs {state.get('config')!r}")
        stop(server)
        return 1
    step("moas-server --headless: a client got the state", started)
    with urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=10) as page:
        if b"<html" not in page.read().lower():
            print("FAIL: the browser client's page")
            stop(server)
            return 1
    step("moas-server --headless: the browser client's page", started)
    started = time.monotonic()
    if stop(server) != 0:
        print(f"FAIL: the headless server ended with {server.returncode}")
        return 1
    step("moas-server --headless: stopped cleanly", started)

    tcp = free_port()
    started = time.monotonic()
    # Windows: the console program's window (a program without a console cannot be sent
    # Ctrl+Break); elsewhere the two are the same program
    window = subprocess.Popen(
        [exe(folder, "moas-server" if WINDOWS else "moas-server-gui"), examples / "small-station.moas", "--new-instance",
         "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--udp-bind", "127.0.0.1", "--no-rotator-program"], env=env, **group)  # type: ignore[call-overload]
    wait_for_state(window, tcp)
    step("moas-server-gui: the window runs the example and a client got the state", started)
    started = time.monotonic()
    if stop(window) != 0:
        print(f"FAIL: the window server ended with {window.returncode}")
        return 1
    step("moas-server-gui: stopped cleanly", started)

    if not WINDOWS:
        started = time.monotonic()
        emulator = subprocess.Popen([exe(folder, "moas-emulator"), "--headless"], env=env,
                                    stdout=subprocess.PIPE)
        assert emulator.stdout is not None
        port = emulator.stdout.readline().decode().strip()
        if not port.startswith("/dev/"):
            print(f"FAIL: moas-emulator said {port!r}")
            return 1
        if stop(emulator) != 0:
            print(f"FAIL: moas-emulator ended with {emulator.returncode}")
            return 1
        emulator.stdout.close()
        step(f"moas-emulator --headless: served {port} and stopped", started)
    print("smoke: every step passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
