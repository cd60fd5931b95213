"""Which question a reply from the box answers.

The box answers its questions in the order it was asked them, one answer
each, and an answer carries nothing that names its question.  So the link
keeps every question it asked in the current session in order, and an answer
goes to the oldest open question of its kind, even when that question's asker
has stopped waiting (timed out): such a late answer is thrown away, never given
to a later asker of the same kind, which would otherwise get an old answer and
every later asker the one before its own.

A question whose asker gave up stays open for one more answer timeout, then is
forgotten (the box may never have heard it: a garbled byte on the line), so that
one lost question does not shift every later answer.  Questions end with the
session: the link reopens the port (which empties what the port had received)
and starts counting again.
"""

from __future__ import annotations

import asyncio
from collections import deque
from dataclasses import dataclass
from enum import Enum
from typing import Any


class Answer(Enum):
    """What became of a reply."""

    ANSWERED = "answered"
    LATE = "late"
    """It answers a question whose asker gave up: thrown away."""
    UNASKED = "unasked"
    """Nothing of its kind was asked in this session: thrown away."""


@dataclass(slots=True)
class _Question:
    reply_type: type
    future: asyncio.Future[Any]
    forget_at: float
    """The link clock's time after which an answer is no longer expected once its asker
    gave up."""


class Questions:
    """The questions of one session, oldest first."""

    __slots__ = ("_open",)

    def __init__(self) -> None:
        self._open: deque[_Question] = deque()

    def ask(self, reply_type: type, future: asyncio.Future[Any], forget_at: float) -> None:
        """A question was written; ``future`` gets its answer."""
        self._open.append(_Question(reply_type, future, forget_at))

    def answer(self, message: object, now: float) -> Answer:
        """Give ``message`` to the question it answers, if any."""
        if any(q.future.done() and q.forget_at < now for q in self._open):
            self._open = deque(
                q for q in self._open if not (q.future.done() and q.forget_at < now)
            )
        for question in self._open:
            if isinstance(message, question.reply_type):
                self._open.remove(question)
                if question.future.done():
                    return Answer.LATE
                question.future.set_result(message)
                return Answer.ANSWERED
        return Answer.UNASKED

    def end(self, error: BaseException) -> None:
        """The session ended: every waiting asker gets ``error``; all is forgotten."""
        for question in self._open:
            if not question.future.done():
                question.future.set_exception(error)
        self._open.clear()

    def __len__(self) -> int:
        return len(self._open)


__all__ = ["Answer", "Questions"]
