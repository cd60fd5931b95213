"""Who transmits, as a box said it: the session's record of its stations' key states.

Pure: the box's T and R events and its box status in, the stations transmitting out.
Until a box status has said every station's state, :meth:`Keying.keyed` is None, which
the safety rule (:func:`.plan.guard`) counts as transmitting.  A station the status
shows inhibited by command (``I``) may be keyed behind its inhibit: it counts as
transmitting until an event says otherwise.
"""

from __future__ import annotations

from collections.abc import Sequence

from ...engine.switchstate import STATIONS
from .messages import TRState


class Keying:
    """The stations' transmit states as the box last said them."""

    __slots__ = ("_known", "_tr", "_unsure")

    def __init__(self) -> None:
        self._tr: dict[int, bool] = {}
        self._unsure: set[int] = set()
        self._known = False

    def clear(self) -> None:
        """A new session: nothing is known."""
        self._tr.clear()
        self._unsure = set()
        self._known = False

    def changed(self, station: int, transmitting: bool) -> bool:
        """The box said ``station`` transmits (or receives); True if that is news."""
        self._unsure.discard(station)
        if self._tr.get(station) is transmitting:
            return False
        self._tr[station] = transmitting
        return True

    def status(self, tr: Sequence[TRState]) -> list[tuple[int, bool]]:
        """A box status said every station's letter: the stations whose state is news."""
        news = [(n, letter is TRState.TRANSMIT) for n, letter in zip(STATIONS, tr, strict=False)
                if self.changed(n, letter is TRState.TRANSMIT)]
        self._unsure = {n for n, letter in zip(STATIONS, tr, strict=False)
                        if letter is TRState.INHIBITED}
        self._known = len(tr) >= len(STATIONS)
        return news

    def keyed(self) -> frozenset[int] | None:
        """Stations transmitting (or that may be); None until the box said it for all."""
        if not self._known:
            return None
        return frozenset(n for n, on in self._tr.items() if on) | frozenset(self._unsure)


__all__ = ["Keying"]
