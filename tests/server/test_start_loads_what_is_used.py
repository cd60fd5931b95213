"""A server loads the parts of the program its station uses, and the others only when used
(issue 41): a tower computer (a Raspberry Pi) starts faster when a station with a Test
rotator and N1MM Logger does not load the Rotator Genius, Hamlib and MOAS Rotator drivers,
the FlexRadio API, the Antenna Genius front, the built-in emulator and so on.  One headless
server on ``examples/small-station.moas`` with its switch on a serial port (one that is not
there: the server waits for it) and N1MM Logger off is traced with ``python -X importtime`` from its start to a
client's ``state`` answered; the modules of the parts its station has are seen loaded (the
check can fire), those of the parts it has not are not."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from test_headless_imports import EXAMPLE, imported, traced_run

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="the server is stopped with SIGTERM"),
]

USED = {
    # the station's Test rotator and its switch's serial port
    "moas_gui.hw.rotators.manager", "moas_gui.hw.rotators.simulated", "moas_gui.serial.port",
    "serial",
    # the client server's memory trimming (its C library is looked up when first used)
    "moas_gui.net.memory",
}
"""Modules of parts small-station.moas has: seen loaded, so the trace is read right."""

NOT_USED = {
    # rotators of kinds the station has none of
    "moas_gui.hw.rotators.genius", "moas_gui.hw.rotators.genius_codec",
    "moas_gui.hw.rotators.hamlib", "moas_gui.hw.rotators.hamlib_codec",
    "moas_gui.hw.rotators.moas_rotator_codec", "moas_gui.hw.rotators.moas_rotator_link",
    "moas_gui.hw.rotators.moas_rotator_process", "moas_gui.hw.rotators.controllers",
    "moas_gui.hw.rotators.controllers.models",
    # frequency sources the station does not turn on (N1MM Logger's packets are XML)
    "moas_gui.sources.n1mm", "moas_gui.sources.n1mm_packet", "xml.etree.ElementTree",
    "moas_gui.sources.flex", "moas_gui.sources.flex_api", "moas_gui.sources.flex_discovery",
    "moas_gui.sources.dxlog", "moas_gui.sources.wintest", "moas_gui.sources.wintest_frame",
    "moas_gui.sources.n1mm_rotor", "moas_gui.sources.n1mm_rotor_packet",
    "moas_gui.sources.otrsp", "moas_gui.sources.otrsp_command",
    # the Antenna Genius front (no AGPort) and the rotctld ports (no RotctldPort)
    "moas_gui.net.antenna_genius", "moas_gui.net.antenna_genius.server",
    "moas_gui.net.antenna_genius.codec", "moas_gui.net.antenna_genius.access",
    "moas_gui.net.rotctld_server", "moas_gui.net.rotctld_codec",
    # the station builder (the server answers its restart requests without it)
    "moas_gui.builder", "moas_gui.builder.apply", "moas_gui.builder.document",
    # the built-in emulator (no switch's Port is "emulator")
    "moas_gui.hw.moas2.emulator", "moas_gui.hw.moas2.emulator.box",
    "moas_gui.hw.moas2.emulator.model",
    # ctypes and the C library's malloc_trim, until a crowd of clients has left
    "ctypes",
    # the standard library's heavier helpers: shutil (with bz2 and lzma) for help text
    # widths, tempfile for the loop watcher's scratch file, platformdirs for a state
    # directory $XDG_STATE_HOME gives, difflib for a misspelt key's suggestion
    "shutil", "lzma", "bz2", "tempfile", "platformdirs", "difflib",
}
"""Modules of parts small-station.moas does not have: loaded only when a station has them."""


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The import trace of one headless server's run: start, a ``state`` answered, SIGTERM."""
    folder = tmp_path_factory.mktemp("start")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    for name in ("XDG_RUNTIME_DIR", "XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME",
                 "XDG_CACHE_HOME"):
        place = folder / name.lower()
        place.mkdir(mode=0o700)
        env[name] = str(place)
    env.pop("QT_QPA_PLATFORM", None)
    station = folder / "serial-station.moas"
    text = EXAMPLE.read_text(encoding="utf-8")
    assert text.count('"Port": "emulator"') == 1 and text.count('"UseN1MMLogger": true') == 1
    text = text.replace('"Port": "emulator"',
                        json.dumps({"Port": str(folder / "no-such-port")})[1:-1])
    station.write_text(text.replace('"UseN1MMLogger": true', '"UseN1MMLogger": false'),
                       encoding="utf-8")
    trace = traced_run(station, env, folder / "stderr.txt")
    assert "cannot open the port" in trace, trace[-3000:]
    return trace


@pytest.mark.timeout(90)
def test_the_parts_the_station_has_are_loaded(trace: str) -> None:
    assert USED <= imported(trace), sorted(USED - imported(trace))


@pytest.mark.timeout(90)
def test_the_parts_the_station_has_not_are_not_loaded(trace: str) -> None:
    assert sorted(NOT_USED & imported(trace)) == []


