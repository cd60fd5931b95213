"""What a switch session's box holds, and the plans that change it: a pure part.

:class:`PlanWriter` keeps what the box holds for sure (``sent``) and what it was last
told (``held``, kept through an outage), turns a wanted state into commands through
:func:`.plan.choose_plan` and :func:`.plan.guard` (the safety rule), and applies the
relay dwell (:mod:`.dwell`).  It never writes: it returns the command bytes, which
the session writes only in a phase of :data:`.phases.WRITES_PLANS`
(``SwitchSession._send``).
"""

from __future__ import annotations

import logging
from dataclasses import replace

from ...engine.switchstate import SwitchState
from .actions import Action, Log
from .commands import encode, split
from .dwell import RelayDwell, interim, moves_relays
from .messages import StateOp
from .plan import UNSURE_RELAYS, Known, choose_plan, guard


class PlanWriter:
    """The box's contents as far as the session knows, and the plans it sends."""

    __slots__ = ("dwell", "events", "held", "refusals", "sent", "station0_waits", "where")

    def __init__(self, where: str, events: tuple[StateOp, ...], dwell_seconds: float,
                 held: SwitchState | None) -> None:
        self.where = where
        self.events = events
        self.sent: SwitchState | None = None
        """What the box holds for sure (None until a session loaded it)."""
        self.held = held
        """What the box was last told (a saved state, or an earlier session's): a new
        session checks what the box holds against it instead of loading it blindly."""
        self.dwell = RelayDwell(dwell_seconds)
        """Automatic relay changes wait for the running dwell's end (:mod:`.dwell`)."""
        self.station0_waits = False
        """The last plan's station-0 relays were held back by the safety rule; they go
        out when no station transmits."""
        self.refusals: list[str] = []
        """Every plan the safety rule refused (for tests and Save Switch Data)."""

    @property
    def holds(self) -> SwitchState | None:
        """What the box was last told, loaded or not: what a saved state should keep, so
        that a restart during an outage still checks the box rather than loading it."""
        return self.sent if self.sent is not None else self.held

    def expect(self) -> bool | None:
        """How active the next pong should say the box is (None: not loaded yet)."""
        return self.sent.active if self.sent is not None else None

    def known(self) -> Known:
        """What a running session knows: the box holds ``sent`` for sure."""
        assert self.sent is not None
        return Known(box_active=self.sent.active, sent=self.sent, events=self.events)

    def plan(self, known: Known, target: SwitchState, keyed: frozenset[int] | None,
             out: list[Action]) -> list[bytes] | None:
        """The commands that take the box from ``known`` to ``target``, through the
        safety rule (None: refused); the box is then taken to hold ``target``, less the
        station-0 relays the rule held back (marked unsure, so they go out later)."""
        verdict = guard(choose_plan(known, target), keyed, self.where)
        if verdict.refused:
            out.append(Log(logging.ERROR, verdict.refused))
            self.refusals.append(verdict.refused)
            return None
        self.station0_waits = verdict.held_back
        if verdict.held_back:
            out.append(Log(logging.INFO, f"{self.where}: its always-on (station 0) relays "
                           "wait until no station transmits"))
        if verdict.warning:
            out.append(Log(logging.WARNING, verdict.warning))
        out += [Log(logging.ERROR, f"{self.where}: {p}") for p in verdict.plan.problems]
        self.sent = replace(target, station0=UNSURE_RELAYS) if verdict.held_back else target
        return [encode(part) for command in verdict.plan.commands for part in split(command)]

    def now_target(self, target: SwitchState, now: float | None, automatic: bool) -> SwitchState:
        """What of ``target`` goes out now (the relay dwell): all of it, or, for an
        automatic change while a dwell runs, the relays as they are with the waiting
        stations inhibited (the latest lands at the dwell's end).  The same also when
        the change happens to need no relay move: no inhibit goes on and off with every
        packet of a flood."""
        assert self.sent is not None
        if automatic and self.dwell.holds(now):
            self.dwell.waiting = True
            return interim(self.sent, target)
        if moves_relays(self.sent, target):
            self.dwell.started(now)
        elif not automatic:
            self.dwell.waiting = False  # a press sends everything: nothing waits
        return target

    def ended(self) -> None:
        """The session ended: what the box holds is no longer sure (but remembered: a
        cable pulled and plugged back must not reset a box), and nothing waits."""
        if self.sent is not None:
            self.held = self.sent
        self.sent = None
        self.dwell.drop()  # the next session plans from the latest wanted state


__all__ = ["PlanWriter"]
