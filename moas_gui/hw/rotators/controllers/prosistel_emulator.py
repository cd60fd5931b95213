"""A Prosistel D control box (azimuth unit ``A``) as a pure model.

=====================  =========================  =====================================
command                answer                     effect
=====================  =========================  =====================================
``\\x02A?\\r``           ``\\x02A,?,ddd,R\\r``        -
``\\x02AGddd\\r``        ``\\x02A,G,R\\r``            turn to ddd (0-360)
``\\x02AG997\\r``/999    ``\\x02A,G,R\\r``            stop (soft / immediate: both stop here)
``\\x02AS\\r``           ``\\x02A,S,R\\r``            continuous position reports (CPM) off
another unit letter    ``\\x02X,?,E,00003\\r``      -
bad value or command   ``\\x02A,c,E,00001\\r``      -
=====================  =========================  =====================================

With ``cpm=True`` the box starts with continuous reports on: it sends the
position answer by itself whenever the whole-degree reading changes.  The
texts of the ``G``/``S`` acknowledgements and of the errors are not
documented anywhere this project could read; these satisfy Hamlib, which
only checks STX and the command letter.
"""

from __future__ import annotations

from .base import DEFAULT_SPEED, Axis, whole

STX = b"\x02"


class ProsistelEmulator:
    """A Prosistel D box with its rotator; see the module docstring."""

    def __init__(self, azimuth: float = 0.0, speed: float = DEFAULT_SPEED, now: float = 0.0,
                 cpm: bool = False) -> None:
        self._az = Axis(azimuth, 0.0, 360.0, speed, now)
        self._cpm = cpm
        self._last_sent = self._reading()
        self._buffer = b""

    @property
    def azimuth(self) -> float:
        return self._az.position

    @property
    def busy(self) -> bool:
        return self._az.moving or (self._cpm and self._reading() != self._last_sent)

    def receive(self, data: bytes, now: float) -> bytes:
        out = self.advance(now)
        self._buffer += data
        while b"\r" in self._buffer:
            frame, _, self._buffer = self._buffer.partition(b"\r")
            start = frame.rfind(STX)
            if start >= 0:
                out += self._obey(frame[start + 1 :], now)
        if len(self._buffer) > 64:
            self._buffer = b""
        return out

    def advance(self, now: float) -> bytes:
        self._az.advance(now)
        if self._cpm and self._reading() != self._last_sent:
            return self._position()
        return b""

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._az.place(azimuth, now)

    def _reading(self) -> int:
        return whole(self._az.position)

    def _position(self) -> bytes:
        self._last_sent = self._reading()
        return STX + b"A,?,%d,R\r" % self._last_sent

    def _obey(self, body: bytes, now: float) -> bytes:
        unit, command, value = body[:1], body[1:2], body[2:]
        if unit != b"A":
            return STX + unit + b",?,E,00003\r"
        if command == b"?" and not value:
            return self._position()
        if command == b"S" and not value:
            self._cpm = False
            return STX + b"A,S,R\r"
        if command == b"G" and value.isdigit():
            target = int(value)
            if target in (997, 999):
                self._az.stop(now)
                return STX + b"A,G,R\r"
            if target <= 360:
                self._az.go_to(target, now)
                return STX + b"A,G,R\r"
        return STX + b"A," + command + b",E,00001\r"


__all__ = ["ProsistelEmulator"]
