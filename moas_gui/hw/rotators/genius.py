"""RotatorGenius rotators: a 4O3A Rotator Genius on the network.

Configuration: ``Address`` is ``host[:port]`` (port 9006 by default) and
``Port`` is which of the controller's two rotators (1 or 2).  Both rotators of
one controller share one connection, polled with ``|h`` every ``Poll``
milliseconds (the shortest of the two).  A turn is ``|A`` with the compass
heading (clamped to the configured travel first); the controller picks the
path within its own limits.  ``|S`` is the only stop the protocol has, and it
stops *both* rotators of the controller.

A rotator whose azimuth reads 999 has no sensor: it is shown offline until a
real azimuth comes back.  A reply that makes no sense is logged with the
rotators it concerns and skipped; no reply within ``Timing.reply_timeout``
drops the connection, which is then made again with back-off.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Callable

from moas_gui.aio import cancel_and_wait
from moas_gui.clock import timeout
from moas_gui.config.model import Rotator

from .base import Publish, RotatorDriver, RotatorStatus, Timing
from .genius_codec import (
    Event,
    GeniusGarbage,
    GeniusReply,
    GeniusStatus,
    ReplyDecoder,
    RotorBlock,
    encode_move,
    encode_read,
    encode_stop,
)
from .headings import Travel, whole_heading
from .tcp_peer import keep_connected

log = logging.getLogger(__name__)

GENIUS_PORT = 9006


class GeniusLink:
    def __init__(self, host: str, port: int, timing: Timing) -> None:
        self.host, self.port, self.timing = host, port, timing
        self.drivers: list[GeniusRotator] = []
        self._lock = asyncio.Lock()
        self._reader: asyncio.StreamReader | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._decoder = ReplyDecoder()
        self._task: asyncio.Task[None] | None = None

    @property
    def where(self) -> str:
        return f"Rotator Genius at {self.host}:{self.port}"

    @property
    def connected(self) -> bool:
        return self._writer is not None and not self._writer.is_closing()

    @property
    def poll(self) -> float:
        return max(min(d.rotator.poll for d in self.drivers) / 1000, 0.05)

    def attach(self, driver: GeniusRotator) -> None:
        self.drivers.append(driver)

    async def start(self) -> None:
        if self._task is None:
            self._task = asyncio.create_task(self._run(), name=self.where)

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)

    async def request(self, command: bytes, answer: str) -> GeniusStatus | GeniusReply:
        """Send one command and wait for its answer (``"h"`` or a command letter).

        Raises ``ConnectionError`` when not connected and ``TimeoutError``
        when no answer comes; either way the connection is then reset.
        """
        async with self._lock:
            reader, writer = self._reader, self._writer
            if reader is None or writer is None or writer.is_closing():
                raise ConnectionError(f"{self.where} is not connected")
            try:
                writer.write(command)
                async with timeout(self.timing.clock, self.timing.reply_timeout):
                    await writer.drain()
                    return await self._answer(reader, answer)
            except (OSError, TimeoutError):
                writer.close()
                raise

    async def turn(self, command: bytes, confirms: Callable[[GeniusStatus], bool]) -> GeniusReply | None:
        """Send a turn (``|A``) and wait for whichever comes first: the
        controller's ``|AK``/``|AF``, or a status in which ``confirms`` sees
        the turn under way.  Returns the reply, or None when a status
        confirmed it.

        The status is asked for with ``|h`` while waiting, and every status
        read is handed to the drivers.  Raises ``TimeoutError`` when neither
        comes within ``Timing.reply_timeout`` (the connection is then reset
        only if the controller answered nothing at all), ``ConnectionError``
        when not connected.
        """
        async with self._lock:
            reader, writer = self._reader, self._writer
            if reader is None or writer is None or writer.is_closing():
                raise ConnectionError(f"{self.where} is not connected")
            heard = False
            try:
                writer.write(command)
                async with timeout(self.timing.clock, self.timing.reply_timeout):
                    await writer.drain()
                    while True:
                        with contextlib.suppress(TimeoutError):
                            async with timeout(self.timing.clock, self._turn_check):
                                return await self._wait_for_reply(reader)
                        writer.write(encode_read())
                        await writer.drain()
                        event = await self._answer(reader, "hA")
                        heard = True
                        if isinstance(event, GeniusReply):
                            return event
                        self._hand_out(event)
                        if confirms(event):
                            return None
            except TimeoutError:
                if not heard:
                    writer.close()
                raise
            except OSError:
                writer.close()
                raise

    @property
    def _turn_check(self) -> float:
        """How long a turn waits for ``|AK`` before looking at the status."""
        return min(self.poll, self.timing.reply_timeout / 4)

    async def _wait_for_reply(self, reader: asyncio.StreamReader) -> GeniusReply:
        event = await self._answer(reader, "A")
        assert isinstance(event, GeniusReply)
        return event

    def _hand_out(self, status: GeniusStatus) -> None:
        for driver in self.drivers:
            driver.on_status(status.rotors[driver.rotor - 1])

    async def _answer(self, reader: asyncio.StreamReader, answers: str) -> GeniusStatus | GeniusReply:
        """Read until an answer to one of ``answers`` (``"h"`` for a status,
        command letters for replies) comes."""
        while True:
            data = await reader.read(512)
            if not data:
                raise ConnectionResetError("it closed the connection")
            found: GeniusStatus | GeniusReply | None = None
            for event in self._decoder.feed(data):
                if found is None and _answers(event, answers):
                    assert isinstance(event, GeniusStatus | GeniusReply)
                    found = event
                else:
                    self._unexpected(event)
            if found is not None:
                return found

    def _unexpected(self, event: Event) -> None:
        names = ", ".join(d.name for d in self.drivers)
        if isinstance(event, GeniusGarbage):
            log.warning("%s (%s) sent a malformed reply %r: %s; skipped",
                        self.where, names, event.data[:80], event.reason)
        else:
            log.debug("%s: unexpected %s", self.where, event)

    async def _run(self) -> None:
        await keep_connected(self.host, self.port, self._session, self.timing,
                             where=self.where, log=log)

    async def _session(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        log.info("%s: connected", self.where)
        self._reader, self._writer, self._decoder = reader, writer, ReplyDecoder()
        try:
            while True:
                status = await self.request(encode_read(), "h")
                assert isinstance(status, GeniusStatus)
                self._hand_out(status)
                await self.timing.clock.sleep(self.poll)
        except TimeoutError:
            log.warning("%s did not answer within %.1f s; reconnecting",
                        self.where, self.timing.reply_timeout)
        except OSError as exc:
            log.warning("%s: connection lost (%s); reconnecting", self.where, exc)
        finally:
            self._reader = self._writer = None
            for driver in self.drivers:
                driver.link_down()
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()


def _answers(event: Event, answers: str) -> bool:
    if isinstance(event, GeniusStatus):
        return "h" in answers
    return isinstance(event, GeniusReply) and event.command in answers


class GeniusRotator(RotatorDriver):
    def __init__(self, rotator: Rotator, travel: Travel, publish: Publish,
                 link: GeniusLink) -> None:
        super().__init__(rotator, travel, publish)
        if rotator.port not in (1, 2):
            raise ValueError(f"Port must be 1 or 2 (the controller's rotator), not {rotator.port}")
        self.rotor = rotator.port
        self.link = link
        self.position: float | None = None
        self._sensor = True
        link.attach(self)

    async def start(self) -> None:
        self._set(RotatorStatus())

    def on_status(self, block: RotorBlock) -> None:
        if block.azimuth is None:
            if self._sensor:
                log.warning("%s rotator %d reports no sensor (999); %s shown offline",
                            self.link.where, self.rotor, self.name)
            self._sensor = False
            self._set(RotatorStatus(heading=self._status.heading, online=False))
            return
        if not self._sensor:
            log.info("%s rotator %d has its sensor back", self.link.where, self.rotor)
        self._sensor = True
        self.position = self.travel.nearest_position(block.azimuth, near=self.position)
        moving = block.moving != 0
        target = block.target if moving and block.target is not None else None
        self._set(RotatorStatus(heading=float(block.azimuth),
                                target=None if target is None else float(target),
                                moving=moving, online=True))

    def travel_position(self) -> float | None:
        return self.position

    def link_down(self) -> None:
        self._set(RotatorStatus(heading=self._status.heading, online=False))

    def check_ready(self) -> None:
        if not self.link.connected:
            raise self._unavailable(f"cannot turn: {self.link.where} is not connected")
        if not self._sensor:
            raise self._unavailable(f"cannot turn: {self.link.where} reports no sensor")

    async def rotate(self, heading: float) -> None:
        self.check_ready()
        end = self.travel.nearest_position(heading, near=self.position)
        azimuth = whole_heading(self.travel.heading_at(end))
        if not self.travel.reaches(heading):
            log.info("%s cannot point at %.0f degrees; turning to the end of its travel (%d)",
                     self.title, heading, azimuth)
        before = self._status.heading
        try:
            reply = await self.link.turn(
                encode_move(self.rotor, azimuth),
                lambda status: _under_way(status.rotors[self.rotor - 1], azimuth, before),
            )
        except TimeoutError as exc:
            if not self.link.connected:
                raise self._unavailable(
                    f"got no answer from {self.link.where}: no answer in time") from exc
            raise self._unavailable(
                f"{self.link.where} did not confirm the turn to {azimuth} degrees: no |AK "
                f"and the heading did not move within {self.link.timing.reply_timeout:.1f} s"
            ) from exc
        except OSError as exc:
            raise self._unavailable(f"got no answer from {self.link.where}: {exc}") from exc
        if reply is not None and not reply.ok:
            raise self._unavailable(f"was refused the turn to {azimuth} degrees by {self.link.where}")
        if reply is None and not self._status.moving:
            return  # already there: the status said so
        self._set(RotatorStatus(heading=self._status.heading, target=float(azimuth),
                                moving=True, online=True))

    async def stop(self) -> None:
        self.check_ready()
        reply = await self._ask(encode_stop(), "S")
        if not reply.ok:
            raise self._unavailable(f"could not be stopped: {self.link.where} answered F")
        self._set(RotatorStatus(heading=self._status.heading, online=True))

    async def _ask(self, command: bytes, answer: str) -> GeniusReply:
        try:
            reply = await self.link.request(command, answer)
        except (OSError, TimeoutError) as exc:
            why = str(exc) or "no answer in time"
            raise self._unavailable(f"got no answer from {self.link.where}: {why}") from exc
        assert isinstance(reply, GeniusReply)
        return reply


def _under_way(block: RotorBlock, azimuth: int, before: float | None) -> bool:
    """Whether a status shows the turn to ``azimuth`` taken up: the rotor
    moving towards it, or its heading changed since the turn was sent, or
    already there."""
    if block.azimuth is None:
        return False
    if block.moving != 0:
        return block.target is None or block.target == azimuth
    return block.azimuth == azimuth or (before is not None and block.azimuth != before)


__all__ = ["GENIUS_PORT", "GeniusLink", "GeniusRotator"]
