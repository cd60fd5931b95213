"""The server: a door into the engine and a fan-out of its decisions, on one loop.

It wires the pieces together (``docs/architecture.md``), the same under the window
(a qasync loop) and headless (plain asyncio):

    inputs                          ServerApp                      outputs
    N1MM packets, client requests   -> act(operation) -> Changes -> switch links (SwitchState)
    switch T/R events, rotators,       apply_changes(changes)      client events, the log,
    the menus (Stop/Start Switches)                                the saved state, the journal

Every input of the engine is a frozen operation (:mod:`moas_gui.engine.operations`)
handed to :meth:`ServerApp.act`, the one door: it checks the asker's rights, stamps
the time, asks the engine and hands the decision to :meth:`ServerApp.apply_changes`,
which sends it out, the switches first.  A band change passes through here once:
the sources' intake (:mod:`moas_gui.source_intake`) calls ``act``, and nothing on its
way out calls back into this module.  What the window reads and is told is
:class:`~moas_gui.server_view.ServerView`; the switch links' callbacks are
:class:`~moas_gui.switch_events.SwitchEvents`; the antenna log's wiring is
:class:`~moas_gui.antenna_feed.AntennaFeed`; :mod:`moas_gui.running` builds the parts.

Opening a configuration with errors changes nothing: the errors are logged and
returned (:mod:`moas_gui.opening`), and whatever ran before keeps running.  Closing
the server leaves the relays as they are.  The state (the engine's selections, what
each switch was told) is saved when it changes and restored when the same
configuration opens again, so a restart changes nothing on the air
(:mod:`moas_gui.state_store`).  Every listener is bound before clients are accepted.
"""

from __future__ import annotations

import asyncio
import logging
import time
from pathlib import Path

from moas_gui import opening, state_store
from moas_gui.config import Config, LoadResult
from moas_gui.engine import Changes, Engine
from moas_gui.engine.focus import FocusKind
from moas_gui.engine.operations import (
    Hold,
    Operation,
    SelectDirection,
    SetFrequency,
    StartSwitches,
    StopSwitches,
    perform,
)
from moas_gui.engine_backend import AgEngineBackend, EngineBackend
from moas_gui.errors import RequestRefused
from moas_gui.hw.rotators.base import RotatorView
from moas_gui.net.identity import current, enforce
from moas_gui.net.secrets import SecretGuard
from moas_gui.rights import action_for
from moas_gui.running import (
    ROTCTLD_HOST,
    Running,
    ServerOptions,
    close_parts,
    save_switch_data,
    start_clients,
    start_rotators,
    start_sources,
    start_switches,
)
from moas_gui.server_view import ServerView
from moas_gui.source_intake import RadioKey
from moas_gui.state_store import SAVE_DELAY_HOOK, SavedState, save_delay_from_environment
from moas_gui.switch_events import SwitchEvents

log = logging.getLogger(__name__)


