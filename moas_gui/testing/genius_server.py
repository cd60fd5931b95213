"""A Rotator Genius emulator: the controller's rules as a pure model (time passed
in) and an asyncio TCP server on loopback that serves it.

The model has two rotors.  Each turns from its CCW limit clockwise to its CW
limit (equal limits, or 0 and 360, mean one full turn with the stop at the
CCW limit) at ``speed`` degrees a second and never through the stop; a
target outside that travel is refused with ``F``, as is any move of a rotor
without a sensor.  ``|S`` stops both rotors, as rev. 4 says.

Test hooks on :class:`GeniusServer`: ``model`` (set ``sensor`` false for
999, move a rotor by hand with ``set_azimuth``), ``prefix`` (bytes put before
the next reply: garbage), ``mute`` (stop answering), ``acknowledge_turns``
(false: carry out ``|A`` but send no ``|AK``/``|AF``, as some units and
firmware versions may), ``drop()``, ``clock`` (the rotors turn on it).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from dataclasses import dataclass, field

from moas_gui.clock import LOOP_CLOCK, Clock
from moas_gui.hw.rotators.genius_codec import (
    GeniusCommand,
    GeniusCommandDecoder,
    GeniusGarbage,
    GeniusStatus,
    RotorBlock,
    encode_reply,
    encode_status,
)
from moas_gui.hw.rotators.headings import Travel, Turn, plan_turn, whole_heading

log = logging.getLogger(__name__)


@dataclass(slots=True)
class EmulatedRotor:
    name: str = ""
    limit_ccw: int = 0
    limit_cw: int = 360
    configuration: str = "A"
    offset: int = 0
    sensor: bool = True
    position: float = 0.0
    """Degrees clockwise from the CCW limit."""
    turn: Turn | None = None
    turn_began: float = 0.0

    @property
    def travel(self) -> Travel:
        rotation = (self.limit_cw - self.limit_ccw) % 360 or 360
        return Travel(self.limit_ccw, rotation, has_stop=True)

    def position_at(self, now: float, speed: float) -> float:
        if self.turn is None:
            return self.position
        return self.turn.position_after((now - self.turn_began) * speed)


@dataclass(slots=True)
class GeniusModel:
    speed: float = 6.0
    rotors: tuple[EmulatedRotor, EmulatedRotor] = field(
        default_factory=lambda: (EmulatedRotor("TOWER 1"), EmulatedRotor("TOWER 2"))
    )

    def advance(self, now: float) -> None:
        """Finish the turns that are over by ``now``."""
        for rotor in self.rotors:
            turn = rotor.turn
            if turn is not None and (now - rotor.turn_began) * self.speed >= turn.degrees:
                rotor.position, rotor.turn = turn.end, None

    def _halt(self, rotor: EmulatedRotor, now: float) -> None:
        rotor.position = rotor.position_at(now, self.speed)
        rotor.turn = None

    def set_azimuth(self, rotor_number: int, azimuth: float, now: float) -> None:
        """Someone turned the rotor by hand: it now points at ``azimuth``."""
        rotor = self.rotors[rotor_number - 1]
        rotor.turn = None
        rotor.position = rotor.travel.nearest_position(azimuth)

    def status(self, now: float) -> GeniusStatus:
        self.advance(now)
        blocks = tuple(self._block(rotor, now) for rotor in self.rotors)
        return GeniusStatus((blocks[0], blocks[1]), active="2")

    def _block(self, rotor: EmulatedRotor, now: float) -> RotorBlock:
        travel = rotor.travel
        turn = rotor.turn
        moving = 0 if turn is None else (1 if turn.direction > 0 else 2)
        position = rotor.position_at(now, self.speed)
        return RotorBlock(
            azimuth=whole_heading(travel.heading_at(position)) if rotor.sensor else None,
            limit_cw=rotor.limit_cw, limit_ccw=rotor.limit_ccw,
            configuration=rotor.configuration, moving=moving, offset=rotor.offset,
            target=None if turn is None else whole_heading(travel.heading_at(turn.end)),
            start=None if turn is None else whole_heading(travel.heading_at(turn.start)),
            name=rotor.name,
        )

    def handle(self, command: GeniusCommand, now: float) -> bytes:
        """The controller's answer to one command."""
        self.advance(now)
        if command.kind == "h":
            return encode_status(self.status(now))
        if command.kind == "S":
            for rotor in self.rotors:
                self._halt(rotor, now)
            return encode_reply("S", True)
        assert command.rotor is not None
        rotor = self.rotors[command.rotor - 1]
        if command.kind == "c":
            return encode_reply("c", True)
        if not rotor.sensor:
            return encode_reply(command.kind, False)
        travel = rotor.travel
        if command.kind == "A":
            assert command.azimuth is not None
            if command.azimuth > 360 or not travel.reaches(command.azimuth):
                return encode_reply("A", False)
            self._halt(rotor, now)
            self._start(rotor, plan_turn(travel, rotor.position, command.azimuth), now)
            return encode_reply("A", True)
        self._halt(rotor, now)
        end = travel.rotation if command.kind == "P" else 0.0
        self._start(rotor, Turn(rotor.position, end), now)
        return encode_reply(command.kind, True)

    @staticmethod
    def _start(rotor: EmulatedRotor, turn: Turn, now: float) -> None:
        rotor.turn = turn if turn.direction != 0 else None
        rotor.turn_began = now


class GeniusServer:
    """Serves a :class:`GeniusModel` on TCP (loopback by default)."""

    def __init__(self, model: GeniusModel | None = None, host: str = "127.0.0.1",
                 port: int = 0, *, acknowledge_turns: bool = True,
                 clock: Clock = LOOP_CLOCK) -> None:
        self.model = model or GeniusModel()
        self.clock = clock
        """The rotors turn on this clock (a test's fake clock makes turns take no time)."""
        self.host, self.port = host, port
        self.prefix = b""
        self.mute = False
        self.acknowledge_turns = acknowledge_turns
        self.commands: list[GeniusCommand | GeniusGarbage] = []
        self._server: asyncio.Server | None = None
        self._writers: set[asyncio.StreamWriter] = set()

    def now(self) -> float:
        return self.clock.now()

    async def start(self) -> int:
        self._server = await asyncio.start_server(self._serve, self.host, self.port)
        self.port = self._server.sockets[0].getsockname()[1]
        return self.port

    async def drop(self) -> None:
        """Stop listening and close every connection."""
        if self._server is not None:
            self._server.close()
            await self._server.wait_closed()
            self._server = None
        writers, self._writers = list(self._writers), set()
        for writer in writers:
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()

    close = drop

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self._writers.add(writer)
        decoder = GeniusCommandDecoder()
        try:
            while data := await reader.read(256):
                for command in decoder.feed(data):
                    self.commands.append(command)
                    if isinstance(command, GeniusGarbage):
                        log.warning("Rotator Genius emulator: %r (%s)", command.data,
                                    command.reason)
                        continue
                    if self.mute:
                        continue
                    reply = self.model.handle(command, self.now())
                    if command.kind == "A" and not self.acknowledge_turns:
                        continue
                    reply = self.prefix + reply
                    self.prefix = b""
                    writer.write(reply)
        except (ConnectionError, OSError):
            pass
        finally:
            self._writers.discard(writer)
            writer.close()
            with contextlib.suppress(OSError):
                await writer.wait_closed()


__all__ = ["EmulatedRotor", "GeniusModel", "GeniusServer"]
