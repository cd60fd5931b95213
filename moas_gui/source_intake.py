"""What the frequency sources say, on its way into the engine through ``ServerApp.act``.

The server's sources (loggers, rig daemons, an SO2R logger's OTRSP port; see
docs/sources.md) hand their events to :meth:`SourceIntake.event`.  What arrives
in one turn of the event loop (an SO2R logger's packets for both radios) is
decided together: transmit and receive focus first, then frequencies with each
station's active radio first (docs/engine.md, "Transmit focus"), then the
antennas a logger chose by its AUX numbers.  Every change of the engine goes
through the one door the app gives (``act``, which returns the radios whose
entries it published); the focus itself is kept here, in the intake's
:class:`~moas_gui.engine.focus.FocusTable`, and shown in the radio entries
clients get (``active``, ``focus``).

One intake serves one running configuration: it is made when the configuration
starts and closed with it, so a batch still waiting when it closes is dropped.

A logger never stops the server: an operation the engine refuses is logged
(Debug for frequencies and focus, which repeat, Info for an antenna a logger
asked for) and changes nothing.  Every line a logger's packets cause (a change of
transmit focus, a refusal, what the logger says) is written at once and then once a
minute at most per kind and radio, the last of a burst with its count
(:class:`~moas_gui.sources.log_bursts.BurstLog`): a logger that flips its focus a
thousand times a second writes one line a minute.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Mapping

from moas_gui.engine import Engine
from moas_gui.engine.focus import FocusKind, FocusTable, active_first
from moas_gui.engine.operations import Operation, Select, SetFrequency
from moas_gui.sources.base import (
    ActiveRadio,
    AuxAntenna,
    FocusRadio,
    FrequencyReport,
    RunOrSearch,
    SourceEvent,
    event_key,
)
from moas_gui.sources.log_bursts import BurstLog

log = logging.getLogger(__name__)

ServerEvent = SourceEvent | AuxAntenna
"""What a server source may hand on: a source event, or an antenna an OTRSP port chose."""

RadioKey = tuple[int, int]
"""A radio as ``(station, radio)``."""

Act = Callable[[Operation], set[RadioKey]]
"""The app's one door into the engine: applies an operation, returns the radios whose
entries it published to clients."""


class SourceIntake:
    """The sources' way into the engine while one configuration runs, and what they told.

    It owns each station's transmit and receive focus (a :class:`FocusTable`), the
    latest focus and run-or-search reports of the loggers, and the batch of events of
    the current loop turn.  ``act`` is the app's one door into the engine;
    ``publish`` sends the entry of radio ``(station, radio)`` (:meth:`radio_entry`) to
    the clients, when any are connected.
    """

    def __init__(self, engine: Engine, act: Act,
                 publish: Callable[[int, int], None]) -> None:
        self._engine = engine
        self._act = act
        self._publish = publish
        self._focus = FocusTable()
        self._reports: dict[tuple[object, ...], SourceEvent] = {}
        self._batch: list[ServerEvent] = []
        self._held = 0
        """Bursts of a UDP listener under way (:meth:`hold`): their batch waits for the
        release rather than the loop's next turn."""
        self._closed = False
        self._info = BurstLog(log, logging.INFO)
        self._debug = BurstLog(log, logging.DEBUG)

    def close(self) -> None:
        """The configuration stops: later events and a waiting batch are dropped."""
        self._closed = True
        self._batch = []
        self._info.close()
        self._debug.close()

    # -- the sink of every server source --------------------------------------------------
    def event(self, event: ServerEvent) -> None:
        """One event of a source; decided with the rest of this loop turn's events (in
        the loop's next turn), or of the UDP burst that brought it (at its end)."""
        if self._closed:
            return
        if isinstance(event, RunOrSearch):
            self._remember(event)
            return
        if not self._batch and not self._held:
            asyncio.get_running_loop().call_soon(self._decide)
        self._batch.append(event)

    def hold(self) -> None:
        """A UDP listener's burst begins (:class:`~moas_gui.sources.base.Bursts`): what
        it hands on waits for :meth:`release`."""
        self._held += 1

    def release(self) -> None:
        """The burst has been read: its batch is decided now, in the loop turn that read
        it (a quiet band change then costs no turn of its own, and its first byte goes
        out a turn sooner); a batch a turn had already begun is decided with it."""
        self._held = max(0, self._held - 1)
        if not self._held and self._batch:
            self._decide()

    def _decide(self) -> None:
        """Focus first, then frequencies with each station's active radio first, then
        antennas a logger chose; a radio whose focus changed and that no decision
        published is published once at the end."""
        events, self._batch = self._batch, []
        if self._closed:
            return
        refocused: set[RadioKey] = set()
        for event in events:
            if isinstance(event, ActiveRadio | FocusRadio):
                kind: FocusKind = "active" if isinstance(event, ActiveRadio) else "focus"
                try:
                    refocused |= self.set_focus(event.station, event.radio, kind,
                                              origin=event.origin, publish=False)
                except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
                    self._debug.line(("focus refused", kind, event.station, event.radio),
                                     "Logger %s for station %d radio %d ignored: %s", kind,
                                     event.station, event.radio, exc)
                self._remember(event)
        published: set[RadioKey] = set()
        reports = [e for e in events if isinstance(e, FrequencyReport)]
        for r in active_first(reports, lambda r: (r.station, r.radio), self._focus):
            published |= self.frequency(r.station, r.radio, r.rx_khz, r.tx_khz)
        for event in events:
            if isinstance(event, AuxAntenna):
                published |= self._aux_antenna(event)
        for station, radio in sorted(refocused - published):
            self._publish(station, radio)

    def frequency(self, station: int, radio: int, khz: float,
                  tx_khz: float | None) -> set[RadioKey]:
        """A logger's frequency for a radio; refused ones are a Debug line.  Returns the
        radios whose entries were published."""
        if self._closed:
            return set()
        try:
            return self._act(SetFrequency(station, radio, khz, tx_khz))
        except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
            self._debug.line(("frequency refused", station, radio),
                             "Logger frequency for station %d radio %d ignored: %s",
                             station, radio, exc)
            return set()

    def _aux_antenna(self, event: AuxAntenna) -> set[RadioKey]:
        try:
            return self._act(Select(event.station, event.radio, event.antenna, "both", True))
        except Exception as exc:  # noqa: BLE001 - a logger must never stop the server
            self._info.line(("antenna refused", event.station, event.radio),
                            "%s asked for antenna %d on station %d radio %d: %s",
                            event.origin, event.antenna, event.station, event.radio, exc)
            return set()

    # -- transmit and receive focus ----------------------------------------------------------
    def set_focus(self, station: int, radio: int, kind: FocusKind, *,
                  origin: str = "a client", publish: bool = True) -> set[RadioKey]:
        """The station's transmit focus (``"active"``) or receive focus (``"focus"``) is
        on ``radio``; the radio entries of the station say so to clients (at once when
        ``publish``).  Returns the radios whose entry changed.  Raises the engine's
        not-found error for a radio that does not exist."""
        self._engine.radio_view(station, radio)
        before = self._focus.set(station, kind, radio)
        if before == radio:
            return set()
        if kind == "active":
            self._info.line(("transmit focus", station),
                            "Station %d: transmit focus on radio %d (%s)", station, radio, origin)
        changed = {(station, number) for number in (before, radio) if number is not None}
        if publish:
            for _, number in sorted(changed):
                self._publish(station, number)
        return changed

    def radio_entry(self, station: int, radio: int) -> dict[str, object]:
        """A radio's entry for clients: the engine's view plus ``active`` and ``focus``."""
        entry: dict[str, object] = self._engine.radio_view(station, radio).to_dict()
        entry.update(self._focus.fields(station, radio))
        return entry

    def restore_focus(self, saved: Mapping[int, tuple[int | None, int | None]]) -> None:
        """Each station's ``(active, focus)`` radios from a saved state."""
        for station, (active, focus) in saved.items():
            if active is not None:
                self._focus.set(station, "active", active)
            if focus is not None:
                self._focus.set(station, "focus", focus)

    def focus_items(self) -> dict[int, tuple[int | None, int | None]]:
        """Every station's ``(active, focus)`` radios, for the saved state."""
        return self._focus.items()

    # -- what the loggers told ----------------------------------------------------------------
    def _remember(self, event: SourceEvent) -> None:
        """Transmit focus, receive focus and run-or-search state of a station, from its
        logger."""
        if not self._closed:
            key = event_key(event)
            self._reports[key] = event
            self._debug.line(("says", *key), "Logger says: %s", event)

    def latest_reports(self) -> dict[tuple[object, ...], SourceEvent]:
        """The latest focus and run-or-search reports: ``("ActiveRadio", station)``,
        ``("FocusRadio", station)``, ``("running", station, radio)``."""
        return dict(self._reports)


__all__ = ["Act", "RadioKey", "ServerEvent", "SourceIntake"]
