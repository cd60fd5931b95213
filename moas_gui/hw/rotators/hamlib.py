"""Hamlib rotators: a running ``rotctld`` reached over TCP.

Configuration: ``Address`` is ``host[:port]`` of the daemon (4533 by
default).  On connect the driver asks ``+\\dump_state`` for the daemon's
azimuth scale (``min_az``..``max_az``), then polls ``+p`` every ``Poll``
milliseconds; a turn is ``+P <azimuth> <elevation>`` (the elevation last
read) and a stop ``+S``.  Positions are converted between the daemon's
unwrapped scale and the rotator's travel with
:func:`.headings.azimuth_of` / :func:`.headings.position_of`, so a rotator
with overlap turns the way the heading rules choose.

rotctld never says whether the rotator moves: :class:`.tracking.TurnTracker`
infers it.  No answer within ``Timing.reply_timeout`` (the daemon stays
silent on commands it does not know) or a closed connection (its answer to
an I/O error on the rotator) makes the driver reconnect with back-off.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging

from moas_gui.aio import cancel_and_wait
from moas_gui.clock import timeout
from moas_gui.config.model import Rotator

from .base import Publish, RotatorDriver, RotatorStatus, Timing
from .hamlib_codec import (
    ExtendedReply,
    Limits,
    ReplyAssembler,
    encode_dump_state,
    encode_get_pos,
    encode_set_pos,
    encode_stop,
    error_text,
    limits_of,
)
from .headings import Travel, angular_distance, azimuth_of, position_of
from .tcp_peer import keep_connected
from .tracking import TurnTracker, linear_distance

log = logging.getLogger(__name__)

MAX_LINE = 4096


class HamlibRotator(RotatorDriver):
    def __init__(self, rotator: Rotator, travel: Travel, publish: Publish, timing: Timing,
                 host: str, port: int) -> None:
        super().__init__(rotator, travel, publish)
        self.host, self.port, self.timing = host, port, timing
        self.poll = max(rotator.poll / 1000, 0.05)
        self.limits = Limits()
        self.elevation = 0.0
        self.azimuth_read: float | None = None
        """The daemon's azimuth (on its own scale) last read."""
        self.tracker = TurnTracker(
            tolerance=timing.arrival_tolerance,
            stall_after=max(timing.stall_polls * self.poll, timing.stall_min),
            moving_window=2 * self.poll + 0.25,
            distance=linear_distance if travel.bounded else angular_distance,
        )
        self._lock = asyncio.Lock()
        self._reader: asyncio.StreamReader | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._task: asyncio.Task[None] | None = None
        self._answering = False
        """True once the daemon has answered a position in this connection."""
        self._skip_dump_state = False
        """Set when the daemon would not answer dump_state (so later connections skip it)."""

    @property
    def where(self) -> str:
        return f"rotctld at {self.host}:{self.port}"

    @property
    def connected(self) -> bool:
        return self._writer is not None and not self._writer.is_closing()

    async def start(self) -> None:
        self._publish_now()
        self._task = asyncio.create_task(self._run(), name=f"{self.name} via {self.where}")

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)

    # ---- requests --------------------------------------------------------------------

    def check_ready(self) -> None:
        if not self._answering:
            raise self._unavailable(f"cannot turn: {self.where} is not connected")

    def travel_position(self) -> float | None:
        return self.tracker.position

    def forget_turn(self) -> None:
        self.tracker.end()
        self._publish_now()

    async def rotate(self, heading: float) -> None:
        self.check_ready()
        end = self.travel.nearest_position(heading, near=self.tracker.position)
        if not self.travel.reaches(heading):
            log.info("%s cannot point at %.0f degrees; turning to the end of its travel (%.0f)",
                     self.title, heading, self.travel.heading_at(end))
        azimuth = azimuth_of(self.travel, end, self.limits.min_az, self.limits.max_az,
                             near=self.azimuth_read)
        reply = await self._ask(encode_set_pos(azimuth, self.elevation), "turn")
        if reply.code != 0:
            raise self._unavailable(
                f"was refused the turn to {azimuth:.0f} by {self.where}: {error_text(reply.code)}"
            )
        self.tracker.begin(end, self._now())
        self._publish_now()

    async def stop(self) -> None:
        self.forget_turn()
        reply = await self._ask(encode_stop(), "stop")
        if reply.code != 0:
            raise self._unavailable(f"could not be stopped by {self.where}: "
                                    f"{error_text(reply.code)}")

    async def _ask(self, command: bytes, what: str) -> ExtendedReply:
        try:
            return await self._request(command)
        except (OSError, TimeoutError, ValueError) as exc:
            why = str(exc) or "no answer in time"
            raise self._unavailable(f"cannot {what}: {self.where}: {why}") from exc

    async def _request(self, command: bytes) -> ExtendedReply:
        """One command, its whole extended answer.  Raises ``OSError`` (not
        connected, closed), ``TimeoutError`` or ``ValueError`` (a line too long);
        the connection is then closed so the poller reconnects."""
        async with self._lock:
            reader, writer = self._reader, self._writer
            if reader is None or writer is None or writer.is_closing():
                raise ConnectionError(f"{self.where} is not connected")
            assembler = ReplyAssembler()
            try:
                writer.write(command)
                async with timeout(self.timing.clock, self.timing.reply_timeout):
                    await writer.drain()
                    while True:
                        line = await reader.readline()
                        if not line:
                            raise ConnectionResetError("it closed the connection")
                        reply = assembler.add(line.decode("latin-1"))
                        if reply is not None:
                            return reply
            except (OSError, TimeoutError, ValueError):
                writer.close()
                raise

    # ---- polling ---------------------------------------------------------------------

    async def _run(self) -> None:
        await keep_connected(self.host, self.port, self._session, self.timing,
                             where=f"{self.name}: {self.where}", log=log, limit=MAX_LINE)

    async def _session(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        log.info("%s: connected to %s", self.name, self.where)
        self._reader, self._writer = reader, writer
        try:
            if not self._skip_dump_state:
                try:
                    self._learn_limits(await self._request(encode_dump_state()))
                except TimeoutError:
                    self._skip_dump_state = True
                    log.warning("%s: %s gave no complete answer to dump_state; will do "
                                "without its limits (%g..%g)", self.name, self.where,
                                self.limits.min_az, self.limits.max_az)
                    raise
            while True:
                self._take_position(await self._request(encode_get_pos()))
                self._answering = True
                if self.tracker.tick(self._now()) == "stalled":
                    log.info("%s stopped short of its target", self.title)
                self._publish_now()
                await self.timing.clock.sleep(self.poll)
        except TimeoutError:
            log.warning("%s: %s did not answer within %.1f s; reconnecting",
                        self.name, self.where, self.timing.reply_timeout)
        except (OSError, ValueError) as exc:
            log.warning("%s: %s: %s; reconnecting", self.name, self.where, exc)
        finally:
            self._reader = self._writer = None
            self._answering = False
            self._publish_now()
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()

    def _learn_limits(self, reply: ExtendedReply) -> None:
        limits = limits_of(reply) if reply.code == 0 else None
        if limits is None:
            log.warning("%s: %s gave no azimuth limits (%s); assuming %g..%g",
                        self.name, self.where, error_text(reply.code),
                        self.limits.min_az, self.limits.max_az)
            return
        self.limits = limits
        log.info("%s: %s azimuth scale %g..%g", self.name, self.where,
                 limits.min_az, limits.max_az)

    def _take_position(self, reply: ExtendedReply) -> None:
        if reply.code != 0:
            log.warning("%s: %s answered get_pos with %s", self.name, self.where,
                        error_text(reply.code))
            return
        azimuth = reply.number("Azimuth")
        if azimuth is None:
            log.warning("%s: %s sent a get_pos answer without a usable Azimuth: %r",
                        self.name, self.where, reply.records)
            return
        self.elevation = reply.number("Elevation") or 0.0
        self.azimuth_read = azimuth
        position = position_of(self.travel, azimuth, self.limits.min_az,
                               near=self.tracker.position)
        self.tracker.observe(position, self._now())

    def _now(self) -> float:
        return self.timing.clock.now()

    def _publish_now(self) -> None:
        position, target = self.tracker.position, self.tracker.target
        online = self.connected and self._answering
        self._set(RotatorStatus(
            heading=None if position is None else self.travel.heading_at(position),
            target=None if target is None else self.travel.heading_at(target),
            moving=online and self.tracker.moving(self._now()),
            online=online,
        ))


__all__ = ["HamlibRotator"]
