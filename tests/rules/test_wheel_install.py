"""The wheel is the product: ``python -m build`` makes an sdist and, from it, a wheel; the
wheel goes into a fresh virtual environment (no setup.sh, no checkout on the path) and
the installed ``moas-server`` checks and serves the example installed with it.

To stay off the network, the wheel is installed with ``--no-deps --no-index`` and the
fresh environment borrows this one's libraries through a ``.pth`` line (PySide6, aiohttp
and the rest; the project itself comes from the wheel alone)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
from helpers import free_port, short_runtime_dir, wait_for

pytestmark = pytest.mark.realtime

ROOT = Path(__file__).resolve().parents[2]
WINDOWS = sys.platform == "win32"


def run(*args: object, **kwargs: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=300,
                          check=False, **kwargs)  # type: ignore[call-overload, no-any-return]


def ask_state(port: int) -> dict[str, object]:
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(b'{"id": 1, "cmd": "state"}\n')
        reader = conn.makefile("rb")
        while True:
            message = json.loads(reader.readline())
            if message.get("id") == 1:
                return message["result"]  # type: ignore[no-any-return]


def install_fresh(base: Path) -> Path:
    """A fresh environment under ``base`` with the wheel built from this source installed;
    returns its scripts' folder."""
    source = base / "source"
    source.mkdir(parents=True)
    for name in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(ROOT / name, source / name)
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info")
    for name in ("moas_gui", "examples", "docs"):  # moas_gui/manual is a link to docs/
        shutil.copytree(ROOT / name, source / name, symlinks=True, ignore=ignore)
    dist = base / "dist"
    built = run(sys.executable, "-m", "build", "--no-isolation", "--outdir", dist, source)
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-3000:]
    wheels, sdists = list(dist.glob("*.whl")), list(dist.glob("*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1, list(dist.iterdir())

    fresh = base / "fresh"
    made = run(sys.executable, "-m", "venv", "--without-pip", fresh)
    assert made.returncode == 0, made.stderr
    scripts = fresh / ("Scripts" if WINDOWS else "bin")
    python = scripts / ("python.exe" if WINDOWS else "python")
    # (--no-compile: pip's byte-compiling of every module, which never fails an install,
    # is left to the imports of the programs run below, for what they load)
    done = run(sys.executable, "-m", "pip", "--python", python, "install", "--quiet",
               "--no-deps", "--no-index", "--disable-pip-version-check", "--no-compile",
               wheels[0])
    assert done.returncode == 0, done.stdout + done.stderr
    purelib = run(python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])")
    (Path(purelib.stdout.strip()) / "borrowed-libraries.pth").write_text(
        sysconfig.get_paths()["purelib"] + "\n", encoding="utf-8")
    return scripts


def installed_example(scripts: Path) -> Path:
    python = scripts / ("python.exe" if WINDOWS else "python")
    where = run(python, "-c", "import moas_gui, pathlib; "
                "print(pathlib.Path(moas_gui.__file__).parent)", cwd=scripts)
    package = Path(where.stdout.strip())
    assert package.is_relative_to(scripts.parent), f"moas_gui came from {package}"
    return package / "examples" / "small-station.moas"


def script(scripts: Path, name: str) -> Path:
    return scripts / (f"{name}.exe" if WINDOWS else name)


def test_the_wheel_installed_in_a_fresh_environment_checks_and_serves(tmp_path: Path) -> None:
    """One test, so that the wheel is built once (the workers would each build it)."""
    installed = install_fresh(tmp_path / "wheel")
    for name in ("moas-server", "moas-server-gui", "moas-client", "moas-client-gui",
                 "moas-emulator", "moas-rotator"):
        assert script(installed, name).is_file(), name
    example = installed_example(installed)
    package = example.parent.parent
    assert (package / "manual" / "README.md").is_file()
    assert (package / "resources" / "web" / "index.html").is_file()
    assert (package / "resources" / "icons" / "moas-server.ico").is_file()

    # --check from the console script and from the window (gui) script
    for name in ("moas-server", "moas-server-gui"):
        done = run(script(installed, name), "--check", example, cwd=installed)
        assert done.returncode == 0, (name, done.stdout, done.stderr)
        assert "Switch" in done.stdout, (name, done.stdout)

    # the installed server serves the installed example
    runtime = short_runtime_dir()
    env = dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"), PYTHONUNBUFFERED="1")
    tcp = free_port()
    server = subprocess.Popen(
        [str(script(installed, "moas-server")), str(example), "--headless", "--new-instance",
         "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
         "--udp-bind", "127.0.0.1", "--no-rotator-program"],
        cwd=installed, env=env, stderr=subprocess.PIPE, text=True,
        creationflags=subprocess.CREATE_NEW_PROCESS_GROUP if WINDOWS else 0)  # type: ignore[attr-defined]
    try:
        state = wait_for(lambda: ask_state(tcp), 60, "the installed server answering")
        assert state["config"] == "small-station.moas"
        # Ctrl+C here, Ctrl+Break on Windows (what a console can send to a program there)
        server.send_signal(signal.CTRL_BREAK_EVENT if WINDOWS else signal.SIGINT)  # type: ignore[attr-defined]
        _, stderr = server.communicate(timeout=60)
    finally:
        if server.poll() is None:
            server.kill()
            server.communicate()
        shutil.rmtree(runtime, ignore_errors=True)
    assert server.returncode == 0, stderr
    assert f"Serving {example}" in stderr
