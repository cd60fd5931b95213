"""Screenshots of the station builder (docs/builder.md), offscreen, at 1024x600 and 1280x800.

Opens the builder on a copy of examples/small-station.moas (and on a new station for the
guide), shows each page worth a picture and saves it as ``builder-PAGE-WxH.png``.

Usage: QT_QPA_PLATFORM=offscreen .venv/bin/python scripts/screenshot_builder.py [FOLDER]
(default docs/images)
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from moas_gui.builder.claims import release
from moas_gui.ui.builder_pages import LayoutPage, WhatIfPage
from moas_gui.ui.builder_window import BuilderWindow, ListPage, open_builder
from moas_gui.ui.qt import QApplication
from moas_gui.ui.server_window import ensure_application

SIZES = ((1024, 600), (1280, 800))


def settle(app: QApplication, until: Callable[[], bool] = lambda: True, seconds: float = 30) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        app.processEvents()
        if until():
            for _ in range(5):
                app.processEvents()
            return
        time.sleep(0.02)
    raise RuntimeError("screenshot_builder: what was waited for never showed")


def shoot(app: QApplication, window: BuilderWindow, name: str, folder: Path) -> None:
    for width, height in SIZES:
        window.resize(width, height)
        settle(app)
        path = folder / f"builder-{name}-{width}x{height}.png"
        window.grab().save(str(path))
        print(path)


def main() -> int:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images"
    app = ensure_application()
    work = Path(tempfile.mkdtemp(prefix="builder-shots-"))
    os.environ.setdefault("XDG_STATE_HOME", str(work / "state"))
    station = work / "small-station.moas"
    shutil.copyfile(ROOT / "examples" / "small-station.moas", station)
    window = open_builder(station)
    assert window is not None
    window.doc.set(("Antennas", 2, "Rotator"), 7)  # one error, to show a finding
    settle(app, lambda: window.checked is not None and len(window.checked.errors) == 1)
    page = window.go("Antennas")
    assert isinstance(page, ListPage) and page.list is not None
    page.list.select(0)
    shoot(app, window, "antennas", folder)
    window.doc.undo()
    settle(app, lambda: window.checked is not None and not window.checked.errors)
    window.go("Band x antenna")
    shoot(app, window, "grid", folder)
    window.doc.set(("Antennas", 1, "Control", 0, "Stations", 1, "Relays"), [0, 26])
    window.go("Relay map")
    shoot(app, window, "relays", folder)
    window.doc.undo()
    layout = window.go("Layout preview")
    assert isinstance(layout, LayoutPage)
    layout.band.setCurrentIndex(layout.band.findText("20 m"))
    layout.refresh()
    layout.buttons[0][0].click()
    shoot(app, window, "layout", folder)
    what_if = window.go("What if")
    assert isinstance(what_if, WhatIfPage)
    for (_, use, khz, keyed), frequency, transmits in zip(what_if.rows, ("14025", "14200"),
                                                          (True, False), strict=False):
        use.setChecked(True)
        khz.setText(frequency)
        keyed.setChecked(transmits)
    what_if.ask_button.click()
    settle(app, lambda: "station 1 radio 2" in what_if.answer.toPlainText())
    shoot(app, window, "what-if", folder)
    window.closing_confirmed = True
    window.close()
    release(station)
    new = open_builder(work / "new-station.moas")
    assert new is not None
    shoot(app, new, "guide", folder)
    new.close()
    release(work / "new-station.moas")
    shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
