"""Which plan a switch session sends, and the safety rule every plan passes.

Two pure functions, side by side, and the values between them:

* :func:`choose_plan` takes what the session knows of the box (:class:`Known`: what
  it holds for sure, what it is believed to hold, whether it is active, whether the
  operator asked for a reset) and the wanted state, and returns the :class:`ChosenPlan`
  to send.  Every plan the session writes is chosen here, and this is the one place a
  reset is chosen (:func:`.sync.difference` never holds one); no caller picks a kind.
* :func:`guard` takes that plan and the stations transmitting and returns a
  :class:`Verdict`.  It decides by itself, from the plan's own facts, what the
  operator asked for and what the session would do on its own.

**The scope of** :func:`guard`, exactly: it holds back only two things.

1. A reset (``*0``), which opens every relay at once whoever transmits.  It goes out
   only when the operator asked for it: Reset Switches (``Known.reset_asked``) or
   Stop Switches (the wanted state is inactive: only a reset deactivates a box, and
   only the operator stops the switches).  Any other plan holding a reset is refused
   whole.  An allowed reset carries a warning naming the stations transmitting then
   (or saying their state is not known yet).
2. The station-0 relays (``!0X``), which the box sets at once with no hot-switch rule.
   While a station transmits or may (``keyed`` None or not empty), a station-0
   command is taken out of the plan unless the wanted state changes them from relays
   the box surely holds (:func:`station0_changed`: ``Known.sent`` with sure station-0
   relays, different from the target's; any change of the engine's counts, a
   logger's band change as much as an operator's press).  So what is held back is
   what a session would set on its own: after a reconnection or a reset, while the
   box's relays are not sure.  The session sends them when every station receives.

Everything else a plan holds reaches a station's relays only through the box's own
rules (wait or interrupt mode, the tables the engine loads): :func:`guard` does not
look at it.  Nothing here logs, reads a clock or touches a port.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...engine.switchstate import SwitchState
from .messages import SetAntenna, SetState, StateOp
from .sync import DEFAULT_EVENTS, CommandPlan, absolute, difference, initialise

UNSURE_RELAYS = frozenset({-1})
"""Station-0 relays the box may not hold (held back by :func:`guard`): any wanted
relays differ from them, so they go out with the next plan that may send them."""


@dataclass(frozen=True, slots=True)
class Known:
    """What a session knows of its box when it chooses a plan."""

    box_active: bool
    """The box is active (its relays follow the antennas), as far as the session knows."""
    sent: SwitchState | None = None
    """What the box holds for sure: the session is running and told it this.  None
    while the session only believes what it holds (a reconnection, a box found reset)."""
    believed: SwitchState | None = None
    """What a reconnected box is taken to hold (:class:`.resync.Reconciliation`), when
    ``sent`` is None; both None: not known, so the whole state goes out as values."""
    reset_asked: bool = False
    """The operator pressed Reset Switches."""
    events: tuple[StateOp, ...] = DEFAULT_EVENTS
    """The events the session asks the box for."""


@dataclass(frozen=True, slots=True)
class ChosenPlan:
    """A plan chosen by :func:`choose_plan`: the commands, and the facts the safety
    rule judges them by."""

    commands: CommandPlan
    target: SwitchState
    """The wanted state the plan takes the box to."""
    known: Known
    """What the session knew when it chose the plan."""


def choose_plan(known: Known, desired: SwitchState) -> ChosenPlan:
    """The plan that takes the box from what the session knows to ``desired``.

    This is the one place a reset is chosen:

    * Reset Switches: a reset and a full load (:func:`.sync.initialise`).
    * An active box (as the session knows it: ``sent``'s, else ``box_active``) that
      should be stopped: a reset and a load without activation (the box has no
      "deactivate"; Stop Switches is the operator's).
    * The box holds a known state (``sent``): the difference (:func:`.sync.difference`).
    * Otherwise, a believed state: the difference from it.
    * Otherwise: the whole state as values, never a reset (:func:`.sync.absolute`)."""
    events = known.events
    active = known.sent.active if known.sent is not None else known.box_active
    if known.reset_asked or (active and not desired.active):
        commands = initialise(desired, events=events)
    elif known.sent is not None:
        commands = difference(known.sent, desired, events=events)
    elif known.believed is not None and (desired.active or not known.believed.active):
        commands = difference(known.believed, desired, events=events)
    else:
        commands = absolute(desired, box_active=known.box_active, events=events)
    return ChosenPlan(commands, desired, known)


@dataclass(frozen=True, slots=True)
class Verdict:
    """What :func:`guard` lets out of a plan."""

    plan: CommandPlan
    """The commands that may go (all, all but the station-0 relays, or none)."""
    refused: str = ""
    """Why the plan was not sent at all ("" when it (or part of it) may go)."""
    warning: str = ""
    """What an allowed reset does to transmitting stations, for the log."""
    held_back: bool = False
    """The station-0 relays were taken out of the plan until nobody transmits."""


def resets(commands: CommandPlan) -> bool:
    """The plan holds a reset (``*0``)."""
    return any(isinstance(c, SetState) and StateOp.RESET in c.ops for c in commands.commands)


def reset_asked(plan: ChosenPlan) -> bool:
    """The operator asked for the reset a plan holds: Reset Switches, or Stop Switches
    (an inactive wanted state: the session never stops a box on its own)."""
    return plan.known.reset_asked or not plan.target.active


def station0_changed(plan: ChosenPlan) -> bool:
    """The wanted state changes the station-0 relays from relays the box surely holds
    (a running session's, not held back) to the target's.  Any change of the engine's
    counts, whoever caused it: an operator's press or a logger's band change alike
    (the engine decides the relays; the rule only keeps the box from setting relays
    on its own initiative, after a reconnection, while someone transmits)."""
    sent = plan.known.sent
    return (
        sent is not None
        and sent.station0 != UNSURE_RELAYS
        and sent.station0 != plan.target.station0
    )


def guard(plan: ChosenPlan, keyed: frozenset[int] | None, where: str) -> Verdict:
    """The safety rule for every plan a session writes (its scope: the module
    docstring).  ``keyed``: the stations transmitting, or None when not known yet
    (which counts as transmitting)."""
    commands = plan.commands
    if resets(commands):
        return _reset_verdict(plan, keyed, where)
    if (keyed is None or keyed) and not station0_changed(plan):
        kept = tuple(
            c for c in commands.commands if not (isinstance(c, SetAntenna) and c.station == 0)
        )
        if len(kept) != len(commands.commands):
            return Verdict(CommandPlan(kept, commands.problems), held_back=True)
    return Verdict(commands)


def _reset_verdict(plan: ChosenPlan, keyed: frozenset[int] | None, where: str) -> Verdict:
    if keyed is None:
        on_air = "the stations' transmit states are not known yet"
    elif keyed:
        names = ", ".join(str(n) for n in sorted(keyed))
        on_air = f"station{'s' if len(keyed) > 1 else ''} {names} transmitting"
    else:
        on_air = ""
    if not reset_asked(plan):
        return Verdict(
            CommandPlan(),
            refused=f"{where}: not resetting it on the server's own "
            f"initiative ({on_air or 'a reset is for the operator alone'})",
        )
    warning = (
        f"{where}: reset by the operator with {on_air}: their relays open now" if on_air else ""
    )
    return Verdict(plan.commands, warning=warning)


__all__ = [
    "UNSURE_RELAYS",
    "ChosenPlan",
    "Known",
    "Verdict",
    "choose_plan",
    "guard",
    "reset_asked",
    "resets",
    "station0_changed",
]
