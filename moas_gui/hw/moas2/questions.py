"""The questions a switch session has in flight: tickets, answers, timeouts and pings.

Pure bookkeeping, no I/O and no clock of its own.  The box answers in order, so:

* a question (``:;``, ``";``, ``|;``) is answered by the first message of its reply
  type; one that is not answered within the answer timeout is given up (its asker
  hears "no answer"), and forgotten one timeout later (a late answer meanwhile is
  dropped, not taken for the next question's);
* pings (``';``) are answered by pongs in the order they went out; each ping closes a
  :class:`~.diagnostics.Batch` of the commands written before it, so an error the box
  sends before that pong belongs to one of them, and a pong that says the box is not
  as active as the batch left it means it was reset or lost power;
* the current phase's questions are a :class:`Step`: answered by name, they move the
  phase on; anyone else's answer is an :class:`~.actions.Answered` for the driver.
"""

from __future__ import annotations

import logging
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from .actions import Action, Answered
from .commands import encode
from .diagnostics import Batch
from .messages import Command, Ping, Pong, RelayStatusRequest, StatusRequest, UnitId

log = logging.getLogger(__name__)


QUESTIONS = (Ping, UnitId, StatusRequest, RelayStatusRequest)
"""What a session asks: questions, which change nothing in the box.  :meth:`Questions.asked`
takes nothing else; a command that could move a relay goes through the safety rule."""


def only_question(where: str, command: Command) -> None:
    """:class:`TypeError` unless ``command`` is a question (:data:`QUESTIONS`)."""
    if not isinstance(command, QUESTIONS):
        raise TypeError(f"{where}: {type(command).__name__} is not a question; "
                        "commands that move relays go through the safety rule")


@dataclass(slots=True)
class _Question:
    reply_type: type
    ticket: int
    expires: float
    """When the asker stops waiting."""
    gave_up: bool = False
    forget_at: float = 0.0


@dataclass(slots=True)
class Step:
    """The questions the current phase waits for, by name, and their answers."""

    asked: dict[str, int] = field(default_factory=dict)
    answers: dict[str, Any] = field(default_factory=dict)

    def done(self) -> bool:
        return len(self.answers) == len(self.asked)


class Questions:
    """Tickets, the questions in flight and the pings, for one session at a time."""

    def __init__(self, where: str, answer_timeout: float, ping_interval: float) -> None:
        self.where = where
        self.timeout = answer_timeout
        self.interval = ping_interval
        self.step = Step()
        self.last_heard = 0.0
        self.next_ping: float | None = None
        """When a running session pings next (None: it is not running)."""
        self._tickets = 0
        self._questions: deque[_Question] = deque()
        self._pings: deque[tuple[Batch, int | None]] = deque()
        self._batch = Batch(None)

    def clear(self, now: float) -> None:
        """A new session: nothing is in flight; the box counts as heard now."""
        self.last_heard = now
        self.next_ping = None
        self._questions.clear()
        self._pings.clear()
        self._batch = Batch(None)
        self.step = Step()

    def ticket(self) -> int:
        self._tickets += 1
        return self._tickets

    def asked(self, command: Command, reply_type: type, now: float,
              expect_active: bool | None) -> tuple[int, bytes]:
        """``command`` is asked now: its ticket and its bytes.  A ping also closes the
        batch, judged by ``expect_active`` (None: not judged).  :class:`TypeError` for
        anything but a question (:data:`QUESTIONS`)."""
        only_question(self.where, command)
        ticket = self.ticket()
        self._questions.append(_Question(reply_type, ticket, now + self.timeout))
        if isinstance(command, Ping):
            return ticket, self.pinged(expect_active, ticket)
        return ticket, encode(command)

    def pinged(self, expect_active: bool | None, ticket: int | None = None) -> bytes:
        """A ping goes out (the running session's own, or a question's)."""
        self._pings.append((Batch(expect_active, self._batch.commands), ticket))
        self._batch = Batch(None)
        return encode(Ping())

    def ping_due(self, now: float) -> bool | None:
        """A running session's ping: None when not due, False when the box has been
        silent past the answer timeout (the session ends), True when one goes out now
        (:meth:`pinged`; the next is due one interval later)."""
        if self.next_ping is None or now < self.next_ping:
            return None
        if now - self.last_heard > self.timeout:
            return False
        self.next_ping = now + self.interval
        return True

    def wrote(self, parts: list[bytes]) -> None:
        """A plan's commands went out: the next ping's batch holds them."""
        self._batch.commands += parts

    def blamed(self) -> list[bytes]:
        """The commands an error the box sends now may belong to."""
        return self._pings[0][0].commands if self._pings else self._batch.commands

    def unjudge(self) -> None:
        """The pings still out were asked before a new load: their pongs are not judged."""
        for earlier, _ in self._pings:
            earlier.expect_active = None

    def took(self, message: object) -> tuple[Batch | None, list[Action]]:
        """``message`` came: the batch its pong closes (None: not a pong of ours), and
        the answers for the driver."""
        if isinstance(message, Pong):
            if not self._pings:
                log.debug("%s: dropped a pong no ping of this session asked for", self.where)
                return None, []
            batch, ticket = self._pings.popleft()
            found = next((q for q in self._questions if q.ticket == ticket), None)
            if ticket is not None and found is None:
                log.debug("%s: dropped a late pong (its asker gave up)", self.where)
            return batch, self._settled(found, message)
        found = next((q for q in self._questions if isinstance(message, q.reply_type)), None)
        return None, self._settled(found, message)

    def _settled(self, question: _Question | None, message: object) -> list[Action]:
        if question is None:
            return []
        self._questions.remove(question)
        if question.gave_up:
            log.debug("%s: dropped a late answer (its asker gave up): %s", self.where, message)
            return []
        return self.answer(question.ticket, message)

    def answer(self, ticket: int, reply: object | None) -> list[Action]:
        """``ticket``'s answer: the step's, or the driver's."""
        for name, asked in self.step.asked.items():
            if asked == ticket:
                self.step.answers[name] = reply
                return []
        return [Answered(ticket, reply)]

    def expired(self, now: float) -> list[Action]:
        """Time passed: questions not answered in time are given up (answered None),
        those given up long ago forgotten."""
        out: list[Action] = []
        for q in list(self._questions):
            if q.gave_up and q.forget_at <= now:
                self._questions.remove(q)  # the box may never have heard it
            elif not q.gave_up and q.expires <= now:
                q.gave_up = True
                q.forget_at = q.expires + self.timeout
                out += self.answer(q.ticket, None)
        return out

    def deadline(self) -> float | None:
        """When a question is to be given up or forgotten next, or a ping is due."""
        return min([q.forget_at if q.gave_up else q.expires for q in self._questions]
                   + ([self.next_ping] if self.next_ping is not None else []), default=None)

    def dropped(self) -> list[Action]:
        """The session ended: every question still awaited is answered None."""
        out: list[Action] = []
        for q in self._questions:
            if not q.gave_up:
                out += self.answer(q.ticket, None)
        self._questions.clear()
        self._pings.clear()
        self.step = Step()
        self.next_ping = None
        return out


__all__ = ["QUESTIONS", "Questions", "Step", "only_question"]
