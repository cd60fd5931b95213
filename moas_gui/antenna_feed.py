"""The antenna log's wiring: everything the running server tells the antenna journal.

:class:`AntennaFeed` is the one part that knows whether the journal is on, opens and
closes the running configuration's journal (``docs/antenna-log.md``) and hands it what
the server hears.  The app holds one for its whole life and calls it from one place
each: a configuration starting (:meth:`~AntennaFeed.start`) and closing
(:meth:`~AntennaFeed.stop`), the menu (:meth:`~AntennaFeed.turn`), and the fan-out of
every engine decision (:meth:`~AntennaFeed.decided`) and of every rotator's news
(:meth:`~AntennaFeed.rotator`).  The switches' news reaches it from
:class:`~moas_gui.switch_events.SwitchEvents` (:meth:`~AntennaFeed.keyed`,
:meth:`~AntennaFeed.landed`), the loggers' contacts straight from the N1MM listener
(:meth:`~AntennaFeed.contact`).  With the journal off (or none open) each of these does
nothing.

The recorder itself (:class:`~moas_gui.antenna_log.recorder.AntennaRecorder`, kept in
``Running.antenna_log``, where the web page's report finds its journal) only compares
and queues; the file is made, pruned and closed off the loop.
"""

from __future__ import annotations

import asyncio
import logging
import sqlite3
import time
from collections.abc import Callable
from pathlib import Path

from moas_gui.antenna_log.journal import Journal, journal_path
from moas_gui.antenna_log.recorder import AntennaRecorder
from moas_gui.antenna_log.records import ContactPacket
from moas_gui.engine import Changes
from moas_gui.hw.rotators.base import RotatorView
from moas_gui.running import Running

log = logging.getLogger(__name__)


class AntennaFeed:
    """The antenna journal of whichever configuration runs, when the log is on."""

    def __init__(self, on: bool, clock: Callable[[], float] | None = None) -> None:
        self.on = on
        """The journal is written (``--no-antenna-log`` and the menu turn it off)."""
        self._clock = clock or time.time
        """The wall clock its rows are stamped with (tests replay on their own)."""
        self._run: Running | None = None
        """The configuration being fed (between :meth:`start` and :meth:`stop`)."""
        self._path: Path | None = None
        """That configuration's file, beside which its journal is kept."""

    @property
    def journal(self) -> Journal | None:
        """The open journal; None when the log is off or no configuration runs."""
        recorder = self._recorder
        return recorder.journal if recorder is not None else None

    @property
    def _recorder(self) -> AntennaRecorder | None:
        return self._run.antenna_log if self._run is not None else None

    # -- the configuration's life ------------------------------------------------------
    async def start(self, run: Running, path: Path | None) -> None:
        """``run`` starts (before its switches, so nothing they report is missed): its
        journal opens when the log is on."""
        self._run, self._path = run, path
        if self.on:
            await self._open(run)

    async def stop(self) -> None:
        """The configuration closes: transmissions still open end, the journal closes."""
        run, self._run = self._run, None
        if run is not None:
            await self._close(run)

    async def turn(self, on: bool) -> None:
        """The menu: off closes the journal; on opens the running configuration's again
        and hands it what each box reports holding now."""
        self.on = on
        run = self._run
        if run is None:
            return
        if on and run.antenna_log is None:
            await self._open(run)
            self._land_all(run)
        elif not on:
            await self._close(run)
        log.info("Antenna log %s", "on" if run.antenna_log is not None else "off")

    async def _open(self, run: Running) -> None:
        if self._path is None:
            return
        path = journal_path(self._path)
        loop = asyncio.get_running_loop()
        try:
            journal = await loop.run_in_executor(None, Journal, path)  # made and pruned
        except (OSError, sqlite3.Error) as exc:
            log.warning("The antenna log %s cannot be opened (%s): the server runs without it",
                        path, exc)
            return
        if self._run is not run or run.antenna_log is not None or not self.on:
            # the configuration closed, or the log was turned off or on again meanwhile
            await loop.run_in_executor(None, journal.close)
            return
        run.antenna_log = AntennaRecorder(journal, run.config, run.engine, clock=self._clock)

    @staticmethod
    async def _close(run: Running) -> None:
        recorder, run.antenna_log = run.antenna_log, None
        if recorder is not None:
            recorder.stopping()
            await asyncio.get_running_loop().run_in_executor(None, recorder.journal.close)

    @staticmethod
    def _land_all(run: Running) -> None:
        """What each box reports holding now, to the journal."""
        recorder = run.antenna_log
        if recorder is not None:
            for link in run.links.values():
                for port, slots in enumerate(link.seen or (), start=1):
                    recorder.landed(link.switch_id, port, slots)

    # -- what the server hears -----------------------------------------------------------
    def decided(self, changes: Changes, operator: str | None) -> None:
        """An engine decision went out: the radios an operator's request changed carry
        that operator's name; when the switches have just started again (Start
        Switches), what each box reports holding is in force again."""
        run, recorder = self._run, self._recorder
        if run is None or recorder is None:
            return
        if operator is not None and changes.radios:
            recorder.chosen_by(operator, {(r.station, r.radio) for r in changes.radios})
        if recorder.switches_running(run.engine.running):
            self._land_all(run)

    def keyed(self, switch_id: int, port: int) -> None:
        """The switch's T/R for ``port`` reached the engine: the radio on that port
        transmits or not, as the engine now says."""
        run, recorder = self._run, self._recorder
        if run is None or recorder is None:
            return
        radio = run.engine.radio_on_port(switch_id, port)
        if radio is not None:
            recorder.transmitting(*radio, run.engine.radio_view(*radio).transmitting)

    def landed(self, switch_id: int, port: int, slots: tuple[int, int, int]) -> None:
        """A switch reports other antennas in use for ``port``: what it confirmed."""
        recorder = self._recorder
        if recorder is not None:
            recorder.landed(switch_id, port, slots)

    def contact(self, packet: ContactPacket, station: int | None, radio: int | None) -> None:
        """A logger's contact packet (the N1MM listener's ``on_contact``)."""
        recorder = self._recorder
        if recorder is not None:
            recorder.contact(packet, station, radio)

    def rotator(self, view: RotatorView) -> None:
        """A rotator's news: its heading once it has settled."""
        recorder = self._recorder
        if recorder is not None:
            recorder.rotator(view.id, view.heading, moving=view.moving, online=view.online)


__all__ = ["AntennaFeed"]
