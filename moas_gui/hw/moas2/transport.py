"""The one seam between a switch link and the outside: a byte pipe.

:class:`SerialTransport` is a real port through pyserial (9600 baud, 8N1),
locked for this link alone where the system allows it (Windows always does);
on Linux and macOS it reads with the event loop's ``add_reader`` (which
qasync supports too), elsewhere with a small reader thread.
:class:`EmulatorTransport` is an emulated box in the same process: the fake
that ships with the package, used for the port name ``"emulator"`` and by
the tests.

A transport calls ``on_data`` with bytes as they arrive and ``on_lost`` (once)
with a reason when the port goes away; ``write`` is immediate.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import select
import sys
import threading
from collections.abc import Callable
from typing import Any, Protocol

import serial  # type: ignore[import-untyped]

from .emulator.box import EmulatedBox
from .errors import PortError

DataCallback = Callable[[bytes], None]
LostCallback = Callable[[str], None]

_SERIAL_ERRORS: tuple[type[BaseException], ...] = (serial.SerialException, OSError, ValueError)
if sys.platform != "win32":
    import termios

    # pyserial lets termios.error (not an OSError) through from a flush of a port whose
    # other end just went away (a pulled adapter, a pseudo-terminal closed)
    _SERIAL_ERRORS += (termios.error,)


_MAX_EMPTY_READS = 100
"""Empty reads in a row taken as a lost port even without a hang-up (no busy loop)."""


def _hung_up(fd: int) -> bool:
    """Whether the port behind ``fd`` hung up (or is in error), as poll tells it."""
    if sys.platform == "win32" or not hasattr(select, "poll"):
        return True  # no poll (Windows): the empty reads in a row tell instead
    poller = select.poll()
    poller.register(fd, select.POLLIN)
    gone = select.POLLHUP | select.POLLERR | select.POLLNVAL
    return any(flags & gone for _, flags in poller.poll(0))


class Transport(Protocol):
    """A byte pipe to one switch."""

    description: str

    def open(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        """Open it, or raise :class:`PortError` saying why not."""

    def write(self, data: bytes) -> None:
        """Write now, or raise :class:`PortError`."""

    def close(self) -> None:
        """Close it (quietly, whatever state it is in)."""


class SerialTransport:
    """A serial port by name, at 9600 baud 8N1."""

    def __init__(self, port: str, *, use_thread: bool | None = None) -> None:
        self.port = port
        self.description = port
        self._use_thread = sys.platform == "win32" if use_thread is None else use_thread
        self._serial: Any = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._on_data: DataCallback | None = None
        self._on_lost: LostCallback | None = None
        self._reading_fd: int | None = None
        self._empty_reads = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def open(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        self.close()
        loop = asyncio.get_running_loop()
        try:
            port = serial.Serial(
                self.port,
                9600,
                bytesize=serial.EIGHTBITS,
                parity=serial.PARITY_NONE,
                stopbits=serial.STOPBITS_ONE,
                timeout=0.1 if self._use_thread else 0,
                write_timeout=2,
                # one program, one link per port: a second opener would take half the
                # box's answers and drive it unchecked (POSIX: an advisory lock)
                exclusive=True if sys.platform != "win32" else None,
            )
            port.reset_input_buffer()
        except _SERIAL_ERRORS as exc:
            raise PortError(_why(exc)) from exc
        self._serial, self._loop = port, loop
        self._on_data, self._on_lost = on_data, on_lost
        self._stop.clear()
        if self._use_thread:
            self._thread = threading.Thread(
                target=self._pump, name=f"switch port {self.port}", daemon=True
            )
            self._thread.start()
        else:
            self._reading_fd = port.fileno()
            self._empty_reads = 0
            loop.add_reader(port.fileno(), self._readable)

    def _readable(self) -> None:
        fd = self._reading_fd
        if fd is None:
            return
        try:
            data = os.read(fd, 4096)
        except BlockingIOError:
            return
        except OSError as exc:
            self._lost(f"reading failed: {exc.strerror or exc}")
            return
        if not data:
            # A serial port read with VMIN 0 gives nothing both when it hung up and when
            # the loop woke it with nothing to read: only the first is a lost port.
            self._empty_reads += 1
            if _hung_up(fd) or self._empty_reads > _MAX_EMPTY_READS:
                self._lost("the port was closed at the other end")
            return
        self._empty_reads = 0
        if self._on_data is not None:
            self._on_data(data)

    def _pump(self) -> None:
        port, loop = self._serial, self._loop
        assert loop is not None
        while not self._stop.is_set():
            try:
                data = port.read(max(1, port.in_waiting))
            except _SERIAL_ERRORS as exc:
                if not self._stop.is_set():
                    loop.call_soon_threadsafe(self._lost, f"reading failed: {_why(exc)}")
                return
            if data and self._on_data is not None:
                loop.call_soon_threadsafe(self._on_data, data)

    def _lost(self, reason: str) -> None:
        callback, self._on_lost = self._on_lost, None
        self._stop_reading()
        if callback is not None:
            callback(reason)

    def write(self, data: bytes) -> None:
        if self._serial is None:
            raise PortError(f"{self.port} is not open")
        try:
            self._serial.write(data)
        except _SERIAL_ERRORS as exc:
            raise PortError(f"writing to {self.port} failed: {_why(exc)}") from exc

    def _stop_reading(self) -> None:
        if self._reading_fd is not None and self._loop is not None:
            with contextlib.suppress(Exception):
                self._loop.remove_reader(self._reading_fd)
        self._reading_fd = None
        self._stop.set()

    def close(self) -> None:
        self._stop_reading()
        self._on_lost = None
        if self._thread is not None and self._thread is not threading.current_thread():
            # Let the reader leave its read (0.1 s timeout) before the port closes.
            with contextlib.suppress(*_SERIAL_ERRORS, AttributeError):
                self._serial.cancel_read()
            self._thread.join(timeout=1)
        self._thread = None
        if self._serial is not None:
            with contextlib.suppress(*_SERIAL_ERRORS):
                self._serial.close()
            self._serial = None


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


def _why(exc: BaseException) -> str:
    """The useful part of a pyserial or OS error."""
    if isinstance(exc, OSError) and not isinstance(exc, serial.SerialException) and exc.strerror:
        return str(exc.strerror)
    return str(exc)


__all__ = ["EmulatorTransport", "SerialTransport", "Transport"]
