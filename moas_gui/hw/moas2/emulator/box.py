"""An emulated MOAS II in real time: the pure model, driven by an asyncio
loop so its timers (inhibit time, interrupt delay, receive delay) run out by
themselves.

No ports here either: the computer's bytes come in through
:meth:`EmulatedBox.receive`, the box's bytes go to whatever :meth:`attach`
was given (a pseudo-terminal, a serial port, or a switch link in the same
process).  Windows watch it with :meth:`add_listener`.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from enum import Enum

from moas_gui.clock import Clock, Timer

from .model import EmulatorModel
from .record import Record
from .view import BoxView

log = logging.getLogger(__name__)


class Traffic(str, Enum):
    """What a listener is told about."""

    RECEIVED = "received"
    """Bytes from the computer (data holds them)."""
    SENT = "sent"
    """Bytes the box sent (data holds them)."""
    CHANGED = "changed"
    """The box's state may have changed (data is empty)."""


Listener = Callable[[Traffic, bytes], None]
Sink = Callable[[bytes], None]


class EmulatedBox:
    """One emulated switch on the running asyncio loop."""

    def __init__(
        self,
        model: EmulatorModel | None = None,
        *,
        loop: asyncio.AbstractEventLoop | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.model = model if model is not None else EmulatorModel()
        self._loop = loop
        self.clock = clock
        """What the timers run on; None: the event loop's own clock."""
        self._sink: Sink | None = None
        self._listeners: list[Listener] = []
        self._timer: Timer | None = None
        self._due = 0.0

    # ------------------------------------------------------------------ wiring

    @property
    def loop(self) -> asyncio.AbstractEventLoop:
        if self._loop is None:
            self._loop = asyncio.get_running_loop()
        return self._loop

    def attach(self, sink: Sink | None) -> None:
        """Send the box's output to ``sink`` (None: nobody listens; output is lost)."""
        self._sink = sink

    def add_listener(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener`` on traffic and changes; returns the way to stop."""
        self._listeners.append(listener)

        def remove() -> None:
            if listener in self._listeners:
                self._listeners.remove(listener)

        return remove

    def close(self) -> None:
        """Stop the timers and forget the output sink."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self._sink = None

    # ------------------------------------------------------------------ inputs

    def now(self) -> float:
        return self.loop.time() if self.clock is None else self.clock.now()

    def receive(self, data: bytes) -> None:
        """Bytes from the computer."""
        self._tell(Traffic.RECEIVED, data)
        self._send(self.model.feed(data, self.now()))

    def set_tr(self, station: int, transmitting: bool) -> None:
        """Key or unkey a station (what the radio's amplifier key line does)."""
        self._send(self.model.set_tr(station, transmitting, self.now()))

    def view(self) -> BoxView:
        return self.model.view()

    @property
    def record(self) -> Record:
        """Every relay change, key change and reset, with the key states (:mod:`.record`)."""
        return self.model.record

    # ------------------------------------------------------------------ internals

    def _send(self, out: bytes) -> None:
        if out:
            self._tell(Traffic.SENT, out)
            if self._sink is not None:
                try:
                    self._sink(out)
                except OSError as exc:
                    log.warning("emulator: could not send %r: %s", out, exc)
        self._tell(Traffic.CHANGED, b"")
        self._schedule()

    def _schedule(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        deadline = self.model.next_deadline()
        if deadline is not None:
            self._due = deadline
            if self.clock is None:
                self._timer = self.loop.call_at(deadline, self._on_timer)
            else:
                self._timer = self.clock.call_later(deadline - self.clock.now(), self._on_timer)

    def _on_timer(self) -> None:
        # asyncio may call a little early (within its clock resolution).
        self._timer = None
        self._send(self.model.advance(max(self.now(), self._due)))

    def _tell(self, kind: Traffic, data: bytes) -> None:
        for listener in list(self._listeners):
            try:
                listener(kind, data)
            except Exception:  # a broken window must not stop the box
                log.exception("emulator: a listener failed on %s", kind.value)


__all__ = ["EmulatedBox", "Listener", "Sink", "Traffic"]
