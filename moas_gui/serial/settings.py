"""How a serial port is opened (no pyserial needed to say it)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class PortSettings:
    """How a port is opened.  The defaults are the MOAS II's: 9600 baud 8N1."""

    baudrate: int = 9600
    bytesize: int = 8
    parity: str = "N"
    stopbits: float = 1
    write_timeout: float = 2.0
    """Seconds a write may wait for room before it counts as failed."""
    exclusive: bool = True
    """For this program alone: a second opener is refused (POSIX: an advisory lock;
    Windows never shares a COM port anyway)."""
    flush_on_open: bool = True
    """Drop whatever the port held before it was opened."""
    urls: bool = False
    """Also accept pyserial URLs (``socket://host:port`` for a serial device server)."""
    dtr: bool | None = None
    """The DTR line once the port is open.  None: as the system's open leaves it (raised on
    POSIX and Windows alike; the program never drops and raises it again, so a device
    that resets on a DTR pulse is not reset by an open).  True or False: set before the
    port opens (on POSIX the system's open still raises it for an instant before it is
    dropped).  A pseudo-terminal has no such line and ignores it."""
    rts: bool | None = None
    """The RTS line once the port is open, as :attr:`dtr`."""


__all__ = ["PortSettings"]
