"""What the frequency sources say, on its way into the engine through ``ServerApp.act``.

The server's sources (loggers, rig daemons, an SO2R logger's OTRSP port; see
docs/sources.md) hand their events to :meth:`SourceFocus.event`.  What arrives
in one turn of the event loop (an SO2R logger's packets for both radios) is
decided together: transmit and receive focus first, then frequencies with each
station's active radio first (docs/engine.md, "Transmit focus"), then the
antennas a logger chose by its AUX numbers.  Every change of the engine goes
through the one door the app gives (``act``); the focus itself is kept in the
running configuration's :class:`~moas_gui.engine.focus.FocusTable` and shown
in the radio entries clients get (``active``, ``focus``).

A logger never stops the server: an operation the engine refuses is logged
(Debug for frequencies and focus, which repeat, Info for an antenna a logger
asked for) and changes nothing.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable

from moas_gui.engine import NotRunning
from moas_gui.engine.focus import FocusKind, active_first
from moas_gui.engine.operations import Operation, Select, SetFrequency
from moas_gui.running import Running
from moas_gui.sources.base import (
    ActiveRadio,
    FocusRadio,
    FrequencyReport,
    SourceEvent,
    event_key,
)
from moas_gui.sources.base import Running as LoggerRunning
from moas_gui.sources.otrsp import AuxAntenna

log = logging.getLogger("moas_gui.app")

ServerEvent = SourceEvent | AuxAntenna
"""What a server source may hand on: a source event, or an antenna an OTRSP port chose."""


class SourceFocus:
    """The sources' way into the engine, and each station's transmit and receive focus.

    ``current`` gives the running configuration (None when none runs); ``act`` is
    the app's one door into the engine.
    """

    def __init__(self, current: Callable[[], Running | None],
                 act: Callable[[Operation], None]) -> None:
        self._current = current
        self._act = act

    def _run(self) -> Running:
        run = self._current()
        if run is None:
            raise NotRunning("No configuration is open")
        return run

    # -- the sink of every server source --------------------------------------------------
    def event(self, event: ServerEvent) -> None:
        """One event of a source; decided with the rest of this loop turn's events."""
        run = self._current()
        if run is None:
            return
        if isinstance(event, LoggerRunning):
            self._remember(event)
            return
        if not run.pending:
            asyncio.get_running_loop().call_soon(self._decide, run)
        run.pending.append(event)

    def _decide(self, run: Running) -> None:
        """Focus first, then frequencies with each station's active radio first, then
        antennas a logger chose; a radio whose focus changed and that no decision
        published is published once at the end."""
        events, run.pending = run.pending, []
        if run is not self._current():
            return
        focused: set[tuple[int, int]] = set()
        for event in events:
            if isinstance(event, ActiveRadio | FocusRadio):
                kind: FocusKind = "active" if isinstance(event, ActiveRadio) else "focus"
                try:
                    focused |= self.set_focus(event.station, event.radio, kind,
                                              origin=event.origin, publish=False)
                except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
                    log.debug("Logger %s for station %d radio %d ignored: %s", kind,
                              event.station, event.radio, exc)
                self._remember(event)
        run.published = set()
        reports = [e for e in events if isinstance(e, FrequencyReport)]
        for r in active_first(reports, lambda r: (r.station, r.radio), run.focus_table):
            self.frequency(r.station, r.radio, r.rx_khz, r.tx_khz)
        for event in events:
            if isinstance(event, AuxAntenna):
                self._aux_antenna(event)
        published, run.published = run.published, None
        if run.clients is not None:
            for station, radio in sorted(focused - (published or set())):
                run.clients.publish_radio(self.radio_entry(station, radio))

    def frequency(self, station: int, radio: int, khz: float, tx_khz: float | None) -> None:
        """A logger's frequency for a radio; refused ones are a Debug line."""
        if self._current() is None:
            return
        try:
            self._act(SetFrequency(station, radio, khz, tx_khz))
        except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
            log.debug("Logger frequency for station %d radio %d ignored: %s",
                      station, radio, exc)

    def _aux_antenna(self, event: AuxAntenna) -> None:
        try:
            self._act(Select(event.station, event.radio, event.antenna, "both", True))
        except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
            log.info("%s asked for antenna %d on station %d radio %d: %s",
                     event.origin, event.antenna, event.station, event.radio, exc)

    # -- focus -------------------------------------------------------------------------------
    def set_focus(self, station: int, radio: int, kind: FocusKind, *,
                  origin: str = "a client", publish: bool = True) -> set[tuple[int, int]]:
        """The station's transmit focus (``"active"``) or receive focus (``"focus"``) is
        on ``radio``; the radio entries of the station say so to clients (at once when
        ``publish``).  Returns the radios whose entry changed.  Raises the engine's
        not-found error for a radio that does not exist."""
        run = self._run()
        run.engine.radio_view(station, radio)
        before = run.focus_table.set(station, kind, radio)
        if before == radio:
            return set()
        if kind == "active":
            log.info("Station %d: transmit focus on radio %d (%s)", station, radio, origin)
        changed = {(station, number) for number in (before, radio) if number is not None}
        if publish and run.clients is not None:
            for _, number in sorted(changed):
                run.clients.publish_radio(self.radio_entry(station, number))
        return changed

    def radio_entry(self, station: int, radio: int) -> dict[str, object]:
        """A radio's entry for clients: the engine's view plus ``active`` and ``focus``."""
        run = self._run()
        entry: dict[str, object] = run.engine.radio_view(station, radio).to_dict()
        entry.update(run.focus_table.fields(station, radio))
        return entry

    def _remember(self, event: SourceEvent) -> None:
        """Transmit focus, receive focus and run state of a station, from its logger."""
        run = self._current()
        if run is not None:
            run.focus[event_key(event)] = event
            log.debug("Logger says: %s", event)

    def latest(self) -> dict[tuple[object, ...], SourceEvent]:
        """The latest focus and run-state events: ``("ActiveRadio", station)``,
        ``("FocusRadio", station)``, ``("running", station, radio)``."""
        run = self._current()
        return dict(run.focus) if run is not None else {}


__all__ = ["ServerEvent", "SourceFocus"]
