"""A SPID Rot1Prog or Rot2Prog controller as a pure model.

It reads 13-byte frames (``W`` ... ``0x20``); a frame that does not end in
0x20 is dropped from its ``W`` and the search starts again at the next
``W``.  Status (0x1F) and stop (0x0F) are answered with the position frame
(5 bytes Rot1Prog, 12 bytes Rot2Prog, digits as binary values); set (0x2F)
is never answered.  A Rot2Prog decodes a set frame with its *own* pulses per
degree and ignores the PH/PV bytes in the frame, as the real unit does.
Answers are rounded to whole degrees (Rot1Prog) or tenths (Rot2Prog).
"""

from __future__ import annotations

from .base import DEFAULT_SPEED, Axis, whole

FRAME = 13
ELEVATION_SPEED = 2.0


def _ascii_number(digits: bytes) -> int | None:
    return int(digits) if digits.isdigit() else None


def _binary_digits(value: float, tenths: bool) -> bytes:
    """``360 + value`` as 3 (or 4, with tenths) binary digit bytes."""
    if tenths:
        scaled = whole((360 + value) * 10)
        return bytes((scaled // 1000, scaled // 100 % 10, scaled // 10 % 10, scaled % 10))
    number = whole(360 + value)
    return bytes((number // 100, number // 10 % 10, number % 10))


class SpidEmulator:
    """A Rot1Prog (``rot2=False``) or Rot2Prog with ``ph``/``pv`` pulses per degree."""

    def __init__(self, azimuth: float = 0.0, rot2: bool = False, ph: int = 2, pv: int = 2,
                 speed: float = DEFAULT_SPEED, now: float = 0.0) -> None:
        self._rot2 = rot2
        self._ph = ph
        self._pv = pv
        self._az = Axis(azimuth, -180.0, 540.0, speed, now)
        self._el = Axis(0.0, -20.0, 210.0, ELEVATION_SPEED, now)
        self._buffer = b""

    @property
    def azimuth(self) -> float:
        return self._az.position

    @property
    def elevation(self) -> float:
        return self._el.position

    @property
    def busy(self) -> bool:
        return self._az.moving or self._el.moving

    def receive(self, data: bytes, now: float) -> bytes:
        self.advance(now)
        self._buffer += data
        out = b""
        while True:
            start = self._buffer.find(b"W")
            if start < 0:
                self._buffer = b""
                break
            self._buffer = self._buffer[start:]
            if len(self._buffer) < FRAME:
                break
            frame = self._buffer[:FRAME]
            if frame[-1] != 0x20:
                self._buffer = self._buffer[1:]
                continue
            self._buffer = self._buffer[FRAME:]
            out += self._obey(frame, now)
        return out

    def advance(self, now: float) -> bytes:
        self._az.advance(now)
        self._el.advance(now)
        return b""

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._az.place(azimuth, now)

    def _answer(self) -> bytes:
        if not self._rot2:
            return b"W" + _binary_digits(self._az.position, False) + b"\x20"
        return (b"W" + _binary_digits(self._az.position, True) + bytes((self._ph,))
                + _binary_digits(self._el.position, True) + bytes((self._pv,)) + b"\x20")

    def _obey(self, frame: bytes, now: float) -> bytes:
        command = frame[11]
        if command == 0x1F:
            return self._answer()
        if command == 0x0F:
            self._az.stop(now)
            self._el.stop(now)
            return self._answer()
        if command == 0x2F:
            self._set(frame, now)
        return b""

    def _set(self, frame: bytes, now: float) -> None:
        if not self._rot2:
            h = _ascii_number(frame[1:4])
            if h is not None:
                self._az.go_to(h - 360, now)
            return
        h = _ascii_number(frame[1:5])
        v = _ascii_number(frame[6:10])
        if h is None or v is None:
            return
        self._az.go_to(h / self._ph - 360, now)
        self._el.go_to(v / self._pv - 360, now)


__all__ = ["SpidEmulator"]
