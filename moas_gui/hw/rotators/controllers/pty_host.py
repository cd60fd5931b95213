"""Serves emulated controllers on pseudo-terminals, any number from one thread.

Each emulator gets a new pseudo-terminal; programs open the *slave* side
(``/dev/pts/N``) as they would a serial port, and the host plays the
controller on the master side: bytes in go to the emulator's ``receive``,
its answers go back, and while something moves (``busy``) the host calls
``advance`` every :data:`TICK` seconds so that unsolicited reports come out
on time.  The host keeps the slave open itself, so clients may come and go;
``remove`` closes both sides, which a client sees as a vanished port.

Time is whatever ``clock`` says (``time.monotonic`` by default; a test's fake
clock's ``now``, with :meth:`EmulatorHost.catch_up` after moving it on).
``ServedPort.received`` and ``sent`` count the bytes each way.

POSIX only (pseudo-terminals); the program's driver itself does not need it.
"""

from __future__ import annotations

import errno
import logging
import os
import selectors
import sys
import threading
import time
import tty
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Self, TypeVar

from .base import ControllerEmulator

log = logging.getLogger(__name__)

TICK = 0.02
"""Seconds between ``advance`` calls while an emulator is busy."""
IDLE_WAIT = 0.5

R = TypeVar("R")


@dataclass(eq=False, slots=True)
class ServedPort:
    """One emulator on its pseudo-terminal."""

    path: str
    """The slave side: give this to the program (or to ``rotctl -r``)."""
    emulator: ControllerEmulator
    link: str | None = None
    master: int = field(default=-1, repr=False)
    slave: int = field(default=-1, repr=False)
    received: int = 0
    sent: int = 0


def _wake_pipe() -> tuple[int, int]:
    """A non-blocking pipe that wakes the host's selector."""
    if sys.platform == "win32":
        raise OSError("emulated controllers need pseudo-terminals: not on Windows "
                      "(use a virtual COM port pair and the emulator models from Python)")
    read, write = os.pipe()
    os.set_blocking(read, False)
    os.set_blocking(write, False)
    return read, write


class EmulatorHost:
    """A thread that serves emulators on pseudo-terminals; see the module docstring."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self.clock = clock
        self._lock = threading.RLock()
        self._ports: dict[int, ServedPort] = {}
        self._selector = selectors.DefaultSelector()
        self._wake_r, self._wake_w = _wake_pipe()
        self._selector.register(self._wake_r, selectors.EVENT_READ)
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name="emulator-host", daemon=True)
        self._started = False

    # -- public ----------------------------------------------------------------------------

    def start(self) -> Self:
        if not self._started:
            self._started = True
            self._thread.start()
        return self

    def add(self, emulator: ControllerEmulator, link: str | None = None) -> ServedPort:
        """Serves ``emulator`` on a new pseudo-terminal (symlinked at ``link`` if given)."""
        if sys.platform == "win32":
            raise OSError("pseudo-terminals are not on Windows")
        master, slave = os.openpty()
        tty.setraw(slave)
        tty.setraw(master)
        os.set_blocking(master, False)
        path = os.ttyname(slave)
        if link is not None:
            if os.path.islink(link):
                os.unlink(link)
            os.symlink(path, link)
        port = ServedPort(path, emulator, link, master, slave)
        with self._lock:
            self._ports[master] = port
            self._selector.register(master, selectors.EVENT_READ)
        self._wake()
        log.info("emulating %s on %s%s", type(emulator).__name__, path,
                 f" (linked at {link})" if link else "")
        return port

    def remove(self, port: ServedPort) -> None:
        """Takes the port away, as if its USB adapter were pulled out."""
        with self._lock:
            if self._ports.pop(port.master, None) is None:
                return
            self._selector.unregister(port.master)
            for fd in (port.master, port.slave):
                try:
                    os.close(fd)
                except OSError:
                    pass
            if port.link is not None and os.path.islink(port.link):
                os.unlink(port.link)
        self._wake()

    def call(self, port: ServedPort, action: Callable[[ControllerEmulator, float], R]) -> R:
        """Runs ``action(emulator, now)`` safely from another thread, sending any output."""
        with self._lock:
            now = self.clock()
            result = action(port.emulator, now)
            self._send(port, port.emulator.advance(now))
        self._wake()
        return result

    def find(self, name: str) -> ServedPort | None:
        """The port served at ``name`` (its pseudo-terminal or its link), if any."""
        with self._lock:
            return next((p for p in self._ports.values() if name in (p.path, p.link)), None)

    def traffic(self, port: ServedPort) -> tuple[int, int] | None:
        """``(received, sent)`` bytes of ``port``, read together; None once removed."""
        with self._lock:
            if self._ports.get(port.master) is not port:
                return None
            return port.received, port.sent

    def catch_up(self) -> None:
        """Lets every emulator see the time now and sends what it says by itself, at
        once rather than at the next tick (for a clock a test has just moved on)."""
        with self._lock:
            now = self.clock()
            for port in list(self._ports.values()):
                self._send(port, port.emulator.advance(now))
        self._wake()

    def close(self) -> None:
        with self._lock:
            ports = list(self._ports.values())
        for port in ports:
            self.remove(port)
        self._stopping = True
        self._wake()
        if self._started:
            self._thread.join(timeout=5)
        self._selector.close()
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self) -> Self:
        return self.start()

    def __exit__(self, *_: object) -> None:
        self.close()

    # -- the thread ------------------------------------------------------------------------

    def _wake(self) -> None:
        try:
            os.write(self._wake_w, b"x")
        except OSError:
            pass

    def _run(self) -> None:
        while not self._stopping:
            with self._lock:
                busy = any(p.emulator.busy for p in self._ports.values())
            try:
                ready = self._selector.select(TICK if busy else IDLE_WAIT)
            except (OSError, ValueError):
                if self._stopping:
                    return
                raise
            with self._lock:
                now = self.clock()
                for key, _ in ready:
                    if key.fd == self._wake_r:
                        try:
                            os.read(self._wake_r, 512)
                        except OSError:
                            pass
                        continue
                    port = self._ports.get(key.fd)
                    if port is not None:
                        self._serve(port, now)
                for port in list(self._ports.values()):
                    if port.emulator.busy:
                        self._send(port, port.emulator.advance(now))

    def _serve(self, port: ServedPort, now: float) -> None:
        try:
            data = os.read(port.master, 4096)
        except BlockingIOError:
            return
        except OSError as error:
            log.warning("emulator on %s: read failed: %s", port.path, error)
            return
        port.received += len(data)
        self._send(port, port.emulator.receive(data, now))

    def _send(self, port: ServedPort, data: bytes) -> None:
        if not data:
            return
        try:
            written = os.write(port.master, data)
            port.sent += written
        except OSError as error:
            if error.errno not in (errno.EAGAIN, errno.EIO):
                log.warning("emulator on %s: write failed: %s", port.path, error)
            # like a serial line with nobody listening: the bytes are lost


__all__ = ["IDLE_WAIT", "TICK", "EmulatorHost", "ServedPort"]
