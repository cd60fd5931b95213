"""The one seam between a switch link and the outside: a byte pipe.

:class:`SerialTransport` is a real port (9600 baud, 8N1) through the
program's serial layer (:mod:`moas_gui.serial`), which keeps it for this link
alone where the system allows it (Windows always does) and reads it without a
thread where the system allows that.  :class:`EmulatorTransport` is an
emulated box in the same process: the fake that ships with the package, used
for the port name ``"emulator"`` and by the tests.

A transport calls ``on_data`` with bytes as they arrive and ``on_lost`` (once)
with a reason when the port goes away; ``write`` is immediate.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from dataclasses import replace
from typing import TYPE_CHECKING, Protocol

from ...clock import Clock
from ...serial import PortError
from ...serial.port import PortSettings, SerialPort

if TYPE_CHECKING:  # the built-in emulator is loaded when a switch's port names it
    from .emulator.box import EmulatedBox

DataCallback = Callable[[bytes], None]
LostCallback = Callable[[str], None]

SWITCH_PORT = PortSettings(baudrate=9600, write_timeout=2.0, exclusive=True, flush_on_open=True)
"""A MOAS II's port: 9600 baud 8N1, for one link alone (a second opener would take half
the box's answers and drive it unchecked), what it held before the open dropped."""


def switch_port(*, dtr: bool | None = None, rts: bool | None = None) -> PortSettings:
    """:data:`SWITCH_PORT` with its DTR and RTS lines set as asked (None: untouched)."""
    return replace(SWITCH_PORT, dtr=dtr, rts=rts)


class Transport(Protocol):
    """A byte pipe to one switch."""

    description: str

    def open(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        """Open it, or raise :class:`PortError` saying why not."""

    def write(self, data: bytes) -> None:
        """Write now, or raise :class:`PortError`."""

    def close(self) -> None:
        """Close it (quietly, whatever state it is in)."""


class SerialTransport(SerialPort):
    """A serial port by name, at 9600 baud 8N1 (:data:`SWITCH_PORT`; ``settings`` may set
    its DTR and RTS lines, :func:`switch_port`)."""

    def __init__(self, port: str, *, use_thread: bool | None = None,
                 settings: PortSettings = SWITCH_PORT) -> None:
        super().__init__(port, settings, use_thread=use_thread)
        self.port = port


class EmulatorTransport:
    """An emulated box in this process."""

    def __init__(self, box: EmulatedBox) -> None:
        self.box = box
        self.description = "the built-in emulator"
        self._open = False

    def open(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        loop = asyncio.get_running_loop()

        def deliver(data: bytes) -> None:
            loop.call_soon(on_data, data)

        self.box.attach(deliver)
        self._open = True

    def write(self, data: bytes) -> None:
        if not self._open:
            raise PortError("the built-in emulator is not open")
        self.box.receive(data)

    def close(self) -> None:
        if self._open:
            self.box.attach(None)
        self._open = False


EMULATOR_PORT = "emulator"
"""The port name that means "the built-in emulator"."""


def transport_for(port: str, echo: int | None, clock: Clock,
                  settings: PortSettings = SWITCH_PORT) -> Transport:
    """The transport a port name stands for: the built-in emulator (an emulated box of
    unit ``echo``, on ``clock``) for :data:`EMULATOR_PORT`, else that serial port."""
    if port == EMULATOR_PORT:
        from .emulator.box import EmulatedBox
        from .emulator.model import EmulatorModel

        return EmulatorTransport(EmulatedBox(EmulatorModel(unit_id=echo or 0), clock=clock))
    return SerialTransport(port, settings=settings)


__all__ = [
    "EMULATOR_PORT",
    "SWITCH_PORT",
    "EmulatorTransport",
    "SerialTransport",
    "Transport",
    "switch_port",
    "transport_for",
]
