"""The one seam between a rotator driver and a serial port.

:func:`open_serial` opens a port with pyserial (``COM14``, ``/dev/ttyUSB0``,
or any pyserial URL such as ``socket://host:port`` for a serial device
server) and hands every byte it receives to a callback on the event loop.
Where the port has a file descriptor and the loop can watch it (Linux, macOS)
no thread is used; otherwise (Windows, URLs) one reader thread per port does
the waiting.  A port that fails (unplugged adapter, closed pseudo-terminal)
is reported once through ``on_lost``.

A port name may end in ``@<baud>`` (``COM14@4800``) to override the model's
usual speed, for units whose speed is set by DIP switches or a menu.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import sys
import threading
from collections.abc import Awaitable, Callable
from typing import Protocol, TypeVar

import serial  # type: ignore[import-untyped]

from moas_gui.errors import HardwareError
from moas_gui.hw.rotators.controllers.base import SerialSettings

log = logging.getLogger(__name__)

T = TypeVar("T")

WRITE_TIMEOUT = 0.5
"""Seconds a write may take before the port counts as failed."""


class PortError(HardwareError):
    """A serial port could not be opened, read or written."""


class Link(Protocol):
    """What a driver needs from an open port."""

    name: str

    def write(self, data: bytes) -> None:
        """Writes all of ``data``; raises :class:`PortError` when the port failed."""
        ...

    def close(self) -> None:
        """Closes the port (no more callbacks afterwards)."""
        ...


Opener = Callable[[str, SerialSettings, Callable[[bytes], None], Callable[[Exception], None]],
                  Awaitable[Link]]
"""``await opener(port, settings, on_data, on_lost)``: the seam drivers are given."""


def split_port(port: str) -> tuple[str, int | None]:
    """``("COM14", 4800)`` for ``"COM14@4800"``; ``(port, None)`` without a speed."""
    name, sep, speed = port.rpartition("@")
    if sep and name and speed.isdigit() and int(speed) > 0:
        return name, int(speed)
    return port, None


class SerialLink:
    """An open pyserial port delivering bytes to ``on_data`` on the event loop."""

    def __init__(self, name: str, port: serial.SerialBase, on_data: Callable[[bytes], None],
                 on_lost: Callable[[Exception], None], use_thread: bool) -> None:
        self.name = name
        self._port = port
        self._on_data = on_data
        self._on_lost = on_lost
        self._loop = asyncio.get_running_loop()
        self._closed = False
        self._lost = False
        self._fd: int | None = None
        self._thread: threading.Thread | None = None
        if use_thread:
            self._thread = threading.Thread(target=self._read_in_thread, daemon=True,
                                            name=f"serial-{name}")
            self._thread.start()
        else:
            self._fd = port.fileno()
            self._loop.add_reader(self._fd, self._read_ready)

    def write(self, data: bytes) -> None:
        if self._closed or self._lost:
            raise PortError(f"port {self.name} is closed")
        try:
            self._port.write(data)
        except (serial.SerialException, OSError, ValueError) as error:
            self._fail(error)
            raise PortError(f"cannot write to {self.name}: {error}") from error

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        if self._fd is not None:
            with contextlib.suppress(Exception):
                self._loop.remove_reader(self._fd)
        if self._thread is not None:
            with contextlib.suppress(Exception):
                self._port.cancel_read()
        with contextlib.suppress(Exception):
            self._port.close()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2)

    # -- reading ---------------------------------------------------------------------------

    def _read_ready(self) -> None:
        try:
            data = self._port.read(self._port.in_waiting or 1)
        except (serial.SerialException, OSError, TypeError, ValueError) as error:
            self._fail(error)
            return
        if data:
            self._on_data(bytes(data))

    def _read_in_thread(self) -> None:
        while not self._closed:
            try:
                data = self._port.read(self._port.in_waiting or 1)
            except Exception as error:  # noqa: BLE001 - any failure ends this port
                if not self._closed:
                    self._loop.call_soon_threadsafe(self._fail, error)
                return
            if data and not self._closed:
                self._loop.call_soon_threadsafe(self._deliver, bytes(data))

    def _deliver(self, data: bytes) -> None:
        if not self._closed:
            self._on_data(data)

    def _fail(self, error: Exception) -> None:
        if self._lost or self._closed:
            return
        self._lost = True
        if self._fd is not None:
            with contextlib.suppress(Exception):
                self._loop.remove_reader(self._fd)
        self._on_lost(error)


async def open_serial(port: str, settings: SerialSettings, on_data: Callable[[bytes], None],
                      on_lost: Callable[[Exception], None], *,
                      use_thread: bool | None = None) -> SerialLink:
    """Opens ``port`` (see the module docstring); raises :class:`PortError` saying why not."""
    name, speed = split_port(port)

    def _open() -> serial.SerialBase:
        return serial.serial_for_url(
            name,
            baudrate=speed or settings.baudrate,
            bytesize=settings.bytesize,
            parity=settings.parity,
            stopbits=settings.stopbits,
            timeout=0.2 if thread else 0,
            write_timeout=WRITE_TIMEOUT,
            xonxoff=False,
            rtscts=False,
            dsrdtr=False,
        )

    loop = asyncio.get_running_loop()
    thread = use_thread if use_thread is not None else not _watchable(name, loop)
    try:
        handle = await _in_daemon_thread(_open)
    except (serial.SerialException, OSError, ValueError) as error:
        raise PortError(f"cannot open {name}: {error}") from error
    try:
        return SerialLink(port, handle, on_data, on_lost, thread)
    except Exception as error:
        handle.close()
        raise PortError(f"cannot watch {name}: {error}") from error


async def _in_daemon_thread(work: Callable[[], T]) -> T:
    """Runs ``work`` in a thread of its own, so that an open that hangs (a confused USB
    driver) can neither block the event loop nor hold up the program's exit."""
    loop = asyncio.get_running_loop()
    future: asyncio.Future[T] = loop.create_future()

    def settle(result: T | None, error: BaseException | None) -> None:
        if future.done():
            close = getattr(result, "close", None)
            if callable(close):
                close()  # nobody waits for it any more
            return
        if error is not None:
            future.set_exception(error)
        else:
            future.set_result(result)  # type: ignore[arg-type]

    def run() -> None:
        try:
            result = work()
        except BaseException as error:  # noqa: BLE001 - handed to the waiting coroutine
            loop.call_soon_threadsafe(settle, None, error)
        else:
            loop.call_soon_threadsafe(settle, result, None)

    threading.Thread(target=run, daemon=True, name="serial-open").start()
    return await future


def _watchable(name: str, loop: asyncio.AbstractEventLoop) -> bool:
    """True when a port of this name gives a descriptor this loop can watch."""
    if "://" in name or sys.platform == "win32":
        return False
    return hasattr(loop, "add_reader") and not isinstance(
        loop, getattr(asyncio, "ProactorEventLoop", ()))


__all__ = ["Link", "Opener", "PortError", "SerialLink", "open_serial", "split_port"]
