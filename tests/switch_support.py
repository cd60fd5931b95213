"""Helpers shared by the tests that plug an emulated switch into a server: the box on a
pseudo-terminal behind a stable path, plugged and unplugged like a USB cable."""

from __future__ import annotations

import asyncio
from pathlib import Path

from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve


class Cable:
    """An emulated switch on a pseudo-terminal behind a stable link: plug and unplug."""

    def __init__(self, link: Path) -> None:
        self.link = link
        self.box: EmulatedBox | None = None
        self.endpoint: PtyEndpoint | None = None

    def plug(self) -> EmulatedBox:
        self.box = EmulatedBox()
        self.endpoint = PtyEndpoint()
        serve(self.box, self.endpoint, asyncio.get_running_loop())
        make_link(self.endpoint.path, self.link)
        return self.box

    def unplug(self) -> None:
        assert self.endpoint is not None and self.box is not None
        self.link.unlink()
        self.endpoint.close()
        self.box.close()