class ServerApp(ServerView):
    """The MOAS server, without any window."""

    def __init__(self, options: ServerOptions | None = None) -> None:
        super().__init__(options)
        self._lock = asyncio.Lock()
        self.secrets = SecretGuard.station()
        """The one place tokens and AG codes are checked (off the loop, budgeted), shared
        by every front; it also watches the operators file and ends a removed operator's
        sessions on all of them (moas_gui/net/secrets.py)."""
        self.switch_events = SwitchEvents(self.act, self.antenna, self._alert,
                                          self._update_status)
        """What the switch links say (moas_gui/switch_events.py)."""

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
            result = await self._open(path, last_good)
            if result.config is not None and self.options.settle_garbage:
                opening.settle_garbage()  # the collection is the opening's, not lag
            return result
        finally:
            self.loop_watch.start()

    async def _open(self, path: str | Path, last_good: bool) -> LoadResult:
        async with self._lock:
            started = time.perf_counter()
            result, source = opening.load(Path(path), last_good, self._run is not None)
            if result.config is None:
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
            opening.opened(self._path, source, last_good, started)
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
        engine = Engine(config, now=asyncio.get_running_loop().time())
        self._run = run = Running(config=config, engine=engine, act=self.act)
        saved = run.restore(self._path, self.options.save_delay) if self._path is not None else None
        await self.antenna.start(run, self._path)  # before the switches: none of their news lost
        events = self.switch_events
        events.start(run)
        start_switches(run, self.options, saved or SavedState(""), events.status,
                       events.transmitting, events.adopt, events.seen)
        # every listener (the logger's port, the rotators' rotctld ports) is bound
        # before clients are accepted, so nothing a client sees as "ready" can miss a packet
        await start_rotators(run, self.options, self._rotator_changed, self._select_direction)
        await start_sources(run, self.options, run.intake.event, self.antenna.contact)
        await start_clients(run, self.options, EngineBackend(self), self.secrets)
        await self._ag.sync(self.options, config, AgEngineBackend(self),
                            f"MOAS_{self._path.stem}" if self._path is not None else "MOAS",
                            lambda: self.config.client_allow if self.config else None,
                            self.secrets)
        run.serving = True
        self._update_status()
        run.ticker = asyncio.get_running_loop().call_later(0.5, self._tick, run)

    def _tick(self, run: Running) -> None:
        """Refresh the status (the number of clients) twice a second while ``run`` runs:
        a timer that arms itself again (one loop turn a refresh, where a task's sleep
        takes two: the sleep's end, then the task's step)."""
        if self._run is run:
            self._update_status()
            run.ticker = asyncio.get_running_loop().call_later(0.5, self._tick, run)

    async def _close_running(self) -> None:
        run, self._run = self._run, None
        if run is None:
            return
        self.switch_events.stop()  # a late event of a link being closed changes nothing
        run.intake.close()  # a batch of the sources still waiting is dropped
        await self.antenna.stop()  # open transmissions end; the journal closes
        if run.ticker is not None:
            run.ticker.cancel()  # before close_parts, which saves the state last
        await close_parts(run)
        self._update_status()

    # -- the operator's menus --------------------------------------------------------------
    async def set_antenna_log(self, on: bool) -> None:
        """Turn the antenna journal on or off (the menu; ``--no-antenna-log`` starts off)."""
        await self.antenna.turn(on)

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

    def release_hold(self, station: int, radio: int) -> str | None:
        """The server window's Release: the hold goes, the frequency chooses again.
        Returns why it could not be done, or None."""
        try:
            held_by = self._running().engine.radio_view(station, radio).held_by
            if held_by is not None:
                self.act(Hold(station, radio, None))
        except RequestRefused as exc:
            return exc.message
        if held_by is not None:
            log.info("The server window released the hold of radio %d/%d (held by %s)",
                     station, radio, held_by)
        return None

    def reset_switches(self) -> None:
        """File > Reset Switches: reset every switch and set the antennas in use again."""
        if self._run is None:
            return
        log.info("Resetting the switches")
        for link in self._run.links.values():
            link.reset()

    def stop_switches(self) -> None:
        """File > Stop Switches: deactivate every switch (all relays off)."""
        if self._run is not None and not self._run.stopped:
            self.act(StopSwitches())  # logs "Switches stopped: all relays off"; the links follow
            self._update_status()

    def start_switches(self) -> None:
        if self._run is not None and self._run.stopped:
            self.act(StartSwitches())  # logs "Switches started"; the links follow
            self._update_status()

    async def save_switch_data(self, path: str | Path) -> Path:
        """File > Save Switch Data: every switch's status replies and tables, to ``path``."""
        run = self._run
        if run is None:
            raise RuntimeError("no configuration is open")
        await save_switch_data(run, Path(path))
        return Path(path)

    # -- the one door into the engine, and the fan-out ---------------------------------------
    def act(self, op: Operation) -> set[RadioKey]:
        """Apply ``op`` now and send the decision out (:meth:`apply_changes`); returns
        the radios whose entries were published to clients.

        Raises :class:`~moas_gui.engine.EngineError` when the rules refuse (nothing
        changes then), :class:`~moas_gui.engine.NotRunning` when no configuration
        runs; each caller turns that into its own answer (a client's error reply,
        a log line, a rotator's refusal).
        """
        run = self._running()
        action = action_for(op, run.config)
        if action is not None:
            enforce(action)  # the role of the client asking, if any; logs who did it
        changes = perform(run.engine, op, now=asyncio.get_running_loop().time())
        who = current() if action is not None else None
        # a frequency, or a hold released (the frequency chooses again), is automatic
        automatic = isinstance(op, SetFrequency) or (isinstance(op, Hold) and op.by is None)
        return self.apply_changes(changes, automatic=automatic, operator=(
            who.operator.name if who is not None and who.operator is not None else None))

    def apply_changes(self, changes: Changes, *, automatic: bool = False,
                      operator: str | None = None) -> set[RadioKey]:
        """Send an engine decision out: switch states to links, then the saved state, the
        log, Electrical rotators, clients, the Antenna Genius front, the hold listeners and
        the antenna log.  Returns the radios ``(station, radio)`` whose entries were
        published to clients (none while no client server runs).  ``automatic``: a
        frequency (a logger's, a client's ``frequency``) decided it, so its relay changes
        keep the switches' relay dwell; anything else is an operator's and goes out at
        once.  ``operator``: the operator whose request it was, named in the journal."""
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
        if changes.radios:
            run.point_rotators()
        if run.clients is not None:
            for ref in changes.radios:  # an entry is built only when a client is connected
                run.publish_radio(ref.station, ref.radio)
                published.add((ref.station, ref.radio))
            if changes.layouts and run.clients.client_count > 0:
                run.clients.layouts_may_have_changed()
        if changes.radios:
            self._ag.radios_changed({(ref.station, ref.radio) for ref in changes.radios})
            self._tell_holds()
        self.antenna.decided(changes, operator)
        return published

    def set_focus(self, station: int, radio: int, kind: FocusKind, *,
                  origin: str = "a client", publish: bool = True) -> set[RadioKey]:
        """The station's transmit (``"active"``) or receive (``"focus"``) focus is on
        ``radio`` (:meth:`SourceIntake.set_focus`); returns the radios whose entry changed."""
        return self._running().intake.set_focus(station, radio, kind, origin=origin,
                                                publish=publish)

    def _rotator_changed(self, view: RotatorView) -> None:
        """A rotator's news: to N1MM's rotor window, the antenna log and the clients."""
        run = self._run
        if run is not None and run.sources is not None:
            run.sources.rotator_heading(view.id, view.heading)
        self.antenna.rotator(view)
        if run is not None and run.clients is not None:
            run.clients.publish_rotator(view.to_json())

    def _select_direction(self, rotator_id: int, heading: int) -> None:
        if self._run is not None:
            self.act(SelectDirection(rotator_id, heading))



__all__ = ["ROTCTLD_HOST", "SAVE_DELAY_HOOK", "ServerApp", "ServerOptions",
           "save_delay_from_environment"]