def test_the_check_fires_on_a_module_loaded_at_start(tmp_path: Path) -> None:
    """A program that loads one of them at start is seen to."""
    done = subprocess.run([sys.executable, "-X", "importtime", "-c",
                           "import moas_gui.hw.rotators.genius"],
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert {"moas_gui.hw.rotators.genius", "moas_gui.hw.rotators.genius_codec"} \
        <= NOT_USED & imported(done.stderr)


def test_the_written_out_flex_port_is_the_api_port() -> None:
    """The sources' settings name FlexRadio's discovery port without loading its API."""
    from moas_gui.sources.flex_api import API_PORT
    from moas_gui.sources.server import SourceSettings

    assert SourceSettings().flex_discovery_port == API_PORT


SHORT_PROGRAMS_PROBE = """
import json, os, sys
import moas_gui.cli.rotator, moas_gui.rotator_program.program
import moas_gui.cli.emulator, moas_gui.cli.client, moas_gui.cli.server
from moas_gui.sources.spec import parse_spec
parse_spec("rigctld:127.0.0.1:4532,station=1,radio=1")
seen = {"start": sorted(m for m in sys.modules if m in WATCHED)}
from moas_gui import places
os.environ["XDG_STATE_HOME"] = os.path.abspath("given-state")
places.state_dir()
seen["a given directory asked for"] = "platformdirs" in sys.modules
del os.environ["XDG_STATE_HOME"]
places.state_dir()
seen["a directory asked for"] = "platformdirs" in sys.modules
from moas_gui.hw.rotators import RotatorManager
seen["the rotator manager asked for"] = "moas_gui.config.model" in sys.modules
print(json.dumps(seen))
"""


def test_the_short_programs_start_without_what_they_do_not_use() -> None:
    """``moas-rotator`` runs serial controllers from ``controllers/`` and the MOAS Rotator
    codec: the rotators package hands out its drivers and manager only when asked, so it
    loads neither them nor the configuration they read (a tenth of its start-up before).
    ``moas-client --source`` parses rig sources with the rig entries' rules alone: the
    configuration package hands out its model and reader only when asked for.
    ``moas-emulator``, ``moas-client`` and ``moas-server --check`` start without
    platformdirs (and the tempfile, shutil and random it brings): the directories are
    looked up when first asked for, and a state directory given by ``$XDG_STATE_HOME``
    (every test's server is given one) without it.  One process imports the programs' modules; what each
    loads when asked for is seen loaded then, so the check can fire."""
    watched = ["moas_gui.config.model", "moas_gui.config.loader", "moas_gui.hw.rotators.base",
               "moas_gui.hw.rotators.manager", "platformdirs"]
    probe = f"WATCHED = {watched!r}\n" + SHORT_PROGRAMS_PROBE
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout) == {"start": [], "a given directory asked for": False,
                                       "a directory asked for": True,
                                       "the rotator manager asked for": True}, done.stdout


def test_the_display_check_loads_ctypes_only_to_ask_an_x_server() -> None:
    """A window program checks its display first: on a windowless platform (offscreen)
    the check needs no ctypes; asking an X server (here one that is not there) loads it."""
    probe = ("import sys\n"
             "from moas_gui.ui.display import display_problem\n"
             "print(display_problem(), 'ctypes' in sys.modules)")
    env = {key: value for key, value in os.environ.items()
           if key not in ("QT_QPA_PLATFORM", "WAYLAND_DISPLAY", "DISPLAY")}
    offscreen = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                               env=dict(env, QT_QPA_PLATFORM="offscreen"), timeout=60,
                               check=False)
    assert offscreen.stdout.strip() == "None False", offscreen.stdout + offscreen.stderr
    x11 = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         env=dict(env, DISPLAY=":97"), timeout=60, check=False)
    if sys.platform == "darwin":  # macOS windows open without asking an X server
        assert x11.stdout.strip() == "None False", x11.stdout + x11.stderr
        return
    assert x11.stdout.strip().startswith("cannot open the display :97"), x11.stdout + x11.stderr
    assert x11.stdout.strip().endswith(" True"), x11.stdout


def test_a_window_builds_the_qt_types_it_uses() -> None:
    """The Qt names of :mod:`moas_gui.ui.qt` are looked up when first asked for (PySide6
    builds a class's type then): the server window's modules build its own, not the
    builder's tables and splitters; a name asked for later is the same Qt class."""
    probe = ("import moas_gui.ui.server_window\n"
             "from moas_gui.ui import qt\n"
             "held = vars(qt)\n"
             "before = ['QMainWindow' in held, 'QTableWidget' in held, 'QSplitter' in held]\n"
             "from PySide6.QtWidgets import QTableWidget\n"
             "print(before, qt.QTableWidget is QTableWidget, 'QTableWidget' in vars(qt))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          env=dict(os.environ, QT_QPA_PLATFORM="offscreen"), timeout=60,
                          check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[True, False, False] True True", done.stdout
