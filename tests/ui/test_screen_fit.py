"""Every window opens within the available screen: 1024x600 and 1280x800 at scale 1,
1920x1080 at scale 2 (960x540 device-independent pixels), for the server window,
the built-in and the standalone client and the emulator window; the emulator opens
wide enough to show all 64 relays where the screen has room for them.

Each size runs tests/ui/screen_probe.py in its own process under Qt's offscreen
platform, given that screen by a configuration file and QT_SCALE_FACTOR."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.ui.screen_fit import FRAME_ROOM

HERE = Path(__file__).resolve().parent
BIG = HERE.parents[1] / "examples" / "big-station.moas"


@pytest.mark.realtime
@pytest.mark.parametrize(("width", "height", "scale"),
                         [(1024, 600, 1), (1280, 800, 1), (1920, 1080, 2)])
def test_every_window_opens_within_the_screen(tmp_path: Path, width: int, height: int,
                                              scale: int) -> None:
    config = tmp_path / "screen.json"
    config.write_text(json.dumps({"screens": [
        {"name": "probe", "x": 0, "y": 0, "width": width, "height": height,
         "logicalDpi": 96, "logicalBaseDpi": 96, "dpr": 1}]}))
    env = dict(os.environ, QT_QPA_PLATFORM=f"offscreen:configfile={config}",
               QT_SCALE_FACTOR=str(scale), XDG_CONFIG_HOME=str(tmp_path / "config"),
               XDG_RUNTIME_DIR=str(tmp_path))
    done = subprocess.run([sys.executable, str(HERE / "screen_probe.py"), str(tmp_path),
                           str(BIG)], env=env, capture_output=True, text=True, check=False,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    left, top, area_w, area_h = seen["area"]
    assert (area_w, area_h) == (width // scale, height // scale)
    for name, (x, y, w, h) in seen["windows"].items():  # frames, title bar included
        assert x >= left and y >= top, (name, seen["windows"][name])
        assert x + w <= left + area_w, (name, seen["windows"][name], seen["area"])
        assert y + h <= top + area_h, (name, seen["windows"][name], seen["area"])
    room_w, _room_h = FRAME_ROOM
    relays = seen["emulator relays width"]
    if relays + 40 <= area_w - room_w:  # the screen has room for every relay
        assert seen["emulator relays hidden"] == 0, seen
        assert seen["windows"]["emulator"][2] > relays
