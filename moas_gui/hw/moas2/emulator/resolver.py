"""The conflict resolver's choice: which pending antenna requests go ahead
together, which wait for a conflict to clear, which wait for their station.

Pure: it sees antenna numbers, the conflict table and a question it may ask
about each station ("may this station make these changes now?").

How the choice is made, in plain words:

* Start from every candidate request and imagine them all carried out at
  once.  Requests are tried together, so two stations swapping antennas (each
  wanting the other's) go ahead in one step.
* If a station may not make its changes now (its phase table says so), its
  newest request is put aside as *waiting*, and the rest tried again.
* If the imagined result has two different stations on conflicting antennas,
  the newest request involved is put aside as *conflicted* (the older request
  wins), and the rest tried again.
* What is left is carried out.  Alternate antennas and extra relays never
  take part in conflicts (alternates have their own rule, applied when they
  are used).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

from .pairs import PairTable
from .station import Slot, SlotRole

CLAIMING = (SlotRole.TX, SlotRole.RX)
"""The kinds of antenna that conflict with other stations'."""

KIND_ORDER = {SlotRole.TX: 0, SlotRole.RX: 1, SlotRole.ALT: 2, SlotRole.EXTRA: 3}
"""Order of one command's requests (``B`` gives TX then RX)."""


@dataclass(frozen=True, slots=True)
class Candidate:
    station: int
    kind: SlotRole
    slot: Slot
    seq: int


@dataclass(frozen=True, slots=True)
class Choice:
    granted: tuple[Candidate, ...]
    conflicted: tuple[Candidate, ...]
    waiting: tuple[Candidate, ...]


def _mask(antennas: Iterable[int]) -> int:
    bits = 0
    for antenna in antennas:
        bits |= 1 << antenna
    return bits


def choose(
    candidates: Iterable[Candidate],
    claims: Mapping[int, Mapping[SlotRole, int]],
    reserved: Mapping[int, Iterable[int]],
    conflicts: PairTable,
    allowed: Callable[[int, dict[SlotRole, Slot]], bool],
) -> Choice:
    """Decide which ``candidates`` go ahead.

    ``claims`` is each station's current TX and RX antenna; ``reserved``
    antennas a station holds beyond them (a change waiting for its interrupt
    delay); ``allowed(station, changes)`` says whether a station may make
    those changes now.
    """
    chosen = sorted(candidates, key=lambda c: (c.seq, KIND_ORDER[c.kind]))
    conflicted: list[Candidate] = []
    waiting: list[Candidate] = []
    while chosen:
        by_station: dict[int, dict[SlotRole, Slot]] = {}
        for c in chosen:
            by_station.setdefault(c.station, {})[c.kind] = c.slot
        refused = [s for s, changes in by_station.items() if not allowed(s, changes)]
        if refused:
            newest = max((c for c in chosen if c.station in refused), key=lambda c: c.seq)
            chosen.remove(newest)
            waiting.append(newest)
            continue
        masks = {}
        for station, held in claims.items():
            antennas = [held[k] for k in CLAIMING]
            for kind, slot in by_station.get(station, {}).items():
                if kind in CLAIMING:
                    antennas[CLAIMING.index(kind)] = slot.antenna
            masks[station] = _mask([*antennas, *reserved.get(station, ())])
        bad = [
            c
            for c in chosen
            if c.kind in CLAIMING
            and any(
                conflicts.row(c.slot.antenna) & mask
                for other, mask in masks.items()
                if other != c.station
            )
        ]
        if not bad:
            break
        newest = max(bad, key=lambda c: (c.seq, KIND_ORDER[c.kind]))
        chosen.remove(newest)
        conflicted.append(newest)
    return Choice(tuple(chosen), tuple(conflicted), tuple(waiting))


__all__ = ["CLAIMING", "Candidate", "Choice", "choose"]
