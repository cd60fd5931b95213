"""``moas-server --install-service FILE``: the systemd user unit it writes, checked by
``systemd-analyze verify`` where systemd is installed (this machine: yes)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import short_runtime_dir

from moas_gui.service import install_service, service_command, systemd_quote, systemd_unit

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ANALYZE = shutil.which("systemd-analyze")
needs_systemd = pytest.mark.skipif(ANALYZE is None, reason="systemd-analyze is not installed")


def verify(unit: Path) -> subprocess.CompletedProcess[str]:
    assert ANALYZE is not None
    runtime = short_runtime_dir()
    try:
        return subprocess.run([ANALYZE, "verify", "--user", str(unit)], capture_output=True,
                              text=True, timeout=60, check=False,
                              env=dict(os.environ, XDG_RUNTIME_DIR=str(runtime)))
    finally:
        shutil.rmtree(runtime, ignore_errors=True)


def test_exec_start_words_are_quoted_as_systemd_reads_them() -> None:
    assert systemd_quote("/usr/bin/moas-server") == "/usr/bin/moas-server"
    assert systemd_quote("/home/op/Contest Files/a.moas") == '"/home/op/Contest Files/a.moas"'
    assert systemd_quote("100%") == "100%%" and systemd_quote("$HOME") == "$$HOME"
    assert systemd_quote('say "hi"\\') == '"say \\"hi\\"\\\\"'


def test_the_command_is_the_headless_server_on_the_absolute_file(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch
                                                                  ) -> None:
    monkeypatch.chdir(tmp_path)
    command = service_command(["/opt/moas/bin/moas-server"],
                              ["station.moas", "--install-service", "--web-port", "8080"],
                              "station.moas")
    assert command == ["/opt/moas/bin/moas-server", "--headless",
                       str(tmp_path / "station.moas"), "--web-port", "8080"]


def test_only_linux_gets_a_unit(tmp_path: Path) -> None:
    for system in ("win32", "darwin"):
        with pytest.raises(OSError, match="docs/platforms.md"):
            install_service(["/bin/true"], platform=system,
                            environ={"XDG_CONFIG_HOME": str(tmp_path)})
    assert not (tmp_path / "systemd").exists()


@pytest.mark.realtime
def test_install_service_writes_a_unit_systemd_accepts(tmp_path: Path) -> None:
    """Through the real command line: the file is checked first, then the unit written."""
    config = tmp_path / "My Station" / "station.moas"
    config.parent.mkdir()
    shutil.copy(EXAMPLES / "small-station.moas", config)
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path / "config"), USER="op")
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", str(config),
                           "--install-service", "--web-port", "8080"],
                          capture_output=True, text=True, timeout=60, check=False, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    unit = tmp_path / "config" / "systemd" / "user" / "moas-server.service"
    assert f"wrote {unit}" in done.stdout
    assert "systemctl --user enable --now moas-server" in done.stdout
    assert "loginctl enable-linger op" in done.stdout
    text = unit.read_text(encoding="utf-8")
    exec_start = next(line for line in text.splitlines() if line.startswith("ExecStart="))
    assert f'--headless "{config}" --web-port 8080' in exec_start
    assert "Restart=on-failure" in text and "WantedBy=default.target" in text
    if ANALYZE is not None:
        checked = verify(unit)
        assert checked.returncode == 0 and checked.stderr.strip() == "", checked.stderr


def test_a_broken_file_is_never_installed(tmp_path: Path) -> None:
    broken = tmp_path / "broken.moas"
    broken.write_text('{"Switches": [}')
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path / "config"))
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", str(broken),
                           "--install-service"],
                          capture_output=True, text=True, timeout=60, check=False, env=env)
    assert done.returncode == 1 and "broken.moas:1" in done.stdout
    assert not (tmp_path / "config").exists()


@needs_systemd
def test_systemd_analyze_catches_a_unit_it_cannot_run(tmp_path: Path) -> None:
    """The check itself can fail: a program that is not there."""
    unit = tmp_path / "moas-server.service"
    unit.write_text(systemd_unit(["/nonexistent/moas-server", "--headless", "/x.moas"]))
    checked = verify(unit)
    assert checked.returncode != 0 and "nonexistent" in checked.stderr
