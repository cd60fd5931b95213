"""How a switch found on (re)connection is brought back: the reconnection policy.

Pure: what the box answered (:class:`Survey`) and what it was last told in, a
:class:`Reconciliation` out.  :mod:`.sync` says which commands take a box from one
state to another; this module says what a box found after a restart, a replug or a
stall is taken to hold, station by station, and which stations' antennas on it win
over the saved state.  The session (:mod:`.session`) turns the result into a plan
through :func:`.plan.choose_plan` and :func:`.plan.guard`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType

from ...engine.switchstate import NO_ANTENNA, STATIONS, StationAntennas, SwitchState
from .actions import Slots
from .messages import BoxStatus, PolarityStatus, Pong, RelayStatus, TRState
from .sync import UNSURE


@dataclass(frozen=True, slots=True)
class Survey:
    """What a box answered when the link asked what it holds."""

    pong: Pong
    box: BoxStatus
    polarity: PolarityStatus
    relays: RelayStatus

    def keyed(self) -> frozenset[int]:
        """Stations that transmit, or may: a station shown inhibited by command (``I``)
        does not say whether its key line is up, so it counts as transmitting."""
        return frozenset(
            n
            for n, letter in zip(STATIONS, self.box.tr, strict=False)
            if letter is not TRState.RECEIVE
        ) | frozenset(STATIONS[len(self.box.tr) :])

    def slots(self, station: int) -> Slots:
        at = station - 1
        return (self.box.tx[at], self.box.rx[at], self.box.alt[at])


@dataclass(frozen=True, slots=True)
class Reconciliation:
    """How a box found on (re)connection is brought to the wanted state."""

    keyed: frozenset[int]
    """Stations transmitting (or that may be) when the box answered."""
    believed: SwitchState | None
    """What the box is taken to hold: the wanted state goes out as the difference from
    it; None when the box's contents are not known well enough, and the whole state goes
    out as values (:func:`absolute`), never as a reset."""
    adopt: Mapping[int, Slots] = field(default_factory=lambda: MappingProxyType({}))
    """Stations whose antennas on the box win over the saved state: the engine takes
    them as the radio's antennas (the saved state is older than the box)."""
    waiting: frozenset[int] = frozenset()
    """Transmitting stations whose last change the box still holds back (wait mode):
    consistent, and sent again so that it is surely what the box applies at receive."""
    why: str = ""
    """Why the box does not simply hold the saved state ("" when it does)."""
    inactive: bool = False
    """The box is inactive: reset or powered off since it was loaded."""


def slots_of(station: StationAntennas) -> Slots:
    return (station.tx, station.rx, station.alt)


def reconcile(
    held: SwitchState | None, seen: Sequence[Slots] | None, survey: Survey
) -> Reconciliation:
    """Compare what a box reports (``survey``) with what it was last told (``held``,
    from this server or the saved state) and last seen holding (``seen``: the antennas
    it reported as in use), station by station.

    * An inactive box lost what it held (reset, power): it is loaded again as values.
    * A station showing what it was told is consistent.
    * A transmitting station showing what it was *seen* holding, not what it was told
      since, has a change waiting for it to receive (wait mode): consistent.
    * Any other station shows a change the saved state does not know (the state could
      not be saved, or the box was driven from elsewhere): what the box holds wins and
      the engine adopts it (stations transmitting always, receiving ones when a saved
      state exists to be wrong).
    * What cannot be judged station by station (inhibit polarity, closed relays that
      the saved state cannot explain while nobody transmits) loads the box as values.
    """
    keyed = survey.keyed()
    if not survey.pong.active:
        return Reconciliation(
            keyed, None, why="it is inactive (reset or powered off since)", inactive=True
        )
    if held is None or not held.active:
        adopt = {n: survey.slots(n) for n in sorted(keyed) if survey.slots(n) != (NO_ANTENNA,) * 3}
        why = "there is no saved state" if held is None else "the saved state is stopped"
        return Reconciliation(keyed, None, MappingProxyType(adopt), why=why)
    adopt, waiting = _compare_stations(held, seen, survey, keyed)
    why = _unexplained(held, survey, keyed, adopt)
    believed: SwitchState | None = None
    if not why:
        believed = _resend_antennas(held, keyed)
    if adopt and not why:
        why = "; ".join(f"station {n} holds other antennas" for n in sorted(adopt))
    return Reconciliation(keyed, believed, MappingProxyType(adopt), frozenset(waiting), why)


def _compare_stations(
    held: SwitchState, seen: Sequence[Slots] | None, survey: Survey, keyed: frozenset[int]
) -> tuple[dict[int, Slots], set[int]]:
    """Station by station: the stations whose antennas on the box win (a change the
    saved state does not know), and the transmitting ones whose change waits for them
    to receive (each antenna is the one told, or still the one seen before)."""
    adopt: dict[int, Slots] = {}
    waiting = set()
    for n, station in zip(STATIONS, held.stations, strict=True):
        found = survey.slots(n)
        if found == slots_of(station):
            continue
        told, before = slots_of(station), tuple(seen[n - 1]) if seen is not None else None
        if (
            n in keyed
            and before is not None
            and all(f in (t, b) for f, t, b in zip(found, told, before, strict=True))
        ):
            waiting.add(n)  # each antenna is the one told, or still the one seen before
        else:
            adopt[n] = found
    return adopt, waiting


def _unexplained(
    held: SwitchState, survey: Survey, keyed: frozenset[int], adopt: Mapping[int, Slots]
) -> str:
    """What cannot be judged station by station, so the box is loaded as values: another
    inhibit polarity, or (while nobody transmits and every station is consistent) closed
    relays the saved state cannot explain.  Empty when there is none."""
    if survey.polarity.enable_low != held.enable_low:
        return "its inhibit polarity differs"
    if keyed or adopt:
        return ""
    possible = set(held.station0)
    for station in held.stations:
        possible |= station.tx_relays | station.rx_relays | station.alt_relays
    if (
        not survey.relays.relays <= possible | _extras(held)
        or not held.station0 <= survey.relays.relays
    ):
        return "its closed relays differ"
    return ""


def _resend_antennas(held: SwitchState, keyed: frozenset[int]) -> SwitchState:
    """The box reports antennas (slots), not the relays behind them: a command lost on
    the line leaves the right slot with other relays, which no status shows.  So every
    station's antenna commands go again; the box takes the same antenna and relays as no
    change, and anything else under its hot-switch rules.  A keyed station's extra relays
    (closed while it transmits, at once) are not resent."""
    return replace(
        held,
        stations=tuple(
            replace(UNSURE, extra=s.extra) if n in keyed else UNSURE
            for n, s in zip(STATIONS, held.stations, strict=True)
        ),
    )


def _extras(state: SwitchState) -> set[int]:
    found: set[int] = set()
    for station in state.stations:
        found |= station.extra
    return found


__all__ = [
    "Reconciliation",
    "Slots",
    "Survey",
    "reconcile",
    "slots_of",
]
