"""The switch session's phases and every move between them, in one table.

Everything that changes a session's phase lives in :data:`TRANSITIONS`; the session
(:mod:`.session`) moves only through :func:`next_phase`, which refuses a move the
table does not hold.  In words:

* **closed** -- no port, or the session ended.  *opened* (a port is open) leads to
  **confirm**.
* **confirm** -- the unit id (``:;``) and a ping (``';``) are asked; nothing that
  could move a relay is written.  *confirmed* (both answered, the unit is ours) leads
  to **survey**.
* **survey** -- ping, box status, inhibit polarity and relays are asked; still
  nothing that could move a relay.  *unanswered* (a question went unanswered, fewer
  than three tries) stays in **survey**, asking again; *surveyed* (every answer in,
  and the engine took the stations the survey adopts) leads to **loading**.
* **loading** -- the reconciling plan goes out (through the safety rule), then a ping
  checks that the box took it.  *loaded* (answered) leads to **running**.
* **running** -- pings once a second; wanted states go out as they come (through
  the safety rule and the relay dwell).
* *ended* -- silence past the answer timeout, a lost port, another unit's id, an
  unanswered survey, a refused plan -- leads from every phase but closed to
  **closed**; the driver opens the port again later, and a new session starts over
  at confirm.

A session writes what could move a relay only in loading and running
(:data:`WRITES_PLANS`): ``SwitchSession._send``, the one place a plan is written,
refuses any other phase as a programming error (:class:`WriteRefused`: logged as a
fault, and the session ends).  The unit id is ours in :data:`CONFIRMED`.
``docs/switch.md`` draws the same table.

What a session knows beside its phase, and the table does not hold, is data, not
another phase: :class:`SessionNotes` (another unit's id heard while confirming, the
survey's tries, a survey waiting for the engine) and, in the session's pure parts,
the station-0 relays held back (``PlanWriter.station0_waits``, :mod:`.writer`), the
stations' transmit states (:class:`.keying.Keying`) and the questions in flight with
the running session's ping clock (:class:`.questions.Questions`).  No other flag of
the session says where it stands.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from .errors import Moas2Error
from .messages import UnitIdReply
from .resync import Reconciliation


class Phase(Enum):
    CLOSED = "closed"
    CONFIRM = "confirm"
    SURVEY = "survey"
    LOADING = "loading"
    RUNNING = "running"


class PhaseEvent(Enum):
    OPENED = "opened"
    CONFIRMED = "confirmed"
    UNANSWERED = "unanswered"
    SURVEYED = "surveyed"
    LOADED = "loaded"
    ENDED = "ended"


TRANSITIONS: dict[tuple[Phase, PhaseEvent], Phase] = {
    (Phase.CLOSED, PhaseEvent.OPENED): Phase.CONFIRM,
    (Phase.CONFIRM, PhaseEvent.CONFIRMED): Phase.SURVEY,
    (Phase.SURVEY, PhaseEvent.UNANSWERED): Phase.SURVEY,
    (Phase.SURVEY, PhaseEvent.SURVEYED): Phase.LOADING,
    (Phase.LOADING, PhaseEvent.LOADED): Phase.RUNNING,
    (Phase.CONFIRM, PhaseEvent.ENDED): Phase.CLOSED,
    (Phase.SURVEY, PhaseEvent.ENDED): Phase.CLOSED,
    (Phase.LOADING, PhaseEvent.ENDED): Phase.CLOSED,
    (Phase.RUNNING, PhaseEvent.ENDED): Phase.CLOSED,
}
"""(phase, event) -> the next phase: every move a session makes."""

WRITES_PLANS = frozenset({Phase.LOADING, Phase.RUNNING})
"""The phases in which a session writes commands that could move a relay (through
the safety rule); before them it only asks questions."""

CONFIRMED = frozenset({Phase.SURVEY, Phase.LOADING, Phase.RUNNING})
"""The phases in which the box's unit id is confirmed ours (another unit's id heard
in them ends the session)."""


@dataclass(slots=True)
class SessionNotes:
    """What a session carries beside its phase (cleared when a session starts)."""

    foreign: UnitIdReply | None = None
    """Another unit's id, heard while confirming (the confirmation then refuses)."""
    survey_tries: int = 0
    """In survey: how many times the survey has been asked."""
    reconciliation: Reconciliation | None = None
    """In survey: what the survey found, waiting for the engine to take the adopted
    stations before the session moves to loading and writes."""


class PhaseError(Moas2Error, RuntimeError):
    """A move the table does not hold: a bug in the session, never the box's doing."""


class WriteRefused(PhaseError):
    """A plan written outside :data:`WRITES_PLANS`: a bug in the session, refused."""

    @staticmethod
    def text(where: str, phase: Phase) -> str:
        """What is logged (and raised, under tests) for a plan refused in ``phase``."""
        return (f"{where}: a programming error: a plan was to be written in phase "
                f"{phase.value}, where the phase table allows none; refused, and the "
                "session ends")


def next_phase(phase: Phase, event: PhaseEvent) -> Phase:
    """The phase ``event`` leads to from ``phase``; :class:`PhaseError` if none."""
    try:
        return TRANSITIONS[(phase, event)]
    except KeyError:
        raise PhaseError(f"no move from {phase.value} on {event.value}") from None


__all__ = [
    "CONFIRMED",
    "TRANSITIONS",
    "WRITES_PLANS",
    "Phase",
    "PhaseError",
    "PhaseEvent",
    "SessionNotes",
    "WriteRefused",
    "next_phase",
]
