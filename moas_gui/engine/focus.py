"""Which radio of a station has the transmit focus and which the operator listens to.

An SO2R logger says which of a station's radios transmits next (*active*, the
transmit focus: N1MM's ``ActiveRadioNr``, OTRSP's ``TX1``/``TX2``) and which
one the operator is on (*focus*, the receive focus: ``FocusRadioNr``,
``RX1``/``RX2``).  :class:`FocusTable` keeps both per station; radio entries
for clients carry them as ``active`` and ``focus`` (see
docs/client-protocol.md).

One rule uses the active radio (docs/engine.md, "Transmit focus"):
**when several radios' frequencies arrive together, the active radio's is
decided first** (:func:`active_first`), so when both radios of an SO2R station
want the same antenna, the radio about to transmit gets it and the other is
given its next choice.  Nothing else changes: a radio without the focus
keeps every antenna it has.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Literal, TypeVar

FocusKind = Literal["active", "focus"]

T = TypeVar("T")


@dataclass(frozen=True, slots=True)
class StationFocus:
    """A station's transmit focus (``active``) and receive focus (``focus``) radios."""

    active: int | None = None
    focus: int | None = None


class FocusTable:
    """The focus of every station that reported one."""

    def __init__(self) -> None:
        self._stations: dict[int, StationFocus] = {}

    def get(self, station: int) -> StationFocus:
        return self._stations.get(station, StationFocus())

    def set(self, station: int, kind: FocusKind, radio: int) -> int | None:
        """Records it; returns the radio that had it before (``radio`` itself: no change)."""
        now = self.get(station)
        before = now.active if kind == "active" else now.focus
        if before != radio:
            self._stations[station] = (StationFocus(radio, now.focus) if kind == "active"
                                       else StationFocus(now.active, radio))
        return before

    def fields(self, station: int, radio: int) -> dict[str, bool]:
        """What a radio entry for clients carries: ``{"active": ..., "focus": ...}``."""
        now = self.get(station)
        return {"active": now.active == radio, "focus": now.focus == radio}

    def clear(self) -> None:
        self._stations.clear()

    def items(self) -> dict[int, tuple[int | None, int | None]]:
        """Every station's ``(active, focus)`` radios (what a saved state keeps)."""
        return {n: (f.active, f.focus) for n, f in sorted(self._stations.items())}


def active_first(items: Iterable[T], key: Callable[[T], tuple[int, int]],
                 table: FocusTable) -> list[T]:
    """``items`` (each naming a station and radio by ``key``) with every station's active
    radio before its other radios; otherwise in their order."""
    listed = list(items)

    def rank(indexed: tuple[int, T]) -> tuple[int, int]:
        station, radio = key(indexed[1])
        return (0 if table.get(station).active == radio else 1, indexed[0])

    return [item for _, item in sorted(enumerate(listed), key=rank)]


__all__ = ["FocusKind", "FocusTable", "StationFocus", "active_first"]
