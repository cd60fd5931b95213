"""What the emulated box did to its relays, kept for a test to check.

The model writes one :class:`Entry` whenever the closed relays change (after
each command, each timer that runs out, each key line that moves), whenever
a station's key line changes, and whenever a reset (``*0``) arrives; each
entry carries every station's key state and closed relays at that moment.
The record is bounded (the oldest entries go first) and numbered, so a
reader that asks for "everything after number n" knows when it missed some.

A test reads it straight from the model (``model.record``), or, from another
process, through ``moas-emulator --control`` (``record`` and ``watch``; see
:mod:`moas_gui.cli.emulator`), where each entry is one JSON object
(:meth:`Entry.as_json`).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from enum import Enum
from typing import Any

RECORD_SIZE = 4096
"""Entries kept (under a kilobyte each); older ones are dropped.  A reader that must
see every entry follows the record as it is written (``watch``)."""


class EntryCause(str, Enum):
    """Why an entry was written."""

    RELAYS = "relays"
    """The closed relays changed."""
    KEY = "key"
    """A station's key line changed (the relays may have changed with it)."""
    RESET = "reset"
    """A ``*0`` arrived; the entry shows the box just before it was carried out."""


@dataclass(frozen=True, slots=True)
class Entry:
    """One moment of the box."""

    seq: int
    """Numbered from 1, one more for each entry ever written."""
    at: float
    """The model's time (seconds)."""
    event: EntryCause
    cause: str
    """The command (``!1B112;``), ``timer``, ``key 1`` or ``unkey 1``."""
    active: bool
    relays: frozenset[int]
    """Every relay closed (station 0's included)."""
    keyed: frozenset[int]
    """Stations whose key line is asserted."""
    closed: tuple[frozenset[int], ...]
    """The relays each station 1-6 closes (index 0 is station 1)."""
    interrupt_mode: frozenset[int]
    """Stations in interrupt mode, whose relays the box itself may move on the air."""

    def station_relays(self, station: int) -> frozenset[int]:
        return self.closed[station - 1]

    def as_json(self) -> dict[str, Any]:
        return {
            "seq": self.seq,
            "at": round(self.at, 6),
            "event": self.event.value,
            "cause": self.cause,
            "active": self.active,
            "relays": sorted(self.relays),
            "keyed": sorted(self.keyed),
            "closed": [sorted(c) for c in self.closed],
            "interrupt_mode": sorted(self.interrupt_mode),
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Entry:
        return cls(
            seq=int(data["seq"]),
            at=float(data["at"]),
            event=EntryCause(data["event"]),
            cause=str(data["cause"]),
            active=bool(data["active"]),
            relays=frozenset(data["relays"]),
            keyed=frozenset(data["keyed"]),
            closed=tuple(frozenset(c) for c in data["closed"]),
            interrupt_mode=frozenset(data["interrupt_mode"]),
        )


class Record:
    """The bounded, numbered list of entries."""

    def __init__(self, size: int = RECORD_SIZE) -> None:
        self._entries: deque[Entry] = deque(maxlen=size)
        self.written = 0
        """Entries ever written (the last one's number)."""
        self.resets = 0
        """``*0`` commands ever received."""

    def add(self, entry: Entry) -> None:
        self._entries.append(entry)
        self.written = entry.seq
        if entry.event is EntryCause.RESET:
            self.resets += 1

    def after(self, seq: int) -> list[Entry]:
        """The entries numbered above ``seq`` that are still kept."""
        if not self._entries or self._entries[-1].seq <= seq:
            return []
        first = self._entries[0].seq
        start = max(0, seq + 1 - first)
        return list(self._entries)[start:]

    def __iter__(self) -> Iterator[Entry]:
        return iter(list(self._entries))

    def __len__(self) -> int:
        return len(self._entries)

    @property
    def last(self) -> Entry | None:
        return self._entries[-1] if self._entries else None


__all__ = ["RECORD_SIZE", "Entry", "EntryCause", "Record"]
