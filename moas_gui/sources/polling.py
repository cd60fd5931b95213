"""The asyncio part shared by the rig daemons that must be asked (rigctld, flrig).

A :class:`PolledRig` connects over TCP, asks its subclass's :meth:`~PolledRig.poll`
every ``interval`` seconds (10 times a second by default), and hands a
:class:`~moas_gui.sources.base.FrequencyReport` to its sink when the radio's
frequencies or transmit state changed since the last report (and always for
the first reading after a connection).  The rules of docs/sources.md:

- **The daemon goes away** (refused, reset, no answer within ``timeout``):
  one warning, then attempts with a growing pause (``retry``, 0.5 s, doubling
  to 10 s)
  and only rate-limited debug lines; one info line when it is back.
- **A reply that makes no sense** (garbage, too long, an absurd frequency):
  dropped with one rate-limited debug line, nothing reaches the sink; the
  connection is out of step, so a fresh one is made after a pause.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

from moas_gui.errors import ProtocolError
from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import (
    DEFAULT_RETRY,
    RETRY_LIMIT,
    BadInputLog,
    ConnectionLog,
    FrequencyReport,
    SourceSink,
    check_khz,
)

DEFAULT_INTERVAL: Final = 0.1
"""Seconds between two polls: 10 Hz."""
DEFAULT_TIMEOUT: Final = 2.0
"""Seconds a connection or an answer may take before the daemon counts as gone."""


class BadReply(ProtocolError, ValueError):
    """A reply the parser refused; ``reason`` is a short key for counting."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class RigState:
    """One poll's answer, in the engine's units."""

    rx_khz: float | None
    tx_khz: float | None
    transmitting: bool | None


class PolledRig:
    """Base of the polled sources: a subclass gives :meth:`poll` (and :meth:`connected`)."""

    kind = "polled"
    label = "rig daemon"
    default_port = 0
    """The daemon's own port, taken when none is given."""

    def __init__(
        self,
        station: int,
        radio: int,
        on_event: SourceSink,
        *,
        host: str = "127.0.0.1",
        port: int | None = None,
        interval: float = DEFAULT_INTERVAL,
        timeout: float = DEFAULT_TIMEOUT,
        retry: float = DEFAULT_RETRY,
        logger: logging.Logger | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if not interval > 0:
            raise ValueError(f"the poll interval must be more than 0 s, not {interval}")
        self.station = station
        self.radio = radio
        self.host = host
        port = self.default_port if port is None else port
        self.port = port
        self.interval = interval
        self.timeout = timeout
        self._on_event = on_event
        self.origin = f"{self.label} {host}:{port}"
        log = logger or logging.getLogger(f"moas_gui.sources.{self.kind}")
        self.log = log
        self.bad = BadInputLog(log, self.label, clock=clock)
        self.link = ConnectionLog(log, f"{self.label} at {host}:{port}", clock=clock)
        self._backoff = Pauses(Backoff(first=retry, most=max(retry, RETRY_LIMIT)))
        self._task: asyncio.Task[None] | None = None
        self._closing = False
        self._last: RigState | None = None
        self.polls = 0
        """Answers read (for tests and benchmarks)."""
        self.reports = 0
        self.connects = 0
        self.answered_at = 0.0
        """``time.perf_counter()`` when the bytes completing the last answer were read
        (set by :meth:`poll`; for the benchmark)."""

    # -- what a subclass gives ----------------------------------------------------------
    async def connected(self, reader: asyncio.StreamReader,
                        writer: asyncio.StreamWriter) -> None:
        """A new connection is open (reset parsers here)."""

    async def poll(self, reader: asyncio.StreamReader,
                   writer: asyncio.StreamWriter) -> RigState:
        """Ask once and read the answer; :class:`BadReply` when it makes no sense."""
        raise NotImplementedError

    # -- the Source shape -----------------------------------------------------------------
    async def start(self) -> int:
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._run(),
                                                                name=f"{self.kind} poller")
        return self.port

    async def close(self) -> None:
        self._closing = True  # ends the loop even if a cancellation were lost on the way
        task, self._task = self._task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task

    def forget(self) -> None:
        """Report the next reading even if it has not changed (the engine restarted)."""
        self._last = None

    # -- the loop ---------------------------------------------------------------------------
    async def _run(self) -> None:
        loop = asyncio.get_running_loop()
        while not self._closing:
            try:
                # asyncio.timeout, not wait_for: on Python 3.11 wait_for may swallow the
                # cancellation of close() when its inner call finishes at the same moment
                async with asyncio.timeout(self.timeout):
                    reader, writer = await asyncio.open_connection(self.host, self.port)
            except (OSError, TimeoutError) as exc:
                self.link.lost(_why(exc))
                await asyncio.sleep(self._backoff.next())
                continue
            self.connects += 1
            self._last = None
            try:
                await self.connected(reader, writer)
                while not self._closing:
                    started = loop.time()
                    async with asyncio.timeout(self.timeout):
                        state = await self.poll(reader, writer)
                    self.polls += 1
                    if self.polls == 1 or not self.link.connected:
                        self.link.up()
                        self._backoff.reset()
                    self._deliver(state)
                    await asyncio.sleep(max(0.0, self.interval - (loop.time() - started)))
            except BadReply as exc:
                self.bad.drop(exc.reason, f"{self.host}:{self.port}", str(exc))
            except (OSError, TimeoutError, asyncio.IncompleteReadError, EOFError) as exc:
                self.link.lost(_why(exc))
            finally:
                writer.close()
                with contextlib.suppress(Exception):
                    await writer.wait_closed()
            await asyncio.sleep(self._backoff.next())

    def _deliver(self, state: RigState) -> None:
        if state.rx_khz is None:
            self.bad.drop("no_frequency", f"{self.host}:{self.port}",
                          "the rig did not say its frequency")
            return
        try:
            rx = check_khz(state.rx_khz, "the frequency")
            tx = check_khz(state.tx_khz, "the transmit frequency") \
                if state.tx_khz is not None else rx
        except ValueError as exc:
            self.bad.drop("absurd", f"{self.host}:{self.port}", str(exc))
            return
        transmitting = state.transmitting
        if transmitting is None and self._last is not None:
            transmitting = self._last.transmitting  # one unreadable PTT changes nothing
        state = RigState(rx, tx, transmitting)
        if state == self._last:
            return
        self._last = state
        self.reports += 1
        self._on_event(FrequencyReport(self.station, self.radio, rx, tx, self.origin,
                                       transmitting=state.transmitting))


def _why(exc: BaseException) -> str:
    if isinstance(exc, TimeoutError):
        return "no answer in time"
    if isinstance(exc, asyncio.IncompleteReadError | EOFError):
        return "the connection was closed"
    if isinstance(exc, OSError) and exc.errno:
        return os.strerror(exc.errno).lower()
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc) or type(exc).__name__


__all__ = ["DEFAULT_INTERVAL", "DEFAULT_TIMEOUT", "BadReply", "PolledRig", "RigState"]
