"""A Hy-Gain DCU-1 as a pure model: it turns, and it never says a word.

It accepts ``AP1ddd;`` (load), ``AM1;`` (go), ``AS1;`` (stop) and a lone
``;`` (reset, which stops the motor), with any CR, LF or spaces between
commands.  Anything else is ignored, as the real box does.  The antenna
turns at a steady speed on a Hy-Gain rotator whose end stop is at south.
"""

from __future__ import annotations

import logging

from .base import DEFAULT_SPEED, Axis
from .dcu1 import HYGAIN_STOP, to_bearing, to_travel

log = logging.getLogger(__name__)

_LONGEST = 12
"""No DCU-1 family command is longer; a longer run without terminator is noise."""


def next_command(buffer: bytes) -> tuple[int, bytes | None]:
    """Cuts one DCU-1 family command from the start of ``buffer``.

    Returns ``(consumed, command)``: ``(0, None)`` when more bytes are needed,
    ``command`` None for bytes to skip quietly (CR, LF, spaces).  Commands
    starting with ``A`` run to ``;`` or CR, and keep their terminator
    (``b"AP1090;"``, ``b"AP1090\\r"``); every other byte is a command of one
    byte (``b";"``, ``b"E"``, or something the controller does not know).
    """
    if not buffer:
        return 0, None
    first = buffer[0]
    if first in b"\r\n ":
        return 1, None
    if first != ord("A"):
        return 1, buffer[:1]
    for i in range(1, min(len(buffer), _LONGEST)):
        if buffer[i] in b";\r":
            return i + 1, buffer[: i + 1]
        if buffer[i] == ord("A"):
            return i, buffer[:i]  # an unterminated command, then the next one
    if len(buffer) >= _LONGEST:
        return _LONGEST, buffer[:_LONGEST]
    return 0, None


def parse_bearing(command: bytes) -> float | None:
    """The bearing of ``AP1ddd;`` or ``AP1ddd\\r`` (000-360), or None."""
    digits = command[3:-1]
    if not command.startswith(b"AP1") or len(digits) != 3 or not digits.isdigit():
        return None
    value = int(digits)
    return float(value) if value <= 360 else None


class HyGainRotator:
    """The antenna side shared by the DCU-1 and the Rotor-EZ: compass bearings, stop at south."""

    def __init__(self, bearing: float, speed: float, now: float, stop: float) -> None:
        self._stop_at = stop
        self.axis = Axis(to_travel(bearing, stop), 0.0, 360.0, speed, now)

    @property
    def bearing(self) -> float:
        return to_bearing(self.axis.position, self._stop_at)

    def go_to(self, bearing: float, now: float) -> None:
        self.axis.advance(now)
        travel = to_travel(bearing, self._stop_at)
        if travel == 0.0 and self.axis.position > 180.0:
            travel = 360.0  # the stop bearing is at both ends: take the nearer one
        self.axis.go_to(travel, now)

    def place(self, bearing: float, now: float) -> None:
        self.axis.place(to_travel(bearing, self._stop_at), now)


class DCU1Emulator:
    """A DCU-1 control box with its rotator; see the module docstring."""

    def __init__(self, bearing: float = 0.0, speed: float = DEFAULT_SPEED, now: float = 0.0,
                 stop: float = HYGAIN_STOP) -> None:
        self._rotator = HyGainRotator(bearing, speed, now, stop)
        self._loaded: float | None = None
        self._buffer = b""

    @property
    def azimuth(self) -> float:
        return self._rotator.bearing

    @property
    def busy(self) -> bool:
        return self._rotator.axis.moving

    def receive(self, data: bytes, now: float) -> bytes:
        self._rotator.axis.advance(now)
        self._buffer += data
        while True:
            used, command = next_command(self._buffer)
            if used == 0:
                break
            self._buffer = self._buffer[used:]
            if command is not None:
                self._obey(command, now)
        return b""

    def advance(self, now: float) -> bytes:
        self._rotator.axis.advance(now)
        return b""

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._rotator.place(azimuth, now)

    def _obey(self, command: bytes, now: float) -> None:
        if command.endswith(b";") and command.startswith(b"AP1"):
            self._loaded = parse_bearing(command)
        elif command == b"AM1;":
            if self._loaded is not None:
                self._rotator.go_to(self._loaded, now)
        elif command in (b"AS1;", b";"):
            self._rotator.axis.stop(now)
        else:
            log.debug("DCU-1 emulator ignores %r", command)


__all__ = ["DCU1Emulator", "HyGainRotator", "next_command", "parse_bearing"]
