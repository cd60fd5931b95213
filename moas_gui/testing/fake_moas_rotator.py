"""A stand-in for the MOAS Rotator program, on loopback, for tests and demos.

It speaks appendix B exactly (through :mod:`moas_gui.hw.rotators.moas_rotator_codec`) and, behind
it, simulates one controller per configured ``CommPort``: a ROTATE moves that
controller's number towards the target at ``speed`` degrees a second (for the
compass models DCU1 and RotorEZ, the shorter way round, wrapping at 360) and
every whole-degree change is reported to every connected server, as is the
current value right after CONFIGURE.  Like the real program it keeps no configuration
of its own: after :meth:`FakeMoasRotator.restart` it has forgotten every
CONFIGURE, while the controllers (the hardware) keep where they point.

Test hooks: ``commands`` (everything received, in order), :meth:`move_to` (the
controller moved by hand: reported at once), :meth:`send_raw` (garbage on the
wire), :meth:`drop` (the program goes away), :meth:`restart`; ``clock``: the
controllers turn on it (a fake clock makes a test's turns take no time).

Run ``python -m moas_gui.testing.fake_moas_rotator --port 13020`` to serve
one until interrupted.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import logging
from collections.abc import Callable
from dataclasses import dataclass

from moas_gui.aio import CleanStop, run_until_stopped
from moas_gui.clock import LOOP_CLOCK, Clock
from moas_gui.hw.rotators.moas_rotator_codec import (
    BadRotatorLine,
    CommandDecoder,
    Configure,
    Rotate,
    RotatorCommand,
    Stop,
    VersionRequest,
    encode_heading,
    encode_version_reply,
)

log = logging.getLogger(__name__)

COMPASS_NAMES = frozenset({"1", "2", "DCU1", "RotorEZ"})


@dataclass(slots=True)
class SimulatedController:
    """The hardware on one port: where it points and where it is going."""

    degrees: float = 0.0
    target: float | None = None
    reported: int | None = None
    compass: bool = False


class FakeMoasRotator:
    def __init__(
        self, host: str = "127.0.0.1", port: int = 0, *, speed: float = 10.0,
        tick: float = 0.05, version: str = "1.0", clock: Clock = LOOP_CLOCK,
    ) -> None:
        self.host, self.port = host, port
        self.speed, self.tick, self.version = speed, tick, version
        self.clock = clock
        """The controllers turn on this clock (a test's :class:`~moas_gui.clock.FakeClock`)."""
        self.controllers: dict[str, SimulatedController] = {}
        self.configured: dict[int, str] = {}
        """rotator number -> CommPort, as the last CONFIGUREs said."""
        self.commands: list[RotatorCommand | BadRotatorLine] = []
        self._server: asyncio.Server | None = None
        self._writers: set[asyncio.StreamWriter] = set()
        self._motion: asyncio.Task[None] | None = None
        self._changed = asyncio.Event()

    # ---- life ------------------------------------------------------------------------

    async def start(self) -> int:
        """Listen; returns the port (chosen by the system when 0 was given)."""
        self._server = await asyncio.start_server(self._serve, self.host, self.port)
        self.port = self._server.sockets[0].getsockname()[1]
        if self._motion is None:
            self._motion = asyncio.create_task(self._move(), name="fake MOAS Rotator motion")
        return self.port

    async def drop(self) -> None:
        """The program goes away: stop listening and close every connection."""
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()
            self._server = None
        writers, self._writers = list(self._writers), set()
        for writer in writers:
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()
        self.configured.clear()

    async def restart(self) -> None:
        """Start again on the same port, knowing nothing of earlier CONFIGUREs."""
        await self.drop()
        await self.start()

    async def close(self) -> None:
        await self.drop()
        if self._motion is not None:
            self._motion.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._motion
            self._motion = None

    @property
    def connections(self) -> int:
        return len(self._writers)

    # ---- test hooks ------------------------------------------------------------------

    def move_to(self, comm_port: str, degrees: float) -> None:
        """The controller on ``comm_port`` now points at ``degrees`` (reported at once)."""
        controller = self.controllers.setdefault(comm_port, SimulatedController())
        controller.degrees, controller.target = degrees, None
        self._report_changes()

    def send_raw(self, data: bytes) -> None:
        for writer in self._writers:
            writer.write(data)

    async def wait_for(self, predicate: Callable[[], bool], timeout: float = 5.0) -> None:
        """Wait until ``predicate()`` is true (checked after every command)."""
        async with asyncio.timeout(timeout):
            while not predicate():
                self._changed.clear()
                await self._changed.wait()

    # ---- protocol --------------------------------------------------------------------

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._writers.add(writer)
        decoder = CommandDecoder()
        try:
            while data := await reader.read(4096):
                for command in decoder.feed(data):
                    self.commands.append(command)
                    self._handle(command, writer)
                    self._changed.set()
        except (ConnectionError, OSError):
            pass
        finally:
            self._writers.discard(writer)
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()

    def _handle(self, command: RotatorCommand | BadRotatorLine,
                writer: asyncio.StreamWriter) -> None:
        if isinstance(command, VersionRequest):
            writer.write(encode_version_reply(self.version))
        elif isinstance(command, Configure):
            self.configured[command.rotator] = command.port
            controller = self.controllers.setdefault(command.port, SimulatedController())
            controller.compass = command.model in COMPASS_NAMES
            controller.reported = round(controller.degrees)
            writer.write(encode_heading(command.rotator, controller.degrees))
        elif isinstance(command, Rotate | Stop):
            port = self.configured.get(command.rotator)
            if port is None:
                log.warning("fake MOAS Rotator: %s for unconfigured rotator", command)
                return
            controller = self.controllers[port]
            controller.target = command.degrees if isinstance(command, Rotate) else None
        else:
            log.warning("fake MOAS Rotator: bad command %r (%s)", command.line, command.reason)

    async def _move(self) -> None:
        last = self.clock.now()
        while True:
            await self.clock.sleep(self.tick)
            now = self.clock.now()
            step, last = self.speed * (now - last), now
            for controller in self.controllers.values():
                if controller.target is None:
                    continue
                gap = controller.target - controller.degrees
                if controller.compass:
                    gap = (gap + 180.0) % 360.0 - 180.0
                if abs(gap) <= step:
                    controller.degrees, controller.target = controller.target, None
                else:
                    controller.degrees += step if gap > 0 else -step
                if controller.compass:
                    controller.degrees %= 360.0
            self._report_changes()

    def _report_changes(self) -> None:
        for rotator, port in self.configured.items():
            controller = self.controllers[port]
            whole = round(controller.degrees)
            if controller.compass:
                whole %= 360
            if whole != controller.reported:
                controller.reported = whole
                for writer in self._writers:
                    writer.write(encode_heading(rotator, whole))


async def _main(host: str, port: int) -> None:
    fake = FakeMoasRotator(host, port)
    await fake.start()
    done = asyncio.Event()
    with CleanStop(done.set):
        print(f"fake MOAS Rotator listening on {host}:{fake.port}", flush=True)
        await done.wait()
        await fake.close()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="A stand-in MOAS Rotator program (loopback).")
    parser.add_argument("--bind", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=13020)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO)
    run_until_stopped(_main(args.bind, args.port))


if __name__ == "__main__":
    main()


__all__ = ["FakeMoasRotator", "SimulatedController"]
