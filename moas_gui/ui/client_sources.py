"""The client window's *Sources* menu: the same choice as ``moas-client --source``.

*Sources > Read from a logger or rig...* asks for a ``KIND[:OPTIONS]``
(docs/sources.md; ``rigctld``, ``otrsp:/dev/ttyUSB1,ant1.3=5``...), runs that
source in the window for the station the window shows, and tells the server
what it says, exactly as ``moas-client --headless`` does.  The choice is kept
in the settings (``sources/list``) and read again at the next start.  *Stop
reading* forgets it.  Changing the window's station restarts the sources for
the new station.  The dialog is opened with ``open()``, never ``exec()``
(no nested event loop under qasync).

*Sources > FlexRadios on the network* lists the FlexRadios whose discovery
broadcasts the window hears (UDP 4992: model, nickname, serial and address);
choosing one reads it as ``flex:ADDRESS:PORT`` (its transmitting slice is the
station's radio 1, the other slice in use radio 2; ``,radio2=0`` is added when the
station has one radio).  A FlexRadio read is listed
with where it stands, in words (connected, or offline and why).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from typing import Any

from moas_gui.sources.base import Source, SourceHub
from moas_gui.sources.flex import FlexSource
from moas_gui.sources.flex_api import API_PORT, FlexAnnouncement
from moas_gui.sources.flex_discovery import FlexDiscovery
from moas_gui.sources.forwarder import Forwarder
from moas_gui.sources.spec import SourceSpec, make_source, parse_spec
from moas_gui.ui.qt import QAction, QInputDialog, QSettings

log = logging.getLogger(__name__)

SETTINGS_KEY = "sources/list"


class ClientSources:
    """Runs the chosen sources for a :class:`~moas_gui.ui.client_window.ClientWindow`."""

    def __init__(self, window: Any, settings: QSettings, *,
                 flex_port: int = API_PORT) -> None:
        self.window = window
        self.settings = settings
        self.specs: list[SourceSpec] = []
        self.running: list[Source] = []
        self._running_specs: list[int] = []
        """``id()`` of the spec of each of :attr:`running`."""
        self.station: int | None = None
        self.forwarder = Forwarder(window.connection)
        self.hub = SourceHub(self.forwarder, logging.getLogger("moas_gui.sources"))
        self._restart: asyncio.Task[None] | None = None
        menu = window.menuBar().addMenu("&Sources")
        self.menu = menu
        self.add_action = QAction("Read from a logger or rig\u2026", window)
        self.add_action.triggered.connect(self.ask)
        self.stop_action = QAction("Stop reading", window)
        self.stop_action.triggered.connect(self.stop_all)
        menu.addAction(self.add_action)
        self.flex_menu = menu.addMenu("FlexRadios on the network")
        self.flex_menu.aboutToShow.connect(self.show_flex)
        self.flex_actions: list[QAction] = []
        self.flex_port = flex_port
        self.flex_discovery = FlexDiscovery(port=flex_port)
        self.flex_problem = ""
        """Why the FlexRadios' broadcasts cannot be heard, when they cannot."""
        self._listening = asyncio.get_event_loop().create_task(self._listen())
        menu.addAction(self.stop_action)
        menu.addSeparator()
        menu.aboutToShow.connect(self._show_list)
        self._listed: list[QAction] = []
        self._dialog: Any = None
        for text in self._saved():
            try:
                self.specs.append(parse_spec(text))
            except ValueError as exc:
                log.warning("The saved source %r is not used: %s", text, exc)
        self._show_list()
        window.station_box.currentIndexChanged.connect(self._station_changed)

    def _saved(self) -> list[str]:
        value: Any = self.settings.value(SETTINGS_KEY, [])
        if isinstance(value, str):
            return [value] if value else []
        return [str(v) for v in value] if isinstance(value, list | tuple) else []

    def _save(self) -> None:
        self.settings.setValue(SETTINGS_KEY, [s.text() for s in self.specs])
        self.settings.sync()

    def _show_list(self) -> None:
        for action in self._listed:
            self.menu.removeAction(action)
        self._listed = []
        by_spec = dict(zip(self._running_specs, self.running, strict=False))
        texts: list[str] = []
        for spec in self.specs:
            running = by_spec.get(id(spec))
            if isinstance(running, FlexSource):  # where it stands, then each radio's slice
                lines = running.describe()
                texts.append(f"Reading {spec.text()}: {running.state_text()}")
                texts += ["    " + line for line in lines[1:]]
            else:
                texts.append(f"Reading {spec.text()}")
        for text in texts:
            action = QAction(text, self.window)
            action.setEnabled(False)
            self.menu.addAction(action)
            self._listed.append(action)
        self.stop_action.setEnabled(bool(self.specs))

    # -- FlexRadios heard -------------------------------------------------------------------
    async def _listen(self) -> None:
        try:
            await self.flex_discovery.start()
        except OSError as exc:
            self.flex_problem = f"Cannot listen on UDP {self.flex_port}: {exc.strerror or exc}"
            log.warning("FlexRadios on the network cannot be listed: %s", self.flex_problem)

    def show_flex(self) -> None:
        """Fills *FlexRadios on the network* with the radios heard now."""
        for action in self.flex_actions:
            self.flex_menu.removeAction(action)
        self.flex_actions = []
        radios = self.flex_discovery.radios()
        for radio in radios:
            action = QAction(radio.label(), self.window)
            action.triggered.connect(lambda _=False, r=radio: self.choose_flex(r))
            self.flex_actions.append(action)
        if not radios:
            none = QAction(self.flex_problem or "No FlexRadio heard (their broadcasts do "
                           "not cross routers or VPNs: use Read from... flex:ADDRESS)",
                           self.window)
            none.setEnabled(False)
            self.flex_actions.append(none)
        for action in self.flex_actions:
            self.flex_menu.addAction(action)

    def choose_flex(self, radio: FlexAnnouncement) -> bool:
        """Reads ``radio``: its transmitting slice is radio 1 of the window's station, the
        other slice in use radio 2 when the station has one."""
        one_radio = self.window.radio_box.findText("2") < 0
        return self.choose(f"flex:{radio.ip}:{radio.port}" + (",radio2=0" if one_radio else ""))

    # -- choosing ---------------------------------------------------------------------------
    def ask(self) -> None:
        dialog = QInputDialog(self.window)
        dialog.setWindowTitle("Read from a logger or rig")
        dialog.setLabelText("KIND[:OPTIONS], for example rigctld:4532,radio=1 or "
                            "otrsp:/dev/ttyUSB1 (see docs/sources.md):")
        dialog.textValueSelected.connect(self.choose)
        self._dialog = dialog
        dialog.open()

    def choose(self, text: str) -> bool:
        """Adds the source ``text``; False (and the reason in the status line) if refused."""
        try:
            spec = parse_spec(text)
        except ValueError as exc:
            self.window._error(f"Source {text}: {exc}")
            return False
        self.specs.append(spec)
        self._save()
        self._show_list()
        self.restart()
        return True

    def stop_all(self) -> None:
        self.specs.clear()
        self._save()
        self._show_list()
        self.restart()

    # -- running ----------------------------------------------------------------------------
    def _station_changed(self, _index: int = 0) -> None:
        if self.window.station != self.station:
            self.restart()

    def restart(self) -> None:
        """Stops what runs and starts the chosen sources for the window's station."""
        previous = self._restart
        self._restart = asyncio.get_event_loop().create_task(self._run_again(previous))

    async def _run_again(self, previous: asyncio.Task[None] | None) -> None:
        if previous is not None:
            try:
                await asyncio.wait({previous})  # the restart before this one ends first
            except asyncio.CancelledError:
                previous.cancel()  # closing: the chain ends with this one (aclose waits)
                await asyncio.wait({previous})
                raise
            if not previous.cancelled():
                previous.exception()  # retrieved; its failure was its own to report
        await self._stop_running()
        self.station = self.window.station
        if self.station is None or not self.specs:
            return
        self.forwarder.start()
        for spec in self.specs:
            source = make_source(spec, self.station, self.hub)
            try:
                await source.start()
            except OSError as exc:
                self.window._error(f"Source {spec.text()} cannot be read: {exc}")
                continue
            self.running.append(source)
            self._running_specs.append(id(spec))
            log.info("Reading %s for station %d", spec.text(), self.station)

    async def _stop_running(self) -> None:
        running, self.running = self.running, []
        self._running_specs = []
        for source in running:
            with contextlib.suppress(Exception):
                await source.close()

    async def aclose(self) -> None:
        if self._restart is not None:
            self._restart.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await self._restart
        await self._stop_running()
        self._listening.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await self._listening
        await self.flex_discovery.close()
        await self.forwarder.aclose()


__all__ = ["SETTINGS_KEY", "ClientSources"]
