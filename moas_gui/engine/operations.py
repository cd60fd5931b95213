"""Every input of the engine as one frozen value, and the one function that applies it.

The server turns whatever arrives (a client's request, a logger's packet, a
switch's T/R line, an Electrical rotator's turn, a menu) into one of these and
hands it to :meth:`moas_gui.app.ServerApp.act`, which stamps the time and calls
:func:`perform`.  Each operation is the argument list of one :class:`Engine`
method, so a reader can follow a frequency from the wire to the switch.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .changes import Changes
from .engine import Engine

Target = Literal["both", "tx", "rx"]


@dataclass(frozen=True, slots=True)
class SetFrequency:
    """A radio's frequency in kHz (``tx_khz`` when split): antenna selection by frequency."""

    station: int
    radio: int
    khz: float
    tx_khz: float | None = None


@dataclass(frozen=True, slots=True)
class Select:
    """A button press: toggle ``antenna`` for ``target``, alone when ``exclusive``."""

    station: int
    radio: int
    antenna: int
    target: Target = "both"
    exclusive: bool = False


@dataclass(frozen=True, slots=True)
class Hold:
    """Hold the radio's antennas against frequency changes (``by``: who holds them),
    or release them (``by`` None)."""

    station: int
    radio: int
    by: str | None
    since: float | None = None
    """When the hold began, in seconds since the epoch (the asker's wall clock), for
    people; a hold taken again by the same holder keeps its first time."""


@dataclass(frozen=True, slots=True)
class RunFunction:
    """Run the configuration's function ``function`` for that radio."""

    station: int
    radio: int
    function: int


@dataclass(frozen=True, slots=True)
class Relative:
    """The next (+1) or previous (-1) relative antenna, or the one at ``index``."""

    station: int
    radio: int
    step: int | None = None
    index: int | None = None


@dataclass(frozen=True, slots=True)
class SetTransmitting:
    """A switch port's T/R line changed."""

    switch_id: int
    port: int
    transmitting: bool


@dataclass(frozen=True, slots=True)
class SelectDirection:
    """An Electrical rotator was asked to point at ``heading`` degrees."""

    rotator_id: int
    heading: float


@dataclass(frozen=True, slots=True)
class KeepSwitchAntennas:
    """A switch found holding other antennas for some ports than the saved state says:
    the radio on each of those ports takes the box's antennas, all in one operation.
    ``held`` is ``(port, transmit slot, receive slot)`` for each such port."""

    switch_id: int
    held: tuple[tuple[int, int, int], ...]


@dataclass(frozen=True, slots=True)
class StopSwitches:
    """File > Stop Switches: every switch inactive, all relays off."""


@dataclass(frozen=True, slots=True)
class StartSwitches:
    """File > Start Switches: the switches hold the current antennas again."""


Operation = (SetFrequency | Select | Hold | RunFunction | Relative | SetTransmitting
             | SelectDirection | KeepSwitchAntennas | StopSwitches | StartSwitches)
"""Anything the engine can be asked to do."""


def perform(engine: Engine, op: Operation, now: float) -> Changes:
    """Apply ``op`` at time ``now`` (seconds of the server's clock).

    Raises :class:`~moas_gui.engine.EngineError` when the rules refuse; the
    engine is then exactly as it was.
    """
    match op:
        case SetFrequency(station, radio, khz, tx_khz):
            return engine.set_frequency(station, radio, khz, tx_khz, now=now)
        case Select(station, radio, antenna, target, exclusive):
            return engine.select(station, radio, antenna, target, exclusive, now=now)
        case Hold(station, radio, by, since):
            return engine.hold(station, radio, by, now=now, since=since)
        case RunFunction(station, radio, function):
            return engine.run_function(station, radio, function, now=now)
        case Relative(station, radio, step, index):
            return engine.relative(station, radio, step=step, index=index, now=now)
        case SetTransmitting(switch_id, port, transmitting):
            return engine.set_transmitting(switch_id, port, transmitting, now=now)
        case SelectDirection(rotator_id, heading):
            return engine.select_direction(rotator_id, heading, now=now)
        case KeepSwitchAntennas(switch_id, held):
            return engine.keep_switch_antennas(
                switch_id, {port: (tx, rx) for port, tx, rx in held}, now=now)
        case StopSwitches():
            return engine.stop()
        case StartSwitches():
            return engine.start()


__all__ = [
    "Hold",
    "KeepSwitchAntennas",
    "Operation",
    "Relative",
    "RunFunction",
    "Select",
    "SelectDirection",
    "SetFrequency",
    "SetTransmitting",
    "StartSwitches",
    "StopSwitches",
    "Target",
    "perform",
]
