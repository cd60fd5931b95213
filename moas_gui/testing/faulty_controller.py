"""A controller that misbehaves on request, wrapped around any emulator.

For trying out how a driver copes, the way a station's wiring would test it:

- ``silent = True``: the controller's computer link is dead (it hears nothing
  and says nothing; a turn already under way runs on);
- ``noise = b"..."``: these bytes come out in front of every answer (a bad
  cable, a wrong baud rate, another device on the line);
- ``heard`` keeps every byte the computer sent, for checking what a driver wrote.
"""

from __future__ import annotations

from moas_gui.hw.rotators.controllers.base import ControllerEmulator


class FaultyController:
    """Wraps ``inner`` (any emulator); see the module docstring."""

    def __init__(self, inner: ControllerEmulator) -> None:
        self.inner = inner
        self.silent = False
        self.noise = b""
        self.heard = bytearray()

    @property
    def azimuth(self) -> float:
        return self.inner.azimuth

    @property
    def busy(self) -> bool:
        return self.inner.busy

    def receive(self, data: bytes, now: float) -> bytes:
        self.heard += data
        if self.silent:
            self.inner.advance(now)
            return b""
        answer = self.inner.receive(data, now)
        return self.noise + answer if answer else answer

    def advance(self, now: float) -> bytes:
        out = self.inner.advance(now)
        return b"" if self.silent else out

    def turn_by_hand(self, azimuth: float, now: float) -> None:
        self.inner.turn_by_hand(azimuth, now)


__all__ = ["FaultyController"]
