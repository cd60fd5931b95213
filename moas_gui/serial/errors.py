"""The one error of the serial layer: a port that cannot be opened, read or written.

Every serial port of the program (a switch, a rotator controller, a logger's
OTRSP port, the emulator's end of a port) raises this same :class:`PortError`,
so a caller catches one class whichever port it holds.  It is an ``OSError``
too: code that already treats operating-system failures as "the port is gone"
catches it unchanged.
"""

from __future__ import annotations

from ..errors import HardwareError


class PortError(HardwareError, OSError):
    """A serial port that cannot be opened, read or written, or that vanished."""


__all__ = ["PortError"]
