"""One rotator: its codec, its serial port, its polling, its reports.

A driver runs as one asyncio task.  Work is done in this order of priority:

1. a STOP (it also drops a turn not yet sent, and the rest of a turn half sent);
2. bytes the codec asked for after an answer (a SPID set frame);
3. the latest ROTATE (a burst of ROTATEs sends only the last one);
4. a poll, when due (every poll time; for a controller that reports by
   itself, only every :data:`ALIVE_CHECK` seconds, to notice it is gone).

Every write is followed by the model's quiet time; a poll waits for its
answer up to the model's reply timeout.  All these times are measured on the
driver's :class:`~moas_gui.clock.Clock` (the event loop's, or a test's fake one).  Headings are reported, in whole
degrees, only when they change.

Failures never stop the driver:

- a port that cannot be opened, or that fails (USB adapter pulled), is
  logged once, closed, and opened again every ``retry`` seconds;
- a controller that stops answering is logged after
  :data:`MISSES_BEFORE_REPORT` polls without an answer, polled on, and
  logged again when it answers;
- bytes that make no sense are logged (at most one line every
  :data:`GARBAGE_LOG_EVERY` seconds per rotator) and skipped.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
from collections import deque
from collections.abc import Callable

from moas_gui.clock import LOOP_CLOCK, Clock, timeout
from moas_gui.hw.rotators.controllers.base import (
    Ack,
    ControllerCodec,
    Garbage,
    Heading,
    Notice,
    Output,
    Send,
    check_range,
    whole,
)
from moas_gui.hw.rotators.controllers.models import Model

from .serial_link import ControllerPort, Opener, PortError, open_serial

log = logging.getLogger(__name__)

RETRY = 2.0
"""Seconds between attempts to open a port that is missing or failed."""
ALIVE_CHECK = 5.0
"""Seconds between questions to a controller that reports by itself."""
MIN_POLL = 0.1
"""Shortest poll time used, whatever the server asks for."""
MISSES_BEFORE_REPORT = 3
GARBAGE_LOG_EVERY = 5.0


class ControllerDriver:
    """Drives rotator ``rotator`` of ``model`` on ``port``; see the module docstring."""

    def __init__(self, rotator: int, model: Model, port: str, poll_ms: int,
                 report: Callable[[int, int], None], *, opener: Opener = open_serial,
                 port_state: Callable[[int, str | None], None] | None = None,
                 codec: ControllerCodec | None = None, retry: float = RETRY,
                 clock: Clock = LOOP_CLOCK) -> None:
        self.rotator = rotator
        self.model = model
        self.port = port
        self.poll_ms = poll_ms
        self.codec = codec if codec is not None else model.codec()
        self.heading: int | None = None
        self.estimated = False
        self._report = report
        self._port_state = port_state
        """Told when the port becomes unusable (why) and usable again (None)."""
        self._opener = opener
        self._retry = retry
        self._clock = clock
        info = self.codec.info
        interval = max(poll_ms / 1000.0, MIN_POLL)
        self.poll_interval = max(interval, ALIVE_CHECK) if info.unsolicited else interval
        self._task: asyncio.Task[None] | None = None
        self._link: ControllerPort | None = None
        self._lost: Exception | None = None
        self._wake = asyncio.Event()
        self._answered = asyncio.Event()
        self._stop_pending = False
        self._rotate_pending: float | None = None
        self._followups: deque[Send] = deque()
        self._next_poll = 0.0
        self._misses = 0
        self._silent = False
        self._open_failures = 0
        self._was_open = False
        self._opening = True
        """True until the first attempt to open the port is over (commands wait for it)."""
        self._garbage_at = -math.inf
        self._garbage_hidden = 0

    # -- public ----------------------------------------------------------------------------

    @property
    def label(self) -> str:
        return f"rotator {self.rotator} ({self.model.name} on {self.port})"

    @property
    def connected(self) -> bool:
        """True while the port is open."""
        return self._link is not None

    @property
    def answering(self) -> bool:
        """False once the controller has missed several polls in a row."""
        return not self._silent

    def same_setup(self, model: Model, port: str, poll_ms: int) -> bool:
        return (model.name, port, poll_ms) == (self.model.name, self.port, self.poll_ms)

    def start(self) -> None:
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(
                self._run(), name=f"rotator-{self.rotator}")

    async def close(self) -> None:
        task, self._task = self._task, None
        while task is not None and not task.done():  # a lost cancellation is sent again
            task.cancel()
            await asyncio.wait({task}, timeout=0.2)
        if task is not None and not task.cancelled() and task.exception() is not None:
            log.error("rotator %d: its loop had ended on an error", self.rotator,
                      exc_info=task.exception())
        self._close_link()

    def rotate(self, degrees: float) -> None:
        """Turns to ``degrees`` soon; raises ControllerError/PortError saying why not."""
        check_range(self.codec.info, degrees)
        self._check_usable()
        self._rotate_pending = degrees
        self._wake.set()

    def stop(self) -> None:
        """Stops the rotator as soon as the port allows; raises PortError when not open."""
        self._rotate_pending = None
        self._followups.clear()
        self._check_usable()
        self._stop_pending = True
        self._wake.set()

    def _check_usable(self) -> None:
        if self._link is None and not self._opening:
            raise PortError(f"port {self.port} is not open")

    # -- the task --------------------------------------------------------------------------

    async def _run(self) -> None:
        try:
            while True:
                if self._link is None:
                    if not await self._open():
                        await self._clock.sleep(self._retry)
                    continue
                try:
                    await self._step()
                except PortError as error:
                    self._drop(error)
                    await self._clock.sleep(self._retry)
        finally:
            self._close_link()

    async def _open(self) -> bool:
        try:
            link = await self._opener(self.port, self.codec.info.serial, self._on_data,
                                      self._on_lost)
        except PortError as error:
            self._open_failures += 1
            if self._open_failures == 1:
                self._drop(error)
            else:
                log.debug("%s: still cannot open: %s", self.label, error)
            return False
        self._opening = False
        self._link = link
        self._lost = None
        self._misses = 0
        self._silent = False
        if self._was_open or self._open_failures:
            log.info("%s: port open again", self.label)
        else:
            log.info("%s: port open", self.label)
        self._was_open = True
        self._open_failures = 0
        if self._port_state is not None:
            self._port_state(self.rotator, None)
        self._next_poll = self._clock.now()
        try:
            for send in self.codec.opening():
                await self._send(send)
        except PortError as error:
            self._drop(error)
            return False
        return True

    async def _step(self) -> None:
        self._check_lost()
        now = self._clock.now()
        if self._stop_pending:
            self._stop_pending = False
            self._rotate_pending = None
            self._followups.clear()
            await self._perform(self.codec.stop(now), interruptible=False)
        elif self._followups:
            await self._send(self._followups.popleft())
        elif self._rotate_pending is not None:
            degrees, self._rotate_pending = self._rotate_pending, None
            await self._perform(self.codec.rotate(degrees, now), interruptible=True)
        elif now >= self._next_poll:
            self._next_poll = now + self.poll_interval
            await self._perform(self.codec.poll(now), interruptible=False)
        else:
            wake_at = self._next_poll
            deadline = self.codec.deadline()
            if deadline is not None:
                wake_at = min(wake_at, deadline)
            self._wake.clear()
            with contextlib.suppress(TimeoutError):
                async with timeout(self._clock, max(0.0, wake_at - now)):
                    await self._wake.wait()
        for output in self.codec.tick(self._clock.now()):
            self._handle(output)

    async def _perform(self, outputs: list[Output], interruptible: bool) -> None:
        """Sends what a codec call returned, handling its events; a STOP cuts a turn short."""
        for output in outputs:
            if not isinstance(output, Send):
                self._handle(output)
                continue
            if interruptible and self._stop_pending:
                return
            await self._send(output)

    async def _send(self, send: Send) -> None:
        link = self._link
        if link is None:
            raise PortError(f"port {self.port} is not open")
        self._answered.clear()
        written_at = self._clock.now()
        link.write(send.data)
        info = self.codec.info
        if send.expects_reply:
            try:
                async with timeout(self._clock, info.reply_timeout):
                    await self._answered.wait()
                answered = True
            except TimeoutError:
                answered = False
            self._check_lost()
            self._note_answer(answered)
        quiet = written_at + max(send.pause, info.write_gap) - self._clock.now()
        if quiet > 0:
            await self._clock.sleep(quiet)
        self._check_lost()

    # -- what comes back -------------------------------------------------------------------

    def _on_data(self, data: bytes) -> None:
        for output in self.codec.receive(data, self._clock.now()):
            self._handle(output)

    def _on_lost(self, error: Exception) -> None:
        self._lost = error
        self._wake.set()
        self._answered.set()

    def _handle(self, output: Output) -> None:
        if isinstance(output, Send):
            self._followups.append(output)
            self._wake.set()
        elif isinstance(output, Heading):
            self._answered.set()
            value = whole(output.degrees)
            self.estimated = output.estimated
            if value != self.heading:
                self.heading = value
                self._report(self.rotator, value)
        elif isinstance(output, Notice):
            self._answered.set()
            log.info("%s: %s", self.label, output.text)
        elif isinstance(output, Ack):
            self._answered.set()
        elif isinstance(output, Garbage):
            self._garbage(output)

    def _garbage(self, garbage: Garbage) -> None:
        now = self._clock.now()
        if now - self._garbage_at < GARBAGE_LOG_EVERY:
            self._garbage_hidden += len(garbage.data)
            return
        hidden = (f" (and {self._garbage_hidden} more bad bytes since the last report)"
                  if self._garbage_hidden else "")
        log.warning("%s: ignored %d bytes from the controller, %s: %r%s", self.label,
                    len(garbage.data), garbage.reason, garbage.data[:40], hidden)
        self._garbage_at = now
        self._garbage_hidden = 0

    def _note_answer(self, answered: bool) -> None:
        if answered:
            if self._silent:
                log.info("%s: the controller answers again", self.label)
            self._silent = False
            self._misses = 0
            return
        self._misses += 1
        if self._misses == MISSES_BEFORE_REPORT:
            self._silent = True
            log.warning("%s: the controller is not answering (%d questions without a reply); "
                        "still trying", self.label, self._misses)

    # -- the port --------------------------------------------------------------------------

    def _check_lost(self) -> None:
        if self._lost is not None:
            raise PortError(f"port {self.port} failed: {self._lost}")

    def _drop(self, error: PortError) -> None:
        self._opening = False
        dropped = self._rotate_pending is not None or self._stop_pending
        log.warning("%s: %s; trying again every %g s%s", self.label, error, self._retry,
                    " (a pending command was dropped)" if dropped else "")
        self._rotate_pending = None
        self._stop_pending = False
        self._followups.clear()
        self._close_link()
        if self._port_state is not None:
            self._port_state(self.rotator, f"port {self.port}: {error}")

    def _close_link(self) -> None:
        link, self._link = self._link, None
        self._lost = None
        if link is not None:
            link.close()


__all__ = ["ALIVE_CHECK", "MIN_POLL", "RETRY", "ControllerDriver"]
