"""One station of the emulated switch, and the table that drives it.

Everything that decides *when* a station's relays may move lives in
:data:`TRANSITIONS`; the model only works out which trigger happened and
then does what the table says.  The rules, in plain words:

* A station is in one of five phases.  RECEIVE: its receive relays are
  closed.  TRANSMIT: its key line is asserted and its transmit relays (and
  extra relays) are closed.  RELEASE: the key line was released and the
  receive delay is running; the transmit relays stay closed.  SLOW: a slow
  transition is in progress; the relays have moved and the station's inhibit
  is asserted for the inhibit time.  INTERRUPT: in interrupt mode, a change
  arrived while the station was on the air; its inhibit is asserted and the
  relays move when the interrupt delay has passed (then SLOW follows, since
  an interrupt always switches the slow way).
* A change that moves the relays of a station that is on the air (TRANSMIT,
  RELEASE, or SLOW/INTERRUPT on the transmit side) is ``ON_AIR_WAIT`` in
  wait mode and ``ON_AIR_INTERRUPT`` in interrupt mode.  ``ON_AIR_WAIT`` has
  no entry anywhere: such a change is held until the station receives, so
  a transmitting station's relays never move in wait mode.
* A pair missing from the table means "not now": the change stays pending
  and is tried again at the next chance (after the next timer, key change or
  command).
* Receive-side changes (receive antenna, alternate antenna) are always
  fast; transmit-antenna changes seen on the receive side, and keying up,
  are fast or slow according to the fast table.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from ..messages import StationMode


class StationPhase(str, Enum):
    RECEIVE = "receive"
    TRANSMIT = "transmit"
    RELEASE = "release"
    SLOW = "slow"
    INTERRUPT = "interrupt"


class Trigger(str, Enum):
    KEY_DOWN = "key down, fast"
    KEY_DOWN_SLOW = "key down, slow"
    KEY_UP = "key up"
    SWITCH = "fast change of closed relays"
    SWITCH_SLOW = "slow change of closed relays"
    ON_AIR_WAIT = "change on the air, wait mode"
    ON_AIR_INTERRUPT = "change on the air, interrupt mode"
    DEADLINE = "timer ran out, key up, receive side"
    DEADLINE_KEYED = "timer ran out, key down"
    DEADLINE_RELEASED = "timer ran out, key up, transmit side"


class TimerChange(str, Enum):
    """What the phase's timer becomes on a transition."""

    NONE = "none"
    KEEP = "keep"
    INHIBIT = "inhibit time"
    INTERRUPT_DELAY = "interrupt delay"
    RECEIVE_DELAY = "receive delay"
    RECEIVE_DELAY_REST = "rest of the receive delay"


P, T, M = StationPhase, Trigger, TimerChange

TRANSITIONS: dict[tuple[StationPhase, Trigger], tuple[StationPhase, TimerChange]] = {
    (P.RECEIVE, T.KEY_DOWN): (P.TRANSMIT, M.NONE),
    (P.RECEIVE, T.KEY_DOWN_SLOW): (P.SLOW, M.INHIBIT),
    (P.RECEIVE, T.SWITCH): (P.RECEIVE, M.NONE),
    (P.RECEIVE, T.SWITCH_SLOW): (P.SLOW, M.INHIBIT),
    (P.TRANSMIT, T.KEY_UP): (P.RELEASE, M.RECEIVE_DELAY),
    (P.TRANSMIT, T.ON_AIR_INTERRUPT): (P.INTERRUPT, M.INTERRUPT_DELAY),
    (P.RELEASE, T.KEY_DOWN): (P.TRANSMIT, M.NONE),
    (P.RELEASE, T.DEADLINE): (P.RECEIVE, M.NONE),
    (P.RELEASE, T.ON_AIR_INTERRUPT): (P.INTERRUPT, M.INTERRUPT_DELAY),
    (P.INTERRUPT, T.KEY_DOWN): (P.INTERRUPT, M.KEEP),
    (P.INTERRUPT, T.KEY_UP): (P.INTERRUPT, M.KEEP),
    (P.INTERRUPT, T.DEADLINE_KEYED): (P.SLOW, M.INHIBIT),
    (P.INTERRUPT, T.DEADLINE_RELEASED): (P.SLOW, M.INHIBIT),
    (P.SLOW, T.KEY_DOWN): (P.SLOW, M.KEEP),
    (P.SLOW, T.KEY_DOWN_SLOW): (P.SLOW, M.INHIBIT),
    (P.SLOW, T.KEY_UP): (P.SLOW, M.KEEP),
    (P.SLOW, T.SWITCH): (P.SLOW, M.KEEP),
    (P.SLOW, T.DEADLINE): (P.RECEIVE, M.NONE),
    (P.SLOW, T.DEADLINE_KEYED): (P.TRANSMIT, M.NONE),
    (P.SLOW, T.DEADLINE_RELEASED): (P.RELEASE, M.RECEIVE_DELAY_REST),
}
"""(phase, trigger) -> (next phase, what happens to the timer)."""

del P, T, M

INHIBITING_PHASES = frozenset({StationPhase.SLOW, StationPhase.INTERRUPT})
"""Phases in which the station's inhibit is asserted by the transition."""


@dataclass(frozen=True, slots=True)
class Slot:
    """An antenna number and the relays that connect a station to it."""

    antenna: int = 63
    relays: frozenset[int] = frozenset()


NO_SLOT = Slot()


class SlotRole(str, Enum):
    """The four things an antenna command can ask for a station."""

    TX = "T"
    RX = "R"
    ALT = "A"
    EXTRA = "X"


@dataclass(slots=True)
class PendingCommand:
    """An antenna command not yet carried out."""

    slot: Slot
    seq: int
    conflict_reported: bool = False


@dataclass(slots=True)
class Station:
    """The live state of one station (1-6)."""

    number: int
    key: bool = False
    phase: StationPhase = StationPhase.RECEIVE
    tx_side: bool = False
    """True while the transmit relays (and extra relays) are the closed ones."""
    deadline: float | None = None
    released_at: float = 0.0
    """When the key line was last released (for the receive delay)."""
    mode: StationMode = StationMode.WAIT
    receive_delay_ms: int = 0
    current: dict[SlotRole, Slot] = field(default_factory=lambda: {k: NO_SLOT for k in SlotRole})
    pending: dict[SlotRole, PendingCommand] = field(default_factory=dict)
    incoming: dict[SlotRole, Slot] = field(default_factory=dict)
    """Granted transmit-side changes waiting for the interrupt delay."""
    reported_tx: bool = False
    """A ``<`` event was sent and no ``>`` yet."""

    @property
    def on_air(self) -> bool:
        return self.tx_side

    @property
    def inhibiting(self) -> bool:
        return self.phase in INHIBITING_PHASES


def next_phase(phase: StationPhase, trigger: Trigger) -> tuple[StationPhase, TimerChange] | None:
    """The table's answer, or None when the trigger must wait."""
    return TRANSITIONS.get((phase, trigger))


__all__ = [
    "INHIBITING_PHASES",
    "NO_SLOT",
    "TRANSITIONS",
    "PendingCommand",
    "Slot",
    "SlotRole",
    "Station",
    "StationPhase",
    "TimerChange",
    "Trigger",
    "next_phase",
]
