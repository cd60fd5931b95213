"""What a switch session reads from its box, beside answers: pure parts.

* :class:`BoxReader` -- the stations' key states (:class:`.keying.Keying`), the
  antennas the box reports in use for each station (its events and status: the
  antenna log's "in force"), conflict warnings, and the box's errors blamed on the
  command that drew them (:func:`.diagnostics.blame`).
* :class:`UnitCheck` -- whether a unit id the box says is this link's box.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

from ...engine.switchstate import NO_ANTENNA, STATIONS
from .actions import Action, BoxError, Log, Slots, Transmit
from .diagnostics import blame
from .keying import Keying
from .messages import (
    AntennaEvent,
    AntennaStatus,
    BoxStatus,
    ErrorReply,
    ReceiveEvent,
    TransmitEvent,
    UnitIdReply,
)

NOTHING: Slots = (NO_ANTENNA,) * 3


class BoxReader:
    """Key states and antennas in use, as the box reports them."""

    __slots__ = ("_seen", "keying", "where")

    def __init__(self, where: str, seen: Sequence[Slots] | None) -> None:
        self.where = where
        self.keying = Keying()
        self._seen: list[Slots] | None = [tuple(s) for s in seen] if seen else None  # type: ignore[misc]

    @property
    def seen(self) -> tuple[Slots, ...] | None:
        """Each station's antennas the box last reported in use (events and status)."""
        return tuple(self._seen) if self._seen is not None else None

    def surveyed(self, slots: list[Slots]) -> None:
        """A survey (or a load) says what each station holds now."""
        self._seen = slots

    def read(self, message: object, blamed: Sequence[bytes], out: list[Action]) -> bool:
        """``message`` came (``blamed``: the commands an error may belong to): the actions
        it calls for; True when who counts as keyed changed (a status is read whole
        first: a station it shows inhibited by command still counts)."""
        keyed = self.keying.keyed()
        if isinstance(message, ErrorReply):
            out.append(BoxError(blame(self.where, message, blamed)))  # the driver logs it
        elif isinstance(message, TransmitEvent | ReceiveEvent):
            on = isinstance(message, TransmitEvent)
            if self.keying.changed(message.station, on):
                out.append(Transmit(message.station, on))
        elif isinstance(message, BoxStatus):
            out += [Transmit(n, on) for n, on in self.keying.status(message.tr)]
        elif isinstance(message, AntennaEvent):
            self._antenna_event(message, out)
        return self.keying.keyed() != keyed

    def _antenna_event(self, event: AntennaEvent, out: list[Action]) -> None:
        status = event.status
        if status in (AntennaStatus.TX_CONFLICT, AntennaStatus.RX_CONFLICT):
            kind = "transmit" if status is AntennaStatus.TX_CONFLICT else "receive"
            out.append(Log(logging.WARNING, (
                f"{self.where} holds station {event.station}'s {kind} antenna (slot "
                f"{event.antenna}): it conflicts with another station's antenna")))
            return
        if self._seen is None or event.station not in STATIONS:
            return
        tx, rx, alt = self._seen[event.station - 1]
        if status in (AntennaStatus.TX_FAST, AntennaStatus.TX_SLOW):
            tx = event.antenna
        elif status in (AntennaStatus.RX_FAST, AntennaStatus.RX_SLOW):
            rx = event.antenna
        else:
            alt = event.antenna
        self._seen[event.station - 1] = (tx, rx, alt)


def reset_found(where: str, active: bool) -> str:
    """What a session says of a box whose pong is not as active as it left it."""
    return (f"{where} says it is {'active' if active else 'inactive'}, which it should not "
            "be: it was reset or lost power; loading it again")


class UnitCheck:
    """Whether a box that says it is some unit is this link's: the configuration's Echo,
    or else the first unit this link drove (a port name that now leads elsewhere)."""

    __slots__ = ("echo", "first", "where")

    def __init__(self, where: str, echo: int | None) -> None:
        self.where = where
        self.echo = echo
        self.first: int | None = None

    def judge(self, unit: UnitIdReply | None, pong: object | None,
              foreign: UnitIdReply | None) -> tuple[int, str] | None:
        """The confirmation's answers (the unit id, the ping's, another unit's id heard
        meanwhile): None when the box is ours (without Echo, the one this link drives
        from now on), else the level and text of why not."""
        if unit is None or pong is None:
            return logging.WARNING, f"{self.where} does not answer; will retry"
        refusal = self.refusal(foreign or unit)
        if refusal:
            return logging.ERROR, refusal
        if self.echo is None and self.first is None:
            self.first = unit.unit
        return None

    def refusal(self, unit: UnitIdReply) -> str:
        """Why a box that says it is ``unit`` is not ours ("" when it is)."""
        if self.echo is not None and unit.unit != self.echo:
            return (
                f"{self.where} says it is unit {unit.unit}, but the configuration's Echo is "
                f"{self.echo}: not driving it (is it on the wrong port?)"
            )
        if self.echo is None and self.first is not None and unit.unit != self.first:
            return (
                f"{self.where} says it is unit {unit.unit}, but the box this port led to "
                f"before was unit {self.first}: not driving it (is it on the wrong "
                f"port? give Echo in the configuration, or restart, to drive it)"
            )
        return ""


__all__ = ["NOTHING", "BoxReader", "UnitCheck", "reset_found"]
