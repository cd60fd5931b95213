"""Helpers shared by the tests that plug an emulated switch into a server: the box on a
pseudo-terminal behind a stable path, plugged and unplugged like a USB cable; and a
switch link's listener that hands what it hears to the test's callables."""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Mapping
from pathlib import Path

from moas_gui.engine.switchstate import SwitchState
from moas_gui.hw.moas2.actions import LinkStatus, Slots
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, serve
from moas_gui.hw.moas2.listener import SwitchListener


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


class Heard(SwitchListener):
    """A switch link's listener for tests: what the link says goes to the callables given
    (each optional); after an adoption, ``wanted()`` (if given) is the engine's state."""

    def __init__(self, *, status: Callable[[LinkStatus], None] | None = None,
                 tr: Callable[[int, bool], None] | None = None,
                 error: Callable[[str], None] | None = None,
                 adopt: Callable[[Mapping[int, Slots], frozenset[int]], None] | None = None,
                 wanted: Callable[[], SwitchState] | None = None,
                 seen: Callable[[int, Slots], None] | None = None) -> None:
        self._status, self._tr, self._error = status, tr, error
        self._adopt, self._wanted, self._seen = adopt, wanted, seen

    def status(self, status: LinkStatus) -> None:
        if self._status is not None:
            self._status(status)

    def transmitting(self, station: int, on: bool) -> None:
        if self._tr is not None:
            self._tr(station, on)

    def box_error(self, text: str) -> None:
        if self._error is not None:
            self._error(text)

    def adopt(self, stations: Mapping[int, Slots],
              transmitting: frozenset[int]) -> SwitchState | None:
        if self._adopt is not None:
            self._adopt(stations, transmitting)
        return self._wanted() if self._wanted is not None else None

    def seen(self, station: int, slots: Slots) -> None:
        if self._seen is not None:
            self._seen(station, slots)
