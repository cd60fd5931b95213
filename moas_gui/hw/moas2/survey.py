"""The survey of a switch session: what it asks, what the answers are, what it says.

Pure.  A session in survey asks :data:`SURVEY` (ping, box status, inhibit polarity,
relays); :func:`answered` turns the answers into a :class:`.resync.Survey` (or says
why they will not do); :func:`.resync.reconcile` judges what the box holds; and
:func:`found` says it: lines for the log and, when stations' antennas on the box win
over the saved state, one :class:`~.actions.Adopt` carrying every one of them.
"""

from __future__ import annotations

import logging
from typing import Any

from ...engine.switchstate import STATIONS, SwitchState
from .actions import Action, Adopt, Log, Slots
from .messages import (
    BoxStatus,
    Command,
    Ping,
    PolarityStatus,
    Pong,
    RelayStatus,
    RelayStatusRequest,
    StatusKind,
    StatusRequest,
)
from .reading import NOTHING
from .resync import Reconciliation, Survey

SURVEY: dict[str, tuple[Command, type]] = {
    "ping": (Ping(), Pong),
    "box": (StatusRequest(StatusKind.BOX), BoxStatus),
    "polarity": (StatusRequest(StatusKind.POLARITY), PolarityStatus),
    "relays": (RelayStatusRequest(), RelayStatus),
}
"""What a survey asks, by name: questions only (nothing that could move a relay)."""

SURVEY_TRIES = 3
"""How many times a session asks what the box holds before it gives up (and the
driver tries a new session later): a noisy line gets as many chances, and meanwhile
nothing is written that could move a relay."""


def answered(answers: dict[str, Any]) -> Survey | str:
    """The survey the answers make, or why they do not make one: "unanswered" (a
    question went unanswered: ask again) or "incomplete" (a box status too short)."""
    if any(answers[name] is None for name in SURVEY):
        return "unanswered"
    box: BoxStatus = answers["box"]
    if min(len(box.tx), len(box.rx), len(box.alt)) < len(STATIONS):
        return "incomplete"
    return Survey(answers["ping"], box, answers["polarity"], answers["relays"])


def trouble(where: str, result: str, tries: int) -> str:
    """What the session says of a survey that did not make one (``result``, from
    :func:`answered`) after ``tries``: asking again, or giving up for now."""
    if result == "incomplete":
        return f"{where} sent an incomplete box status; will retry"
    if tries < SURVEY_TRIES:
        return (f"{where} did not answer every status request; asking again (nothing is "
                "sent until it does)")
    return (f"{where} did not answer every status request ({SURVEY_TRIES} tries): not "
            "driving it until it does; will retry")


def found(where: str, held: SwitchState | None, r: Reconciliation) -> list[Action]:
    """What a survey found, as lines for the log and (when some are adopted) one
    :class:`~.actions.Adopt` with every station whose antennas on the box win."""
    if held is None:
        said = f"{where}: {r.why}: loading it (no reset)"
    elif r.why:
        said = (f"{where} does not hold the saved state ({r.why}): " +
                ("loading it again (no reset)" if r.believed is None else "sending what differs"))
    else:
        said = f"{where} still holds the saved state: carrying on without a reset{_waiting(r)}"
    out: list[Action] = [Log(logging.INFO, said)]
    for n, slots in sorted(r.adopt.items()):
        out.append(Log(logging.WARNING, (
            f"{where} station {n} "
            f"{'is transmitting on' if n in r.keyed else 'holds'} antennas "
            f"{_shown(slots)} (transmit, receive, alternate slots), "
            f"not the saved {_shown(_held_slots(held, n))}: keeping what the box holds")))
    if r.adopt:
        out.append(Adopt(dict(sorted(r.adopt.items())), frozenset(r.adopt) & r.keyed))
    return out


def _shown(slots: Slots) -> str:
    return "/".join(str(s) for s in slots)


def _waiting(r: Reconciliation) -> str:
    if not r.waiting:
        return ""
    names = ", ".join(str(n) for n in sorted(r.waiting))
    return f" (station {names} transmitting: its change waits for receive)"


def _held_slots(held: SwitchState | None, n: int) -> Slots:
    if held is None:
        return NOTHING
    s = held.station(n)
    return (s.tx, s.rx, s.alt)


__all__ = ["SURVEY", "SURVEY_TRIES", "answered", "found", "trouble"]
