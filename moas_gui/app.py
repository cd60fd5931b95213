"""The server: configuration, engine, switch links, clients, logger and rotators on one loop.

This is the one place that wires the pieces together (``docs/architecture.md``).
It runs the same under the window (a qasync loop) and headless (plain asyncio):

    inputs                          ServerApp                      outputs
    N1MM packets, client requests   -> act(operation) -> Changes -> switch links (SwitchState)
    switch T/R events, rotators,                                     client events, the log
    the menus (Stop/Start Switches)

Every input of the engine is a frozen operation (:mod:`moas_gui.engine.operations`)
handed to :meth:`ServerApp.act`, the one door: it stamps the time, asks the
engine and sends the decision out.  The app starts every listener: the client
server, the N1MM Logger listener and the rotctld-compatible listeners.

Opening a configuration with errors changes nothing: the errors are logged and
returned, and whatever ran before keeps running.  Closing the server leaves
the relays as they are.  The last good state (the engine's selections and what
each switch was told) is saved whenever it changes and restored when the same
configuration is opened again, so a restart changes nothing on the air
(:mod:`moas_gui.state_store`).  Every listener is bound before the server
starts accepting clients.
"""

from __future__ import annotations

import asyncio
import functools
import logging
import sqlite3
import time
from collections.abc import Callable, Mapping
from pathlib import Path

from moas_gui import state_store
from moas_gui.addresses import WebPage, network_address
from moas_gui.antenna_log.journal import Journal, journal_path
from moas_gui.antenna_log.recorder import AntennaRecorder
from moas_gui.antenna_log.records import ContactPacket
from moas_gui.config import Config, LoadResult, load_config
from moas_gui.config.model import RotatorControl
from moas_gui.engine import Changes, Engine, NotRunning
from moas_gui.engine.focus import FocusKind
from moas_gui.engine.operations import (
    Hold,
    KeepSwitchAntennas,
    Operation,
    SelectDirection,
    SetFrequency,
    SetTransmitting,
    StartSwitches,
    StopSwitches,
    perform,
)
from moas_gui.engine.snapshot import export_selections
from moas_gui.engine.views import RadioView
from moas_gui.engine_backend import AgEngineBackend, EngineBackend
from moas_gui.errors import RequestRefused
from moas_gui.files import write_text_atomic
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.link import LinkStatus
from moas_gui.hw.rotators.base import RotatorView
from moas_gui.hw.rotators.manager import RotatorManager
from moas_gui.loop_watch import LoopWatch
from moas_gui.net.identity import current, enforce
from moas_gui.net.secrets import SecretGuard
from moas_gui.net.server import ClientServer
from moas_gui.rights import action_for
from moas_gui.running import (
    ROTCTLD_HOST,
    AntennaGenius,
    Running,
    ServerOptions,
    close_parts,
    start_clients,
    start_rotators,
    start_sources,
    start_switches,
)
from moas_gui.source_intake import RadioKey, ServerEvent, SourceIntake
from moas_gui.sources.base import SourceEvent
from moas_gui.sources.server import ServerSources
from moas_gui.state_store import SavedState, StateKeeper
from moas_gui.status import ServerStatus, overall_state

log = logging.getLogger(__name__)


