"""The relay dwell: automatic updates move a switch's relays at most once per dwell.

A logger that floods band changes (a tuning knob turned fast, a rig daemon polled
a thousand times a second) would otherwise make the relays follow every step; the
manual warns that needless switching wears them out.  The rules, in plain words
(the session, :mod:`.session`, applies them; everything here is pure):

* A change that moves relays, when no dwell runs, goes out at once and starts a
  dwell of :attr:`.timing.LinkTiming.relay_dwell` seconds (0.1 by default): a single
  band change is never delayed.
* An *automatic* change (a logger's frequency, a client's ``frequency`` command)
  that moves relays while a dwell runs waits for its end; only the latest wanted
  state lands then, through the safety rule like every plan, and starts the next
  dwell.  Meanwhile :func:`interim` goes out at once: the relays as they are, with
  whatever makes the box stricter from the new state (more conflict pairs, fewer
  fast pairs, more inhibits) and every station whose relays wait inhibited, so no
  radio transmits into an antenna its new band does not want.
* An operator's press (a button, a function, a relative step, a T/R event's
  consequences, anything but a frequency) is never delayed: it sends the whole
  wanted state at once, which also lands whatever was waiting, and starts a dwell.
* A session that ends drops what waits; the next one plans from the latest wanted
  state, as every re-sync does.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ...engine.switchstate import STATIONS, SwitchState


def moves_relays(sent: SwitchState, target: SwitchState) -> bool:
    """Whether going from ``sent`` to ``target`` changes any station's relays (its
    antennas, their relays, its extra relays, or who moves to an alternate)."""
    return sent.stations != target.stations or sent.use_alternate != target.use_alternate


def waiting_stations(sent: SwitchState, target: SwitchState) -> frozenset[int]:
    """The stations whose relays differ between ``sent`` and ``target``."""
    moved = {n for n, (a, b) in zip(STATIONS, zip(sent.stations, target.stations,
                                                  strict=True), strict=True) if a != b}
    for a, b in zip(sent.use_alternate, target.use_alternate, strict=True):
        moved |= a ^ b  # who moves to an alternate when that station transmits
    return frozenset(moved)


def interim(sent: SwitchState, target: SwitchState) -> SwitchState:
    """What the box holds while ``target``'s relay changes wait: ``sent``'s relays, with
    the tables tightened by ``target`` and the waiting stations inhibited."""
    return replace(
        target,
        stations=sent.stations,
        station0=target.station0 if -1 in sent.station0 else sent.station0,
        use_alternate=sent.use_alternate,
        systems=sent.systems,
        interrupt=sent.interrupt,
        conflicts=sent.conflicts | target.conflicts,
        fast=sent.fast & target.fast,
        inhibited=sent.inhibited | target.inhibited | waiting_stations(sent, target),
        inhibit_others=tuple(a | b for a, b in zip(sent.inhibit_others, target.inhibit_others,
                                                   strict=True)),
    )


@dataclass(slots=True)
class RelayDwell:
    """When the running dwell ends, and whether a wanted state waits for it."""

    seconds: float
    ends: float | None = None
    """The end of the running dwell (None: none runs)."""
    waiting: bool = False
    """An automatic change waits for :attr:`ends`."""

    def holds(self, now: float | None) -> bool:
        """Whether an automatic change that moves relays at ``now`` must wait."""
        return (self.waiting or (now is not None and self.ends is not None
                                 and now < self.ends)) and self.seconds > 0

    def started(self, now: float | None) -> None:
        """Relays moved at ``now``: a dwell runs from there; nothing waits any more."""
        self.waiting = False
        self.ends = None if now is None or self.seconds <= 0 else now + self.seconds

    def due(self, now: float) -> bool:
        """Whether what waits must land now."""
        return self.waiting and self.ends is not None and now >= self.ends

    def deadline(self) -> float | None:
        return self.ends if self.waiting else None

    def drop(self) -> None:
        """The session ended: nothing waits, no dwell runs."""
        self.waiting = False
        self.ends = None


__all__ = ["RelayDwell", "interim", "moves_relays", "waiting_stations"]
