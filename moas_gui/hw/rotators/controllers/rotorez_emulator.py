"""An Idiom Press Rotor-EZ as a pure model, quirks included.

- ``AI1;`` answers ``;ddd`` (or ``ddd;`` when built as a Green Heron style
  box, ``green_heron=True``), the bearing in whole degrees 000-359.
- ``AP1ddd;`` loads a bearing; ``AM1;`` starts the turn; ``AP1ddd<CR>``
  loads and starts at once; ``;`` stops.
- The option letters ``E e J j O o S s`` are accepted silently.
- Anything it does not understand, including ``;`` while standing still,
  makes it send ``C2000 IDIOM V1.4S `` (trailing space), as real units do.
- ``stray_byte=True`` puts the 0xE0 some units emit at power-on in front of
  the first answer.
"""

from __future__ import annotations

from .base import DEFAULT_SPEED
from .dcu1 import HYGAIN_STOP
from .dcu1_emulator import HyGainRotator, next_command, parse_bearing

BANNER = b"C2000 IDIOM V1.4S "
"""The undocumented text a Rotor-EZ sends for a command it does not understand."""

OPTION_LETTERS = frozenset(b"EeJjOoSs")


class RotorEZEmulator:
    """A Rotor-EZ board with its rotator; see the module docstring."""

    def __init__(self, bearing: float = 0.0, speed: float = DEFAULT_SPEED, now: float = 0.0,
                 stop: float = HYGAIN_STOP, green_heron: bool = False,
                 stray_byte: bool = False) -> None:
        self._rotator = HyGainRotator(bearing, speed, now, stop)
        self._green_heron = green_heron
        self._loaded: float | None = None
        self._buffer = b""
        self._pending = b"\xe0" if stray_byte else b""

    @property
    def azimuth(self) -> float:
        return self._rotator.bearing

    @property
    def busy(self) -> bool:
        return self._rotator.axis.moving

    def receive(self, data: bytes, now: float) -> bytes:
        self._rotator.axis.advance(now)
        self._buffer += data
        out = self._pending
        self._pending = b""
        while True:
            used, command = next_command(self._buffer)
            if used == 0:
                break
            self._buffer = self._buffer[used:]
            if command is not None:
                out += self._obey(command, now)
        return out

    def advance(self, now: float) -> bytes:
        self._rotator.axis.advance(now)
        return b""

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._rotator.place(azimuth, now)

    def _reading(self) -> bytes:
        value = int(self._rotator.bearing + 0.5) % 360
        return b"%03d;" % value if self._green_heron else b";%03d" % value

    def _obey(self, command: bytes, now: float) -> bytes:
        if command == b"AI1;":
            return self._reading()
        if command.startswith(b"AP1"):
            bearing = parse_bearing(command)
            if bearing is None:
                return BANNER
            self._loaded = bearing
            if command.endswith(b"\r"):
                self._rotator.go_to(bearing, now)
            return b""
        if command == b"AM1;":
            if self._loaded is not None:
                self._rotator.go_to(self._loaded, now)
            return b""
        if command == b";":
            if not self._rotator.axis.moving:
                return BANNER
            self._rotator.axis.stop(now)
            return b""
        if len(command) == 1 and command[0] in OPTION_LETTERS:
            return b""
        return BANNER


__all__ = ["BANNER", "RotorEZEmulator"]
