"""What the window, the tray and tests read of the server, and are told: :class:`ServerView`.

Nothing here changes the server: where clients, the browser page, the logger and the
Antenna Genius devices connect, who may (the open LAN, tokens, TLS), who transmits
now, the held radios, the running parts; and the listeners the window adds, told the
status, the held radios and alerts as they change.  :class:`~moas_gui.app.ServerApp`
is this view plus the configuration's life, the engine's one door and the fan-out
of its decisions.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from moas_gui.addresses import WebPage, network_address
from moas_gui.antenna_feed import AntennaFeed
from moas_gui.antenna_log.journal import Journal
from moas_gui.config import Config
from moas_gui.engine import Engine, NotRunning
from moas_gui.engine.views import RadioView
from moas_gui.hw.rotators.manager import RotatorManager
from moas_gui.loop_watch import LoopWatch
from moas_gui.running import AntennaGenius, Running, ServerOptions
from moas_gui.sources.base import SourceEvent
from moas_gui.sources.server import ServerSources
from moas_gui.status import ServerStatus, overall_state

if TYPE_CHECKING:  # the built-in emulator is loaded when a switch's port names it
    from moas_gui.hw.moas2.emulator.box import EmulatedBox


class ServerView:
    """The server as it is read; the running configuration is ``_run`` (None: none)."""

    def __init__(self, options: ServerOptions | None = None) -> None:
        self.options = options or ServerOptions()
        self._run: Running | None = None
        self._path: Path | None = None
        self._last_good = False
        """The running configuration is the last good version of ``_path`` (which has
        errors): ``--headless`` started it rather than nothing."""
        self._status = ServerStatus()
        self._status_listeners: list[Callable[[ServerStatus], None]] = []
        self._alert_listeners: list[Callable[[str, str], None]] = []
        self._hold_listeners: list[Callable[[tuple[RadioView, ...]], None]] = []
        self._holds: tuple[tuple[object, ...], ...] = ()
        self._ag = AntennaGenius()
        """The Antenna Genius front: it outlives a configuration, closed with the server."""
        self.antenna = AntennaFeed(self.options.antenna_log, self.options.antenna_log_clock)
        """The antenna log's wiring (moas_gui/antenna_feed.py)."""
        self.loop_watch = LoopWatch()
        """How late the event loop runs: watched from the first open on (but not while
        a file opens), its largest lag in the status (:mod:`moas_gui.loop_watch`)."""

    def _running(self) -> Running:
        run = self._run
        if run is None:
            raise NotRunning("No configuration is open")
        return run

    @property
    def config(self) -> Config | None:
        return self._run.config if self._run else None

    @property
    def path(self) -> Path | None:
        """The configuration file that runs (or ran last), None before the first open."""
        return self._path

    @property
    def engine(self) -> Engine | None:
        return self._run.engine if self._run else None

    @property
    def status(self) -> ServerStatus:
        return self._status

    @property
    def switches_stopped(self) -> bool:
        return bool(self._run and self._run.stopped)

    @property
    def sources(self) -> ServerSources | None:
        """The running sources, None when no configuration runs."""
        return self._run.sources if self._run else None

    @property
    def rotator_manager(self) -> RotatorManager | None:
        return self._run.rotators if self._run else None

    # -- where to connect, and who may ------------------------------------------------
    @property
    def client_address(self) -> tuple[str, int] | None:
        """Where clients connect (host, port), once the client server listens."""
        if self._run is None or self._run.clients is None:
            return None
        host = self.options.bind
        if host in ("0.0.0.0", "", "::"):
            host = "127.0.0.1"
        return host, int(self._run.clients.port)

    @property
    def ag_ports(self) -> list[int]:
        """The Antenna Genius devices' TCP ports (docs/antenna-genius.md), empty when
        not served."""
        return self._ag.ports

    @property
    def web_address(self) -> tuple[str, int, bool] | None:
        """The browser page (host, port, over TLS), once it is served; the host is this
        computer's address on its network when the server listens on every interface."""
        run = self._run
        if run is None or run.web is None or run.clients is None:
            return None
        host = self.options.bind
        if host in ("0.0.0.0", "", "::"):
            host = network_address()
        return host, int(run.web.port), run.clients.tls is not None

    @property
    def web_page(self) -> WebPage | None:
        """The browser page as View > Pair a device shows it: the address it listens on
        (as bound), its port, TLS and the certificate's fingerprint; None when not served."""
        run = self._run
        if run is None or run.web is None or run.clients is None:
            return None
        return WebPage(self.options.bind, int(run.web.port), run.clients.tls is not None,
                       self.client_fingerprint)

    @property
    def client_fingerprint(self) -> str | None:
        """The SHA-256 fingerprint of the certificate the client port serves; None
        without TLS (or before the client server runs)."""
        run = self._run
        if run is None or run.clients is None or run.clients.tls is None:
            return None
        return run.clients.fingerprint

    @property
    def security(self) -> tuple[str, str] | None:
        """What the window says of who may connect: a short text and a longer one
        (the open LAN, TLS and its fingerprint), None while no client server runs."""
        run = self._run
        if run is None or run.clients is None:
            return None
        parts = ["LAN open: no token needed" if not self.options.require_token
                 else "tokens required"]
        detail = [("Clients from the allowed networks (ClientAllow) need no token "
                   "(moas-server --require-token changes that)") if not
                  self.options.require_token else
                  "Every client but this computer's programs needs an operator's token"]
        seen = self.client_fingerprint
        if seen is not None:
            parts.append(f"TLS {seen[:11]}\u2026")
            detail.append(f"TLS certificate SHA-256 fingerprint: {seen}")
        return " \u00b7 ".join(parts), "\n".join(detail)

    @property
    def n1mm_address(self) -> tuple[str, int] | None:
        if self._run is None or self._run.n1mm is None or self._run.n1mm.port is None:
            return None
        host = self.options.udp_bind
        return ("127.0.0.1" if host in ("0.0.0.0", "", "::") else host), int(self._run.n1mm.port)

    # -- the switches, the radios, the loggers, the journal --------------------------------
    def keyed_radios(self) -> list[str]:
        """Who transmits now, as each switch last said ("station 1 radio 1 (switch 1 port
        1)"): what Stop and Reset Switches name before they open relays under a key.  A
        switch that has not said yet (it does not answer) names nobody: the switches
        that answer are the ones a Stop or a Reset reaches."""
        run = self._run
        if run is None:
            return []
        names = []
        for switch_id, link in sorted(run.links.items()):
            for port in sorted(link.session.keyed() or ()):
                radio = run.engine.radio_on_port(switch_id, port)
                where = f"switch {switch_id} port {port}"
                names.append(f"station {radio[0]} radio {radio[1]} ({where})"
                             if radio is not None else where)
        return names

    def emulators(self) -> dict[int, EmulatedBox]:
        """The in-process emulators of switches whose port is ``"emulator"``."""
        if self._run is None:
            return {}
        return {switch_id: link.emulator for switch_id, link in self._run.links.items()
                if link.emulator is not None}

    def holds(self) -> tuple[RadioView, ...]:
        """The radios whose antennas someone holds now (``held_by``, ``held_since``)."""
        engine = self.engine
        return () if engine is None else tuple(v for v in engine.radios() if v.held_by)

    def radio_entry(self, station: int, radio: int) -> dict[str, object]:
        """A radio's entry for clients: the engine's view plus ``active`` and ``focus``."""
        return self._running().intake.radio_entry(station, radio)

    def latest_reports(self) -> dict[tuple[object, ...], SourceEvent]:
        """The latest focus and run-or-search reports the loggers told
        (:meth:`SourceIntake.latest_reports`); empty while no configuration runs."""
        return self._run.intake.latest_reports() if self._run is not None else {}

    @property
    def antenna_journal(self) -> Journal | None:
        """The running configuration's antenna journal (a
        :class:`~moas_gui.antenna_log.records.JournalReader`); None when it is off or no
        configuration runs."""
        return self.antenna.journal

    @property
    def antenna_log_on(self) -> bool:
        return self.antenna.on

    # -- what the window is told ------------------------------------------------------------
    def add_status_listener(self, listener: Callable[[ServerStatus], None]) -> None:
        self._status_listeners.append(listener)

    def add_alert_listener(self, listener: Callable[[str, str], None]) -> None:
        self._alert_listeners.append(listener)

    def add_hold_listener(self, listener: Callable[[tuple[RadioView, ...]], None]) -> None:
        """``listener`` is told the held radios (:meth:`holds`) whenever they change."""
        if not self._hold_listeners:  # untracked while nobody listened: from now on
            self._holds = self._said_holds(self.holds())
        self._hold_listeners.append(listener)

    def _alert(self, title: str, text: str) -> None:
        for listener in self._alert_listeners:
            listener(title, text)

    @staticmethod
    def _said_holds(holds: tuple[RadioView, ...]) -> tuple[tuple[object, ...], ...]:
        return tuple((v.station, v.radio, v.held_by, v.held_since) for v in holds)

    def _tell_holds(self) -> None:
        if not self._hold_listeners:
            return  # (a headless server: every radio's view is not walked at each change)
        holds = self.holds()
        said = self._said_holds(holds)
        if said != self._holds:  # who holds what since when, not each radio's frequency
            self._holds = said
            for listener in self._hold_listeners:
                listener(holds)

    def _update_status(self) -> None:
        self._tell_holds()  # a configuration opened or closed: no hold outlives it
        run = self._run
        if run is not None and not run.serving:
            return  # still starting: nothing shown runs before its ports listen
        if run is None:
            status = ServerStatus(loop_lag_ms=self.loop_watch.largest_ms)
        else:
            switches = tuple(sorted(run.switch_status.items()))
            shown = tuple((i, "stopped" if run.stopped else s) for i, s in switches)
            status = ServerStatus(
                state=overall_state(True, run.stopped, [s for _, s in switches]),
                file=(None if self._path is None else self._path.name
                      + (" (last good version: the file has errors)"
                         if self._last_good else "")),
                switches=shown,
                clients=run.clients.client_count if run.clients is not None else 0,
                loop_lag_ms=self.loop_watch.largest_ms,
            )
        if status != self._status:
            self._status = status
            for listener in self._status_listeners:
                listener(status)


__all__ = ["ServerView"]
