"""No file the server writes is ever left half written: each goes to a temporary file
that is flushed and renamed over the old one.  Checked against the real programs with
a write that cannot finish (the file-size limit, as a full disk does it, set in the
child process only): the old file stays whole, the program says what failed.

``kill -9`` in the middle of the saved state's writes, and the restart from it, is
``tests/journeys/test_restart_journey.py``; the saved state's writer is the one these use."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.desktop import DESKTOP_FILE, MIME_TYPE

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform != "linux", reason="XDG desktop files, rlimits"),
]

LIMIT = 1000
"""Bytes a child may write to one file: less than each file below."""


LIMITED = (
    "import os, resource, sys; n = int(sys.argv[1]); "
    "resource.setrlimit(resource.RLIMIT_FSIZE, (n, n)); "
    "os.execv(sys.executable, [sys.executable, *sys.argv[2:]])"
)
"""Sets the limit, then becomes the program (no ``preexec_fn`` in a threaded runner)."""


def run_limited(args: list[str], env: dict[str, str],
                limit: int = LIMIT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", LIMITED, str(limit), *args], env=env,
                          capture_output=True, text=True, timeout=60, check=False)


def environment(tmp_path: Path) -> dict[str, str]:
    return dict(os.environ, XDG_DATA_HOME=str(tmp_path / "data"),
                XDG_CONFIG_HOME=str(tmp_path / "config"), PATH="/nonexistent",
                PYTHONDONTWRITEBYTECODE="1")


def test_uninstall_on_a_full_disk_keeps_the_users_other_file_associations(
        tmp_path: Path) -> None:
    env = environment(tmp_path)
    mimeapps = tmp_path / "config" / "mimeapps.list"
    mimeapps.parent.mkdir(parents=True)
    others = "".join(f"text/x-kind{n}=editor{n}.desktop;\n" for n in range(80))
    before = f"[Default Applications]\n{MIME_TYPE}={DESKTOP_FILE};\n{others}"
    mimeapps.write_text(before)
    assert len(before) > LIMIT
    done = run_limited(["-m", "moas_gui.cli.server", "--uninstall-desktop"], env)
    assert done.returncode == 1, done
    assert "could not uninstall" in done.stderr and "File too large" in done.stderr, done
    assert "Traceback" not in done.stderr
    assert mimeapps.read_text() == before, "the file is the old one, whole"
    assert [p.name for p in mimeapps.parent.iterdir()] == ["mimeapps.list"], "no leftovers"
    # with room on the disk it goes through
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--uninstall-desktop"],
                          env=env, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done
    assert mimeapps.read_text() == f"[Default Applications]\n{others}"


def test_install_on_a_full_disk_leaves_every_file_old_or_new(tmp_path: Path) -> None:
    env = environment(tmp_path)
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--install-desktop"],
                          env=env, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done
    data = tmp_path / "data"
    written = {p: p.read_bytes() for p in data.rglob("*") if p.is_file()}
    big = [p for p, content in written.items() if len(content) > LIMIT]
    assert big, "some files are larger than the limit"
    for path in written:  # an older installation, of other content
        path.write_bytes(b"old " * (LIMIT // 2))
    old = {p: p.read_bytes() for p in written}
    done = run_limited(["-m", "moas_gui.cli.server", "--install-desktop"], env)
    assert done.returncode == 1 and "could not install" in done.stderr, done
    now = {p: p.read_bytes() for p in data.rglob("*") if p.is_file()}
    assert set(now) == set(written), "no temporary file left behind"
    for path, content in now.items():
        assert content in (old[path], written[path]), f"{path} is half written"


SAVE_SWITCH_DATA = """
import asyncio, sys
from pathlib import Path
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.status import ServerState

async def main() -> None:
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False))
    assert (await app.open(Path(sys.argv[1]))).ok
    for _ in range(200):
        if app.status.state is ServerState.NORMAL:
            break
        await asyncio.sleep(0.05)
    try:
        await app.save_switch_data(sys.argv[2])
    except OSError as exc:
        print(f"could not save: {exc}", file=sys.stderr)
        raise SystemExit(1)
    finally:
        await app.close()

asyncio.run(main())
"""


def test_save_switch_data_on_a_full_disk_keeps_the_old_file(tmp_path: Path) -> None:
    env = dict(environment(tmp_path), XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_RUNTIME_DIR=str(tmp_path))
    config = Path(__file__).resolve().parent.parent.parent / "examples" / "big-station.moas"
    target = tmp_path / "switch-data.txt"
    before = "an earlier Save Switch Data\n" * 100
    target.write_text(before)
    # each switch's part fits under the limit, the whole file does not
    done = run_limited(["-c", SAVE_SWITCH_DATA, str(config), str(target)], env, limit=3000)
    assert done.returncode == 1 and "File too large" in done.stderr, done.stderr[-2000:]
    assert target.read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    done = subprocess.run([sys.executable, "-c", SAVE_SWITCH_DATA, str(config), str(target)],
                          env=env, capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert target.read_text().startswith("MOAS II switch 1"), target.read_text()[:200]
    assert len(target.read_text()) > 3000, "the limit is smaller than the file"
