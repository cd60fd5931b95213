"""What a switch session asks its driver to do: the actions, and the link's status.

A :class:`~.session.SwitchSession` call returns a list of these, for the driver
(:class:`~.link.SwitchLink`) to carry out in order.  Also here: :class:`Voice`, the
session's status and what it says of an outage (each problem once), and
:func:`describe`, a message from the box in words for the debug log.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Mapping
from dataclasses import dataclass, fields, is_dataclass
from enum import Enum

Slots = tuple[int, int, int]
"""A station's transmit, receive and alternate antennas (switch slots)."""


class LinkStatus(str, Enum):
    CONNECTING = "connecting"
    OK = "ok"
    UNRESPONSIVE = "unresponsive"
    STOPPED = "stopped"


@dataclass(frozen=True, slots=True)
class Write:
    """Write these bytes to the port now."""

    data: bytes


@dataclass(frozen=True, slots=True)
class StatusChanged:
    """The link's status changed."""

    status: LinkStatus


@dataclass(frozen=True, slots=True)
class Transmit:
    """A station began (True) or ended (False) transmitting."""

    station: int
    transmitting: bool


@dataclass(frozen=True, slots=True)
class BoxError:
    """The box refused a command (the text names it)."""

    text: str


@dataclass(frozen=True, slots=True)
class Log:
    """A line for the log, at ``level`` (:mod:`logging`'s): the session decides what to
    say and how loud, the driver writes it."""

    level: int
    text: str


@dataclass(frozen=True, slots=True)
class Adopt:
    """A survey found stations whose antennas on the box win over the saved state: the
    engine should take ``stations`` (slots by station; ``transmitting``: those keyed
    then) as those ports' antennas, all at once; then the driver calls
    :meth:`.session.SwitchSession.reconcile` with the engine's wanted state.  A survey
    with nothing to adopt reconciles at once, with the wanted state the session has."""

    stations: Mapping[int, Slots]
    transmitting: frozenset[int]


@dataclass(frozen=True, slots=True)
class Answered:
    """The answer to the driver's question ``ticket`` (None: no answer)."""

    ticket: int
    reply: object | None


@dataclass(frozen=True, slots=True)
class End:
    """The session is over: close the port and try again later.  ``reached``: the box
    had become ready in it (the retries start over)."""

    reached: bool


Action = Write | Log | StatusChanged | Transmit | BoxError | Adopt | Answered | End


class Voice:
    """The session's status, and what it says of an outage: each problem once."""

    __slots__ = ("_last_problem", "status")

    def __init__(self) -> None:
        self.status = LinkStatus.CONNECTING
        self._last_problem = ""

    def set(self, status: LinkStatus) -> list[Action]:
        """The status is ``status`` now: a :class:`StatusChanged` if that is news."""
        if status is self.status:
            return []
        self.status = status
        return [StatusChanged(status)]

    def problem(self, level: int, text: str) -> list[Action]:
        """A problem, said once per outage: its first warning (and an error not said yet)
        at its level; what the retries meet after it at debug level."""
        quiet = text == self._last_problem or (
            level <= logging.WARNING and bool(self._last_problem))
        self._last_problem = text
        return [Log(logging.DEBUG if quiet else level, text)]

    def recovered(self, where: str) -> list[Action]:
        """The box answers again: the outage (if any) is over."""
        said: list[Action] = [Log(logging.INFO, f"{where} answers again")] \
            if self._last_problem else []
        self._last_problem = ""
        return said


def describe(message: object) -> str:
    """A message from the box in words for the debug log: ``antenna event: station 1,
    status TX fast (F), antenna 3`` rather than its Python form."""
    name = re.sub(r"(?<!^)(?=[A-Z])", " ", type(message).__name__).lower()
    if not is_dataclass(message):
        return name
    parts = []
    for item in fields(message):
        value = getattr(message, item.name)
        if isinstance(value, Enum):
            shown = f"{value.name.replace('_', ' ').lower()} ({value.value})"
        elif isinstance(value, frozenset | set | tuple | list):
            shown = ", ".join(str(v) for v in sorted(value, key=str)) or "none"
        else:
            shown = str(value)
        parts.append(f"{item.name.replace('_', ' ')} {shown}")
    return f"{name}: {', '.join(parts)}" if parts else name


__all__ = [
    "Action",
    "Adopt",
    "Answered",
    "BoxError",
    "End",
    "LinkStatus",
    "Log",
    "Slots",
    "StatusChanged",
    "Transmit",
    "Voice",
    "Write",
    "describe",
]
