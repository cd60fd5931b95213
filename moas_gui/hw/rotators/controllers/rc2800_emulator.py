"""An M2 RC2800 controller as a pure model (``early=True``: RC2800P-A; else RC2800P-X).

Every command ends with CR (LF is ignored).  The unit keeps a *selected*
axis (``A`` azimuth, ``E`` elevation) and answers with its status line,
``A P= 123.0 S=9 ST`` + LF + CR: position right-aligned in six characters
with one decimal (Hamlib reads the number from the second character of that
field), ``S=`` the speed setting, ``ST`` standing or ``MV`` moving.

=============  ======================================  ==================
command        effect                                  answer
=============  ======================================  ==================
``A`` / ``E``  select the axis                         status line
``A200``       select and turn to 200                  status line
``200``        turn the selected axis to 200           nothing
(empty)                                                status line
``S``          stop the selected axis                  status line
other          -                                       ``A ERR=05``
=============  ======================================  ==================

The RC2800P-A also sends the status line of the azimuth by itself whenever
its reading changes, at most every :data:`REPORT_EVERY` seconds.
"""

from __future__ import annotations

import re

from .base import DEFAULT_SPEED, Axis

REPORT_EVERY = 0.1
"""Seconds between two status lines the RC2800P-A sends by itself."""

_NUMBER = re.compile(rb"-?\d+(?:\.\d*)?")


class RC2800Emulator:
    """An RC2800P-A or RC2800P-X with its rotators; see the module docstring."""

    def __init__(self, azimuth: float = 0.0, early: bool = True, speed: float = DEFAULT_SPEED,
                 now: float = 0.0) -> None:
        self._early = early
        self._axes = {b"A": Axis(azimuth, 0.0, 360.0, speed, now),
                      b"E": Axis(0.0, 0.0, 180.0, speed / 3, now)}
        self._selected = b"A"
        self._buffer = b""
        self._last_reported = self._reading(b"A")
        self._last_report_time = now

    @property
    def azimuth(self) -> float:
        return self._axes[b"A"].position

    @property
    def busy(self) -> bool:
        moving = any(axis.moving for axis in self._axes.values())
        return moving or (self._early and self._reading(b"A") != self._last_reported)

    def receive(self, data: bytes, now: float) -> bytes:
        out = self.advance(now)
        self._buffer += data.replace(b"\n", b"")
        while b"\r" in self._buffer:
            line, _, self._buffer = self._buffer.partition(b"\r")
            out += self._obey(line.strip().upper(), now)
        if len(self._buffer) > 64:
            self._buffer = b""
            out += self._selected + b" ERR=05\n\r"
        return out

    def advance(self, now: float) -> bytes:
        for axis in self._axes.values():
            axis.advance(now)
        if not self._early or now - self._last_report_time < REPORT_EVERY - 1e-9:
            return b""
        if self._reading(b"A") == self._last_reported:
            return b""
        return self._status(b"A", now)

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self._axes[b"A"].place(azimuth, now)

    def _reading(self, name: bytes) -> str:
        return f"{self._axes[name].position:6.1f}"

    def _status(self, name: bytes, now: float) -> bytes:
        axis = self._axes[name]
        reading = self._reading(name)
        if name == b"A":
            self._last_reported = reading
            self._last_report_time = now
        state = b"MV" if axis.moving else b"ST"
        return name + b" P=" + reading.encode("ascii") + b" S=9 " + state + b"\n\r"

    def _obey(self, line: bytes, now: float) -> bytes:
        if line == b"":
            return self._status(self._selected, now)
        if line[:1] in self._axes:
            self._selected = line[:1]
            rest = line[1:].strip()
            if rest and _NUMBER.fullmatch(rest):
                self._axes[self._selected].go_to(float(rest), now)
            elif rest:
                return self._selected + b" ERR=05\n\r"
            return self._status(self._selected, now)
        if _NUMBER.fullmatch(line):
            self._axes[self._selected].go_to(float(line), now)
            return b""
        if line == b"S":
            self._axes[self._selected].stop(now)
            return self._status(self._selected, now)
        return self._selected + b" ERR=05\n\r"


__all__ = ["REPORT_EVERY", "RC2800Emulator"]
