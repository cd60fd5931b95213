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


__all__ = ["PortSettings"]
