"""The link's calls on its session, each stamped with the time and recorded.

:class:`SessionCalls` is the one collaborator through which :class:`~.link.SwitchLink`
calls its :class:`~.session.SwitchSession`: every call takes the time from the link's
clock and, when a recording runs (``--record-serial``, :class:`.recording.SerialRecorder`),
writes the call first with that time, so that a replay (:func:`.recording.replay`)
hands the session the same times.  The bytes written to the box are recorded here too
(:meth:`SessionCalls.wrote`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from ...engine.switchstate import SwitchState
from .actions import Action, LinkStatus
from .messages import Command
from .recording import SerialRecorder, command_text
from .session import SwitchSession
from .sync import stopped


class SessionCalls:
    """A session's inputs as the link makes them: stamped, recorded, handed over."""

    __slots__ = ("_now", "_recorder", "session", "switch_id")

    def __init__(self, session: SwitchSession, now: Callable[[], float],
                 recorder: SerialRecorder | None) -> None:
        self.session = session
        self.switch_id = session.switch_id
        self._now = now
        self._recorder = recorder

    def _stamp(self, kind: str, **fields: object) -> float:
        """The time now, after writing the call ``kind`` to the recording (if any)."""
        now = self._now()
        if self._recorder is not None:
            self._recorder.note(self.switch_id, kind, now, **fields)
        return now

    def opened(self) -> list[Action]:
        return self.session.opened(self._stamp("opened"))

    def feed(self, data: bytes) -> list[Action]:
        return self.session.feed(data, self._stamp("in", data=data))

    def tick(self) -> list[Action]:
        return self.session.tick(self._stamp("tick"))

    def lost(self, reason: str) -> list[Action]:
        self._stamp("lost", reason=reason)
        return self.session.lost(reason)

    def closed(self) -> list[Action]:
        """The driver closed the port after an End (or to stop): unresponsive."""
        self._stamp("closed")
        return self.session.voice.set(LinkStatus.UNRESPONSIVE)

    def apply(self, state: SwitchState, automatic: bool) -> list[Action]:
        now = self._stamp("want", state=state, automatic=automatic)
        return self.session.apply(state, now, automatic=automatic)

    def stop(self) -> list[Action]:
        """Stop Switches, for a driver without an engine: the wanted state, inactive."""
        self._stamp("stop")
        return self.session.apply(stopped(self.session.desired))

    def start(self) -> list[Action]:
        """Start Switches, for a driver without an engine: the wanted state, active."""
        self._stamp("start")
        return self.session.apply(replace(self.session.desired, active=True))

    def reset(self) -> list[Action]:
        self._stamp("reset")
        return self.session.reset()

    def reconcile(self, desired: SwitchState) -> list[Action]:
        return self.session.reconcile(desired, self._stamp("reconcile", state=desired))

    def ask(self, command: Command, reply_type: type) -> tuple[int, list[Action]]:
        now = self._stamp("ask", command=command_text(command))
        return self.session.ask(command, reply_type, now)

    def wrote(self, data: bytes) -> None:
        """Bytes went to the box."""
        self._stamp("out", data=data)


__all__ = ["SessionCalls"]
