"""Serving an emulated box on a port a switch link can open.

On Linux and macOS :class:`PtyEndpoint` makes a new pseudo-terminal: the box
works the master side, the server opens the slave side (``path``) like any
serial port.  The emulator keeps the slave open itself too, so the server
may close and reopen the port as often as it likes.  On Windows (or for any
real serial port, such as one end of a null-modem pair) :class:`SerialEndpoint`
works a port by name through the program's serial layer.

:func:`make_link` gives the port a stable name (a symbolic link) that a
configuration can name.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

from ....serial import PortError, PortSettings
from .box import EmulatedBox

log = logging.getLogger(__name__)

MAX_BACKLOG = 64 * 1024
"""Bytes kept for a reader that is not reading; beyond that output is dropped,
as the real box drops status messages when its queue is full."""

DataCallback = Callable[[bytes], None]

EMULATED_BOX_PORT = PortSettings(baudrate=9600, write_timeout=1.0, exclusive=False,
                                 flush_on_open=False)
"""The box's end of a real port: 9600 baud 8N1, opened as it is."""


class Endpoint(Protocol):
    """The box's end of a port."""

    path: str

    def start(self, loop: asyncio.AbstractEventLoop, on_data: DataCallback) -> None: ...

    def write(self, data: bytes) -> None: ...

    def close(self) -> None: ...


def _open_pty() -> tuple[int, int, str]:
    """A new raw pseudo-terminal: its master, its slave and the slave's name."""
    if sys.platform == "win32":
        raise PortError("Windows has no pseudo-terminals: give a serial port "
                        "(one end of a COM pair) instead")
    import pty
    import tty

    master, slave = pty.openpty()
    tty.setraw(slave)
    os.set_blocking(master, False)
    return master, slave, os.ttyname(slave)


class PtyEndpoint:
    """A new pseudo-terminal (POSIX only)."""

    def __init__(self) -> None:
        self._master, self._slave, self.path = _open_pty()
        self._backlog = bytearray()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._on_data: DataCallback | None = None

    def start(self, loop: asyncio.AbstractEventLoop, on_data: DataCallback) -> None:
        self._loop = loop
        self._on_data = on_data
        loop.add_reader(self._master, self._readable)

    def _readable(self) -> None:
        try:
            data = os.read(self._master, 4096)
        except BlockingIOError:
            return
        except OSError as exc:
            log.warning("emulator: reading %s failed: %s", self.path, exc)
            return
        if data and self._on_data is not None:
            self._on_data(data)

    def write(self, data: bytes) -> None:
        if self._backlog:
            self._queue(data)
            return
        try:
            written = os.write(self._master, data)
        except BlockingIOError:
            written = 0
        if written < len(data):
            self._queue(data[written:])
            if self._loop is not None:
                self._loop.add_writer(self._master, self._drain)

    def _queue(self, data: bytes) -> None:
        if len(self._backlog) + len(data) > MAX_BACKLOG:
            log.warning("emulator: nobody reads %s; dropped %d bytes", self.path, len(data))
            return
        self._backlog += data

    def _drain(self) -> None:
        try:
            written = os.write(self._master, self._backlog)
        except BlockingIOError:
            return
        except OSError as exc:
            log.warning("emulator: writing %s failed: %s", self.path, exc)
            written = len(self._backlog)
        del self._backlog[:written]
        if not self._backlog and self._loop is not None:
            self._loop.remove_writer(self._master)

    def close(self) -> None:
        if self._loop is not None:
            self._loop.remove_reader(self._master)
            self._loop.remove_writer(self._master)
        for fd in (self._master, self._slave):
            with contextlib.suppress(OSError):
                os.close(fd)


class SerialEndpoint:
    """A serial port by name (``COM7``, ``/dev/ttyUSB1``), through the program's serial
    layer (:mod:`moas_gui.serial`), which reads it the way this system allows."""

    def __init__(self, port: str) -> None:
        from ....serial.port import SerialPort  # pyserial only for a real port

        self.path = port
        self._port = SerialPort(port, EMULATED_BOX_PORT)
        try:
            self._port.open_device(_running_loop())
        except PortError as exc:
            raise PortError(f"cannot open serial port {port}: {exc}") from exc

    def start(self, loop: asyncio.AbstractEventLoop, on_data: DataCallback) -> None:
        self._port.start(loop, on_data, self._lost)

    def _lost(self, why: str) -> None:
        log.warning("emulator: %s: %s", self.path, why)

    def write(self, data: bytes) -> None:
        self._port.write(data)

    def close(self) -> None:
        self._port.close()


def _running_loop() -> asyncio.AbstractEventLoop | None:
    try:
        return asyncio.get_running_loop()
    except RuntimeError:
        return None


def serve(box: EmulatedBox, endpoint: Endpoint, loop: asyncio.AbstractEventLoop) -> None:
    """Connect ``box`` to ``endpoint``: bytes both ways."""
    endpoint.start(loop, box.receive)
    box.attach(endpoint.write)


def make_link(target: str, link: Path) -> None:
    """Make ``link`` a symbolic link to ``target``, replacing an old link."""
    if link.exists() and not link.is_symlink():
        raise PortError(f"{link} exists and is not a symbolic link; not replacing it")
    temporary = link.with_name(f".{link.name}.{os.getpid()}")
    with contextlib.suppress(FileNotFoundError):
        temporary.unlink()
    os.symlink(target, temporary)
    os.replace(temporary, link)


def remove_link(link: Path, target: str) -> None:
    """Remove ``link`` if it still points at ``target``."""
    with contextlib.suppress(OSError):
        if link.is_symlink() and os.readlink(link) == target:
            link.unlink()


__all__ = [
    "MAX_BACKLOG",
    "Endpoint",
    "PtyEndpoint",
    "SerialEndpoint",
    "make_link",
    "remove_link",
    "serve",
]
