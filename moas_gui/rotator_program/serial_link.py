"""The one seam between a rotator driver and a serial port.

:func:`open_serial` opens a port through the program's serial layer
(:mod:`moas_gui.serial`): ``COM14``, ``/dev/ttyUSB0``, or any pyserial URL such
as ``socket://host:port`` for a serial device server.  Every byte it receives
goes to a callback on the event loop (the layer decides, per system, whether
the loop watches the port or a reader thread waits on it).  The system's open
runs in a thread of its own, so that one that hangs cannot block the program.
A port that fails (unplugged adapter, closed pseudo-terminal) is reported once
through ``on_lost``.

A port name may end in ``@<baud>`` (``COM14@4800``) to override the model's
usual speed, for units whose speed is set by DIP switches or a menu.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from typing import Protocol

from moas_gui.hw.rotators.controllers.base import SerialSettings
from moas_gui.serial import PortError
from moas_gui.serial.port import PortSettings, SerialPort

WRITE_TIMEOUT = 0.5
"""Seconds a write may take before the port counts as failed."""


class ControllerPort(Protocol):
    """What a rotator driver needs from an open controller port."""

    name: str

    def write(self, data: bytes) -> None:
        """Writes all of ``data``; raises :class:`PortError` when the port failed."""
        ...

    def close(self) -> None:
        """Closes the port (no more callbacks afterwards)."""
        ...


Opener = Callable[[str, SerialSettings, Callable[[bytes], None], Callable[[Exception], None]],
                  Awaitable[ControllerPort]]
"""``await opener(port, settings, on_data, on_lost)``: the seam drivers are given."""


def split_port(port: str) -> tuple[str, int | None]:
    """``("COM14", 4800)`` for ``"COM14@4800"``; ``(port, None)`` without a speed."""
    name, sep, speed = port.rpartition("@")
    if sep and name and speed.isdigit() and int(speed) > 0:
        return name, int(speed)
    return port, None


def controller_settings(settings: SerialSettings, speed: int | None = None) -> PortSettings:
    """How a controller's port is opened: the model's speed (or ``speed``), no lock (the
    program itself refuses a second rotator on one port), nothing flushed, URLs allowed."""
    return PortSettings(baudrate=speed or settings.baudrate, bytesize=settings.bytesize,
                        parity=settings.parity, stopbits=settings.stopbits,
                        write_timeout=WRITE_TIMEOUT, exclusive=False, flush_on_open=False,
                        urls=True)


async def open_serial(port: str, settings: SerialSettings, on_data: Callable[[bytes], None],
                      on_lost: Callable[[Exception], None], *,
                      use_thread: bool | None = None) -> SerialPort:
    """Opens ``port`` (see the module docstring); raises :class:`PortError` saying why not.
    ``on_lost`` is given a :class:`PortError` saying what happened."""
    name, speed = split_port(port)
    opened = SerialPort(port, controller_settings(settings, speed), device=name,
                        use_thread=use_thread)

    def lost(why: str) -> None:
        on_lost(PortError(why))

    try:
        await opened.open_off_loop(on_data, lost)
    except PortError as error:
        raise PortError(f"cannot open {name}: {error}") from error
    return opened


__all__ = ["ControllerPort", "Opener", "PortError", "controller_settings", "open_serial",
           "split_port"]