class ServerApp:
    """The MOAS server, without any window."""

    def __init__(self, options: ServerOptions | None = None) -> None:
        self.options = options or ServerOptions()
        self._run: Running | None = None
        self._path: Path | None = None
        self._last_good = False
        """The running configuration is the last good version of ``_path`` (which has
        errors): ``--headless`` started it rather than nothing."""
        self._status_listeners: list[Callable[[ServerStatus], None]] = []
        self._alert_listeners: list[Callable[[str, str], None]] = []
        self._hold_listeners: list[Callable[[tuple[RadioView, ...]], None]] = []
        self._holds: tuple[tuple[int, int, str | None, float | None], ...] = ()
        self._status = ServerStatus()
        self._lock = asyncio.Lock()
        self._ag = AntennaGenius()
        """The Antenna Genius front: it outlives a configuration, closed by :meth:`close`."""
        self.secrets = SecretGuard.station()
        """The one place tokens and AG codes are checked (off the loop, budgeted), shared
        by every front; it also watches the operators file and ends a removed operator's
        sessions on all of them (moas_gui/net/secrets.py)."""
        self._antenna_log_on = self.options.antenna_log
        """The antenna journal is written (``--no-antenna-log`` and the menu turn it off)."""
        self.loop_watch = LoopWatch()
        """How late the event loop runs: watched from the first :meth:`open` on (but not
        while a file opens), its largest lag in the status (:mod:`moas_gui.loop_watch`)."""

    # -- what the window and tests read ---------------------------------------------
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

    def add_status_listener(self, listener: Callable[[ServerStatus], None]) -> None:
        self._status_listeners.append(listener)

    def add_alert_listener(self, listener: Callable[[str, str], None]) -> None:
        self._alert_listeners.append(listener)

    def add_hold_listener(self, listener: Callable[[tuple[RadioView, ...]], None]) -> None:
        """``listener`` is told the held radios (:meth:`holds`) whenever they change."""
        self._hold_listeners.append(listener)

    def holds(self) -> tuple[RadioView, ...]:
        """The radios whose antennas someone holds now (``held_by``, ``held_since``)."""
        engine = self.engine
        return () if engine is None else tuple(v for v in engine.radios() if v.held_by)

    def release_hold(self, station: int, radio: int) -> str | None:
        """The server window's Release: the hold goes, the frequency chooses again.
        Returns why it could not be done, or None."""
        try:
            engine = self._running().engine
            held_by = engine.radio_view(station, radio).held_by
            if held_by is not None:
                self.act(Hold(station, radio, None))
        except RequestRefused as exc:
            return exc.message
        if held_by is not None:
            log.info("The server window released the hold of radio %d/%d (held by %s)",
                     station, radio, held_by)
        return None

    def _tell_holds(self) -> None:
        holds = self.holds()
        said = tuple((v.station, v.radio, v.held_by, v.held_since) for v in holds)
        if said != self._holds:  # who holds what since when, not each radio's frequency
            self._holds = said
            for listener in self._hold_listeners:
                listener(holds)

    # -- opening and closing -----------------------------------------------------------
    async def open(self, path: str | Path, *, last_good: bool = False) -> LoadResult:
        """Load ``path`` and, when it has no errors, run it instead of what ran before.

        Each file that opens is kept beside its saved state (:func:`state_store.last_good_path`);
        ``last_good`` runs that kept copy instead of ``path`` (which has errors), under
        ``path``'s name and saved state, saying so in the log and the status.

        The loop's watch (:attr:`loop_watch`) pauses meanwhile: loading a file, building
        its engine and opening every port is the operator's pause, not the loop's lag."""
        self.loop_watch.stop()
        try:
            return await self._open(path, last_good)
        finally:
            self.loop_watch.start()

    async def _open(self, path: str | Path, last_good: bool) -> LoadResult:
        async with self._lock:
            started = time.perf_counter()
            source = state_store.last_good_path(Path(path)) if last_good else Path(path)
            result = load_config(source)
            for problem in result.warnings:
                log.warning("%s", problem)
            if result.config is None:
                for problem in result.errors:
                    log.error("%s", problem)
                log.error("%s was not opened: %d error%s%s", path, len(result.errors),
                          "s" if len(result.errors) != 1 else "",
                          "; the running configuration carries on" if self._run else "")
                return result
            if self._run is not None:
                log.info("Closing %s to open %s", self._status.file, Path(path).name)
                await self._close_running()
            self._path = Path(path)
            self._last_good = last_good
            try:
                await self._start(result.config)
            except Exception:
                # whatever started is closed again, so the title, status bar and tray
                # say "no configuration" instead of what is no longer true
                log.exception("%s could not be started", self._path.name)
                await self._close_running()
                self._update_status()
                raise
            log.info("Opened %s in %.0f ms", self._path.name, (time.perf_counter() - started) * 1000)
            if last_good:
                log.warning("RUNNING THE LAST GOOD VERSION of %s (kept %s): the file itself "
                            "has errors; fix it, then Restart", self._path,
                            time.strftime("%Y-%m-%d %H:%M", time.localtime(
                                source.stat().st_mtime)))
            else:
                # off the loop and not waited for: opening is done when the ports listen
                asyncio.get_running_loop().run_in_executor(None, _keep_last_good, self._path)
            return result

    async def open_or_last_good(self, path: str | Path) -> LoadResult:
        """:meth:`open`; when ``path`` has errors and a last good version of it is kept,
        that one (a station computer restarted after an edit that broke the file runs
        the version that last ran, rather than nothing)."""
        result = await self.open(path)
        if result.config is None and state_store.last_good_path(Path(path)).is_file():
            result = await self.open(path, last_good=True)
        return result

    async def restart(self) -> LoadResult | None:
        """Reopen the current file (File > Restart), checked first: a file that now has
        errors is not opened and the running configuration carries on (:meth:`open`
        closes it only for a file that loads); None when no file is open."""
        if self._path is None:
            return None
        return await self.open(self._path)

    async def close(self) -> None:
        """Stop serving; the relays stay as they are."""
        async with self._lock:
            if self._run is not None:
                await self._close_running()
            await self._ag.close()
            self.secrets.close()
            self.secrets = SecretGuard(self.secrets.book)  # a server opened again starts afresh
            self._path = None
            self._update_status()
            self.loop_watch.stop()

    async def _start(self, config: Config) -> None:
        loop = asyncio.get_running_loop()
        engine = Engine(config, now=loop.time())
        intake = SourceIntake(engine, self.act, self._publish_radio)
        self._run = run = Running(config=config, engine=engine, intake=intake)
        saved = self._restore(run)
        if self._antenna_log_on:
            await self._open_antenna_log(run)
        start_switches(run, self.options, saved or SavedState(""),
                       self._link_status, self._switch_tr, self._switch_antennas,
                       self._switch_seen)
        # every listener (the logger's port, the rotators' rotctld ports) is bound
        # before clients are accepted, so nothing a client sees as "ready" can miss a packet
        await start_rotators(run, self.options, self._rotator_changed, self._select_direction)
        await start_sources(run, self.options, self._source_event, self._contact)
        await start_clients(run, self.options, EngineBackend(self), self.secrets)
        await self._ag.sync(self.options, config, AgEngineBackend(self),
                            f"MOAS_{self._path.stem}" if self._path is not None else "MOAS",
                            lambda: self.config.client_allow if self.config else None,
                            self.secrets)
        run.serving = True
        self._update_status()
        run.ticker = asyncio.get_running_loop().create_task(self._tick(run))

    async def _tick(self, run: Running) -> None:
        """Refresh the status (the number of clients) twice a second while ``run`` runs."""
        while self._run is run:
            await asyncio.sleep(0.5)
            self._update_status()

    async def _close_running(self) -> None:
        run, self._run = self._run, None
        if run is None:
            return
        run.intake.close()  # a batch of the sources still waiting is dropped
        if run.ticker is not None:
            run.ticker.cancel()  # and awaited by close_parts
        if run.keeper is not None:
            try:
                await run.keeper.flush()
            except Exception:
                log.exception("while saving the state")
            run.keeper.close()
        await close_parts(run)
        await self._close_antenna_log(run)
        self._update_status()

    # -- the saved state ---------------------------------------------------------------
    def _restore(self, run: Running) -> SavedState | None:
        """Start keeping the state of ``run``; put the saved one, if usable, into its engine."""
        if self._path is None:
            return None
        run.fingerprint, saved = state_store.restore(self._path, run.engine)
        if run.fingerprint:
            run.keeper = StateKeeper(state_store.state_path(self._path),
                                     functools.partial(self._collect_state, run))
        if saved is not None:
            run.intake.restore_focus(saved.focus)
        return saved

    def _collect_state(self, run: Running) -> SavedState:
        # what each box was last told, also while it is away (a restart during an outage
        # must still check the box, not load it), and what it was last seen holding
        held = {i: s for i, link in run.links.items() if (s := link.holds) is not None}
        seen = {i: v for i, link in run.links.items() if (v := link.seen) is not None}
        return SavedState(run.fingerprint, export_selections(run.engine), held, seen,
                          run.intake.focus_items())

    def _state_changed(self) -> None:
        run = self._run
        if run is not None and run.keeper is not None:
            run.keeper.changed()

    # -- switches ----------------------------------------------------------------------
    def _link_status(self, switch_id: int, status: LinkStatus) -> None:
        self._switch_status(switch_id, status.value)
        self._state_changed()

    def _switch_status(self, switch_id: int, status: str) -> None:
        run = self._run
        if run is None or switch_id not in run.switch_status:
            return
        before = run.switch_status[switch_id]
        if before == status:
            return
        run.switch_status[switch_id] = status
        if status == "unresponsive":
            # the link said where and why, once per outage, at Warning
            log.info("Switch %d is not responding", switch_id)
            if before == "ok":
                for listener in self._alert_listeners:
                    listener("MOAS switch lost", f"Switch {switch_id} stopped responding.")
        if run.clients is not None:
            run.clients.publish_switch({"id": switch_id, "status": status})
        self._update_status()

    def _switch_tr(self, switch_id: int, port: int, transmitting: bool) -> None:
        run = self._run
        if run is not None:  # not a late event of a link being closed
            self.act(SetTransmitting(switch_id, port, transmitting))
            radio = run.engine.radio_on_port(switch_id, port)
            if run.antenna_log is not None and radio is not None:
                run.antenna_log.transmitting(*radio, run.engine.radio_view(*radio).transmitting)

    def _switch_seen(self, switch_id: int, port: int, slots: tuple[int, int, int]) -> None:
        """A switch reported other antennas in use for ``port``: what it confirmed."""
        run = self._run
        if run is not None and run.antenna_log is not None:
            run.antenna_log.landed(switch_id, port, slots)

    # -- the antenna log (docs/antenna-log.md) -----------------------------------------------
    @property
    def antenna_journal(self) -> Journal | None:
        """The running configuration's antenna journal (a
        :class:`~moas_gui.antenna_log.records.JournalReader`); None when it is off or no
        configuration runs."""
        run = self._run
        return run.antenna_log.journal if run is not None and run.antenna_log else None

    @property
    def antenna_log_on(self) -> bool:
        return self._antenna_log_on

    async def set_antenna_log(self, on: bool) -> None:
        """Turn the antenna journal on or off (the menu; ``--no-antenna-log`` starts off).
        Off closes the file; on opens the running configuration's again."""
        self._antenna_log_on = on
        run = self._run
        if run is None:
            return
        if on and run.antenna_log is None:
            await self._open_antenna_log(run)
            self._land_all(run)
        elif not on:
            await self._close_antenna_log(run)
        log.info("Antenna log %s", "on" if run.antenna_log is not None else "off")

    @staticmethod
    def _land_all(run: Running) -> None:
        """What each box reports holding now, to the antenna log."""
        if run.antenna_log is not None:
            for link in run.links.values():
                for port, slots in enumerate(link.seen or (), start=1):
                    run.antenna_log.landed(link.switch_id, port, slots)

    async def _open_antenna_log(self, run: Running) -> None:
        if self._path is None:
            return
        path = journal_path(self._path)
        try:
            # the file is made (and pruned) off the loop
            journal = await asyncio.get_running_loop().run_in_executor(None, Journal, path)
        except (OSError, sqlite3.Error) as exc:
            log.warning("The antenna log %s cannot be opened (%s): the server runs without it",
                        path, exc)
            return
        if self._run is not run or run.antenna_log is not None or not self._antenna_log_on:
            # the configuration closed, or the log was turned off or on again meanwhile
            await asyncio.get_running_loop().run_in_executor(None, journal.close)
            return
        run.antenna_log = AntennaRecorder(journal, run.config, run.engine,
                                          clock=self.options.antenna_log_clock or time.time)

    async def _close_antenna_log(self, run: Running) -> None:
        recorder, run.antenna_log = run.antenna_log, None
        if recorder is not None:
            recorder.stopping()
            await asyncio.get_running_loop().run_in_executor(None, recorder.journal.close)

    def _contact(self, packet: ContactPacket, station: int | None, radio: int | None) -> None:
        """A logger's contact packet (the N1MM listener), to the journal when it is on."""
        run = self._run
        if run is not None and run.antenna_log is not None:
            run.antenna_log.contact(packet, station, radio)

    def _switch_antennas(self, switch_id: int, held: Mapping[int, tuple[int, int, int]],
                         transmitting: frozenset[int]) -> None:
        """A switch holds other antennas for some ports (``held``: slots by port) than
        the saved state says: the box wins, and the engine takes them all in one
        operation (the link logged which and why)."""
        if self._run is not None:
            self.act(KeepSwitchAntennas(switch_id, tuple(
                (port, slots[0], slots[1]) for port, slots in sorted(held.items()))))

    def end_operator(self, name: str) -> int:
        """Ends the sessions of operator ``name`` (just removed) on every front; how many,
        those the server had already ended itself on noticing the file's change
        included."""
        earlier = self.secrets.recently_ended(name)
        ended = self.secrets.end_operator(name)
        if ended or not earlier:
            log.info('Operator "%s" was removed: %d session%s ended', name, ended + earlier,
                     "" if ended + earlier == 1 else "s")
        return ended + earlier

    def reset_switches(self) -> None:
        """File > Reset Switches: reset every switch and set the antennas in use again."""
        if self._run is None:
            return
        log.info("Resetting the switches")
        for link in self._run.links.values():
            link.reset()

    def stop_switches(self) -> None:
        """File > Stop Switches: deactivate every switch (all relays off)."""
        run = self._run
        if run is None or run.stopped:
            return
        self.act(StopSwitches())  # logs "Switches stopped: all relays off"; the links follow
        self._update_status()

    def start_switches(self) -> None:
        run = self._run
        if run is None or not run.stopped:
            return
        self.act(StartSwitches())  # logs "Switches started"; the links follow
        self._update_status()

    async def save_switch_data(self, path: str | Path) -> Path:
        """File > Save Switch Data: every switch's status replies and tables, to ``path``."""
        run = self._run
        if run is None:
            raise RuntimeError("no configuration is open")
        target = Path(path)
        parts = []
        for switch_id, link in sorted(run.links.items()):
            part = target.with_name(f".{target.name}.switch{switch_id}")
            try:
                await link.save_data(part)
                parts.append(part.read_text(encoding="utf-8"))
            finally:
                part.unlink(missing_ok=True)
        write_text_atomic(target, "\n".join(parts))  # never half a file, whatever happens
        return target

    # -- the one door into the engine ------------------------------------------------------
    def act(self, op: Operation) -> set[RadioKey]:
        """Apply ``op`` now and send the decision out (:meth:`apply_changes`); returns
        the radios whose entries were published to clients.

        Raises :class:`~moas_gui.engine.EngineError` when the rules refuse (nothing
        changes then), :class:`~moas_gui.engine.NotRunning` when no configuration
        runs; each caller turns that into its own answer (a client's error reply,
        a log line, a rotator's refusal).
        """
        run = self._run
        if run is None:
            raise NotRunning("No configuration is open")
        action = action_for(op, run.config)
        if action is not None:
            enforce(action)  # the role of the client asking, if any; logs who did it
        changes = perform(run.engine, op, now=asyncio.get_running_loop().time())
        if action is not None and run.antenna_log is not None and changes.radios:
            who = current()
            if who is not None and who.operator is not None:
                run.antenna_log.chosen_by(who.operator.name,
                                          {(r.station, r.radio) for r in changes.radios})
        # a frequency, or a hold released (the frequency chooses again), is automatic
        automatic = isinstance(op, SetFrequency) or (isinstance(op, Hold) and op.by is None)
        return self.apply_changes(changes, automatic=automatic)

    def apply_changes(self, changes: Changes, *, automatic: bool = False) -> set[RadioKey]:
        """Send an engine decision out: switch states to links, news to clients, lines to
        the log.  Returns the radios ``(station, radio)`` whose entries were published to
        clients (none while no client server runs).  ``automatic``: a frequency (a
        logger's, a client's ``frequency``) decided it, so its relay changes keep the
        switches' relay dwell; anything else is an operator's and goes out at once."""
        published: set[RadioKey] = set()
        run = self._run
        if run is None:
            return published
        for switch_id, state in changes.switches.items():  # the switches first: the
            link = run.links.get(switch_id)               # quickest to the first byte
            if link is not None:
                link.apply(state, automatic=automatic)
        if run.keeper is not None:
            run.keeper.changed()
        for line in changes.log:
            log.info("%s", line)
        for line in changes.details:
            log.debug("%s", line)
        if run.rotators is not None and changes.radios:
            # an Electrical rotator points where its antenna in use points, however
            # that antenna was chosen (a button, a band change, a turn)
            for rotator in run.config.rotators:
                if rotator.control is RotatorControl.ELECTRICAL:
                    heading = run.engine.electrical_heading(rotator.id)
                    if heading is not None:
                        run.rotators.note_direction(rotator.id, heading)
        if run.clients is not None:
            published = self._tell_clients(run.clients, changes)
        if changes.radios:
            self._ag.radios_changed({(ref.station, ref.radio) for ref in changes.radios})
            self._tell_holds()
        if run.antenna_log is not None and run.antenna_log.switches_running(run.engine.running):
            self._land_all(run)
        return published

    def _tell_clients(self, clients: ClientServer, changes: Changes) -> set[RadioKey]:
        """The changed radios' entries and a layout refresh to the clients; the radios
        published.  With no client connected there is nobody to tell: no entry is even
        built."""
        served = clients.client_count > 0
        for ref in changes.radios:
            if served:
                clients.publish_radio(self.radio_entry(ref.station, ref.radio))
        if changes.layouts and served:
            clients.layouts_may_have_changed()
        return {(ref.station, ref.radio) for ref in changes.radios}

    def _publish_radio(self, station: int, radio: int) -> None:
        """A radio's entry to the clients of the running configuration, when any are
        connected (otherwise the entry is not built)."""
        run = self._run
        if run is not None and run.clients is not None and run.clients.client_count > 0:
            run.clients.publish_radio(run.intake.radio_entry(station, radio))

    # -- frequency sources (loggers, rig daemons, OTRSP): moas_gui/source_intake.py --------
    def _running(self) -> Running:
        run = self._run
        if run is None:
            raise NotRunning("No configuration is open")
        return run

    def _source_event(self, event: ServerEvent) -> None:
        """The sink of every server source (docs/sources.md)."""
        if self._run is not None:
            self._run.intake.event(event)

    def set_focus(self, station: int, radio: int, kind: FocusKind, *,
                  origin: str = "a client", publish: bool = True) -> set[RadioKey]:
        """The station's transmit (``"active"``) or receive (``"focus"``) focus is on
        ``radio`` (:meth:`SourceIntake.set_focus`); returns the radios whose entry changed."""
        return self._running().intake.set_focus(station, radio, kind, origin=origin,
                                                publish=publish)

    def radio_entry(self, station: int, radio: int) -> dict[str, object]:
        """A radio's entry for clients: the engine's view plus ``active`` and ``focus``."""
        return self._running().intake.radio_entry(station, radio)

    def latest_reports(self) -> dict[tuple[object, ...], SourceEvent]:
        """The latest focus and run-or-search reports the loggers told
        (:meth:`SourceIntake.latest_reports`); empty while no configuration runs."""
        return self._run.intake.latest_reports() if self._run is not None else {}

    @property
    def sources(self) -> ServerSources | None:
        """The running sources, None when no configuration runs."""
        return self._run.sources if self._run else None

    @property
    def rotator_manager(self) -> RotatorManager | None:
        return self._run.rotators if self._run else None

    def _rotator_changed(self, view: RotatorView) -> None:
        run = self._run
        if run is not None and run.sources is not None:
            run.sources.rotator_heading(view.id, view.heading)
        if run is not None and run.antenna_log is not None:
            run.antenna_log.rotator(view.id, view.heading, moving=view.moving,
                                    online=view.online)
        if run is not None and run.clients is not None:
            run.clients.publish_rotator(view.to_json())

    def _select_direction(self, rotator_id: int, heading: int) -> None:
        if self._run is not None:
            self.act(SelectDirection(rotator_id, heading))

    # -- status ----------------------------------------------------------------------------
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


def _keep_last_good(path: Path) -> None:
    """Keep ``path``'s bytes (it opened) as its last good version; a failure is logged."""
    kept = state_store.last_good_path(path)
    try:
        data = path.read_bytes()
        if kept.is_file() and kept.read_bytes() == data:
            return
        state_store.write_atomic(kept, data)
    except OSError as exc:
        log.warning("Cannot keep the last good version of %s in %s: %s", path.name, kept,
                    exc.strerror or exc)


__all__ = ["ROTCTLD_HOST", "ServerApp", "ServerOptions"]
