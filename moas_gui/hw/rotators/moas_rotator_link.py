"""Serial rotators: one TCP connection per MOAS Rotator program, shared by all
the rotators at that address.

On connect the link sends ``VERSION``, then every rotator's ``CONFIGURE``
(and, for a turn the program's departure interrupted, the ``ROTATE`` again).
Heading reports go to the rotator they name.  When the program goes away its
rotators show ``online: false`` (keeping their last heading) and the link
tries again after 0.5 s, 1 s, 2 s ... up to ``Timing.reconnect_max``.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging

from moas_gui.aio import cancel_and_wait
from moas_gui.config.model import Rotator

from .base import Publish, RotatorDriver, RotatorStatus, Timing
from .headings import Travel, angular_distance, normalize
from .moas_rotator_codec import (
    PORT,
    BadRotatorLine,
    HeadingReport,
    HeadingScale,
    PortReport,
    ReportDecoder,
    VersionReport,
    encode_configure,
    encode_rotate,
    encode_stop,
    encode_version,
)
from .tcp_peer import keep_connected
from .tracking import TurnTracker, linear_distance

log = logging.getLogger(__name__)

MOAS_ROTATOR_PORT = PORT


class MoasRotatorLink:
    def __init__(self, host: str, port: int, timing: Timing) -> None:
        self.host, self.port, self.timing = host, port, timing
        self.drivers: dict[int, SerialRotator] = {}
        self.version: str | None = None
        self._writer: asyncio.StreamWriter | None = None
        self._task: asyncio.Task[None] | None = None

    @property
    def where(self) -> str:
        return f"MOAS Rotator at {self.host}:{self.port}"

    @property
    def connected(self) -> bool:
        return self._writer is not None and not self._writer.is_closing()

    def attach(self, driver: SerialRotator) -> None:
        self.drivers[driver.rotator.id] = driver

    async def start(self) -> None:
        if self._task is None:
            self._task = asyncio.create_task(self._run(), name=self.where)

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)

    async def send(self, data: bytes) -> None:
        writer = self._writer
        if writer is None or writer.is_closing():
            raise ConnectionError(f"{self.where} is not connected")
        writer.write(data)
        await asyncio.wait_for(writer.drain(), self.timing.reply_timeout)

    async def _run(self) -> None:
        await keep_connected(self.host, self.port, self._session, self.timing,
                             where=self.where, log=log)

    async def _session(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        log.info("%s: connected", self.where)
        self._writer = writer
        try:
            hello = bytearray(encode_version())
            for driver in self.drivers.values():
                hello += driver.link_up()
            writer.write(bytes(hello))
            await asyncio.wait_for(writer.drain(), self.timing.reply_timeout)
            decoder = ReportDecoder()
            while data := await reader.read(4096):
                for report in decoder.feed(data):
                    self._dispatch(report)
            log.warning("%s closed the connection; its rotators are offline", self.where)
        except (OSError, TimeoutError) as exc:
            log.warning("%s: connection lost (%s); its rotators are offline", self.where, exc)
        finally:
            self._writer = None
            for driver in self.drivers.values():
                driver.link_down()
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()

    def _dispatch(self, report: HeadingReport | VersionReport | PortReport | BadRotatorLine
                  ) -> None:
        if isinstance(report, VersionReport):
            self.version = report.version
            log.info("%s: program version %s", self.where, report.version)
            return
        driver = self.drivers.get(report.rotator) if report.rotator is not None else None
        if isinstance(report, HeadingReport):
            if driver is None:
                log.warning("%s reports rotator %d, which is not configured here; ignored",
                            self.where, report.rotator)
            else:
                driver.on_report(report.degrees)
            return
        if isinstance(report, PortReport):
            if driver is not None:
                driver.on_port(report.reason)
            return
        about = f" about {driver.name}" if driver is not None else ""
        log.warning("%s sent a malformed line%s: %r (%s); ignored",
                    self.where, about, report.line, report.reason)


class SerialRotator(RotatorDriver):
    """A rotator on a serial port of a computer running the MOAS Rotator program."""

    def __init__(
        self, rotator: Rotator, travel: Travel, publish: Publish, timing: Timing,
        link: MoasRotatorLink, model_field: str, scale: HeadingScale,
    ) -> None:
        super().__init__(rotator, travel, publish)
        self.link, self.model_field, self.scale, self.timing = link, model_field, scale, timing
        poll = max(rotator.poll, 0) / 1000
        self.tracker = TurnTracker(
            tolerance=timing.arrival_tolerance,
            stall_after=max(timing.stall_polls * poll, timing.stall_min),
            moving_window=2 * poll + 0.25,
            distance=linear_distance if travel.bounded else angular_distance,
        )
        self._watch_every = min(max(poll, 0.1), 1.0)
        self._online = False
        self._unreachable: str | None = None
        """Why the program says it cannot reach this rotator's controller (its port is
        missing or failed), or None: then the rotator is offline too, and refuses turns."""
        self._task: asyncio.Task[None] | None = None
        link.attach(self)

    async def start(self) -> None:
        self._publish_now()
        self._task = asyncio.create_task(self._watch(), name=f"{self.name} watch")

    async def close(self) -> None:
        task, self._task = self._task, None
        if task is not None:
            await cancel_and_wait(task)

    # ---- called by the link ----------------------------------------------------------

    def travel_position(self) -> float | None:
        return self.tracker.position

    def link_up(self) -> bytes:
        """The program is (again) there: what to send for this rotator."""
        self._online = True
        out = encode_configure(self.rotator.id, self.model_field, self.rotator.comm_port,
                               self.rotator.poll)
        if self.tracker.target is not None:
            log.info("%s: resuming the turn the program's departure interrupted", self.name)
            out += encode_rotate(self.rotator.id, self._wire_degrees(self.tracker.target))
            self.tracker.begin(self.tracker.target, self._now())
        self._publish_now()
        return out

    def link_down(self) -> None:
        self._online = False
        self._unreachable = None  # the next program says afresh
        self._publish_now()

    def on_port(self, reason: str | None) -> None:
        """The program says the controller's port is unusable (why) or usable again."""
        if reason != self._unreachable:
            if reason is None:
                log.info("%s is online again: its controller's port is open", self.title)
            else:
                log.warning("%s is offline: %s", self.title, reason)
                self.tracker.end()  # no turn goes on where nothing is driven
        self._unreachable = reason
        self._publish_now()

    def on_report(self, degrees: float) -> None:
        if self.scale is HeadingScale.COMPASS:
            position = self.travel.nearest_position(degrees, near=self.tracker.position)
        elif self.travel.bounded:
            position = degrees
        else:
            position = normalize(degrees)
        self._unreachable = None  # a heading: the controller answers
        if self.tracker.observe(position, self._now()) == "arrived":
            log.debug("%s reached its target", self.name)
        self._publish_now()

    # ---- requests --------------------------------------------------------------------

    def check_ready(self) -> None:
        if not self.link.connected:
            raise self._unavailable(f"cannot turn: {self.link.where} is not connected")
        if self._unreachable is not None:
            raise self._unavailable(f"cannot turn: it is offline ({self._unreachable})")

    def forget_turn(self) -> None:
        self.tracker.end()
        self._publish_now()

    async def rotate(self, heading: float) -> None:
        self.check_ready()
        end = self.travel.nearest_position(heading, near=self.tracker.position)
        if not self.travel.reaches(heading):
            log.info("%s cannot point at %.0f degrees; turning to the end of its travel (%.0f)",
                     self.title, heading, self.travel.heading_at(end))
        try:
            await self.link.send(encode_rotate(self.rotator.id, self._wire_degrees(end)))
        except (OSError, TimeoutError) as exc:
            raise self._unavailable(f"cannot turn: {exc}") from exc
        self.tracker.begin(end, self._now())
        self._publish_now()

    async def stop(self) -> None:
        self.forget_turn()
        try:
            await self.link.send(encode_stop(self.rotator.id))
        except (OSError, TimeoutError) as exc:
            raise self._unavailable(f"cannot be told to stop: {exc}") from exc

    # ---- helpers ---------------------------------------------------------------------

    @property
    def usable(self) -> bool:
        """The program is connected and says the controller's port is open."""
        return self._online and self._unreachable is None

    def _wire_degrees(self, position: float) -> float:
        if self.scale is HeadingScale.COMPASS:
            return round(self.travel.heading_at(position)) % 360
        return position if self.travel.bounded else normalize(position)

    def _now(self) -> float:
        return self.timing.clock.now()

    def _publish_now(self) -> None:
        position, target = self.tracker.position, self.tracker.target
        self._set(RotatorStatus(
            heading=None if position is None else self.travel.heading_at(position),
            target=None if target is None else self.travel.heading_at(target),
            moving=self.usable and self.tracker.moving(self._now()),
            online=self.usable,
        ))

    async def _watch(self) -> None:
        while True:
            await self.timing.clock.sleep(self._watch_every)
            if self._online and self.tracker.tick(self._now()) == "stalled":
                log.info("%s stopped short of its target", self.title)
            self._publish_now()


__all__ = ["MOAS_ROTATOR_PORT", "MoasRotatorLink", "SerialRotator"]
