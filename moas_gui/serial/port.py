"""One serial port: opened for one program, read on the event loop, written at once.

A :class:`SerialPort` is opened with :meth:`SerialPort.open` (or, where an open
that hangs must not hold up the event loop, :meth:`SerialPort.open_off_loop`).
From then on ``on_data`` is called on the event loop with the bytes as they
arrive, and ``on_lost`` once, with a sentence, when the port goes away while
it is read (a pulled adapter, a pseudo-terminal closed at the other end).  A
write that fails raises :class:`PortError`; whoever wrote decides what follows.
After :meth:`SerialPort.close` no callback comes any more.

The emulator, which must refuse a port before its event loop serves it, opens
in two steps: :meth:`SerialPort.open_device`, then :meth:`SerialPort.start`.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import select
import selectors
import sys
import threading
from collections.abc import Callable
from typing import Any

import serial  # type: ignore[import-untyped]

from .errors import PortError
from .settings import PortSettings

DataCallback = Callable[[bytes], None]
"""Called on the event loop with bytes as they arrive."""
LostCallback = Callable[[str], None]
"""Called on the event loop, once, with why the port went away."""

SERIAL_ERRORS: tuple[type[BaseException], ...] = (serial.SerialException, OSError, ValueError)
"""What pyserial and the system raise for a port that is missing, busy or gone."""
if sys.platform != "win32":
    import termios

    # pyserial lets termios.error (not an OSError) through from a flush or a setting of
    # a port whose other end just went away (a pulled adapter, a closed pseudo-terminal)
    SERIAL_ERRORS += (termios.error,)

THREAD_READ_TIMEOUT = 0.1
"""Seconds a reader thread's read waits at most, so that it sees a close soon."""

MAX_EMPTY_READS = 100
"""Empty reads in a row taken as a lost port even without a hang-up (no busy loop)."""

READ_SIZE = 4096

HUNG_UP = "the port was closed at the other end"
"""What ``on_lost`` is told when the system says the port hung up."""


def reason(exc: BaseException) -> str:
    """The useful part of a pyserial or system error."""
    if isinstance(exc, OSError) and not isinstance(exc, serial.SerialException) and exc.strerror:
        return str(exc.strerror)
    return str(exc)


# -- what differs between systems, decided once ----------------------------------------------


def reads_by_thread(device: str, loop: asyncio.AbstractEventLoop) -> bool:
    """Whether ``device`` is waited for by a reader thread rather than by ``loop``.

    The loop watches the descriptor wherever it can (no thread, no hand-over):
    Linux, macOS, the BSDs, with asyncio's own loop or qasync's.  A thread waits
    instead on Windows (a COM port is a handle, not a socket: neither the
    proactor nor ``select()`` watch it), for a pyserial URL (nothing to watch),
    for a loop without ``add_reader``, and on macOS for a loop built on
    ``poll()``, which does not work on devices there."""
    if sys.platform == "win32":
        return True
    if "://" in device:
        return True
    if not hasattr(loop, "add_reader") or isinstance(
            loop, getattr(asyncio, "ProactorEventLoop", ())):
        return True
    selector = getattr(loop, "_selector", None)
    return sys.platform == "darwin" and isinstance(selector, selectors.PollSelector)


POLL_SEES_HANG_UPS = sys.platform not in ("win32", "darwin") and hasattr(select, "poll")
"""Whether this system's ``poll()`` tells a hung-up device (see :func:`hung_up`)."""


def hung_up(fd: int) -> bool:
    """Whether the port behind ``fd`` hung up, as far as the system can tell at once.

    ``poll()`` tells on Linux and the BSDs.  On macOS it refuses devices (every
    answer would be "gone"), and Windows has none: there only the run of empty
    reads (:data:`MAX_EMPTY_READS`) tells."""
    if sys.platform in ("win32", "darwin") or not hasattr(select, "poll"):
        return False
    poller = select.poll()
    poller.register(fd, select.POLLIN)
    gone = select.POLLHUP | select.POLLERR | select.POLLNVAL
    return any(flags & gone for _, flags in poller.poll(0))


def _exclusive(settings: PortSettings) -> bool | None:
    """pyserial's ``exclusive``: POSIX takes an advisory lock; on Windows it must be None
    (every COM port is exclusive there)."""
    if sys.platform == "win32" or not settings.exclusive:
        return None
    return True


# -- the port ------------------------------------------------------------------------------


class SerialPort:
    """A serial port by name (``COM14``, ``/dev/ttyUSB0``, a pseudo-terminal's path).

    ``name`` is how messages call it; ``device`` what is opened (``name`` unless
    given, e.g. without a ``@<baud>`` suffix).  ``use_thread`` forces the way of
    reading (the tests try both); None leaves it to :func:`reads_by_thread`."""

    def __init__(self, name: str, settings: PortSettings | None = None, *,
                 device: str | None = None, use_thread: bool | None = None) -> None:
        self.name = name
        self.description = name
        self.device = device if device is not None else name
        self.settings = settings if settings is not None else PortSettings()
        self._use_thread = use_thread
        self._serial: Any = None
        self._fd: int | None = None
        """The descriptor written to directly (and watched, when the loop reads)."""
        self._by_thread = False
        self._loop: asyncio.AbstractEventLoop | None = None
        self._on_data: DataCallback | None = None
        self._on_lost: LostCallback | None = None
        self._watching = False
        self._gone = False
        """The port was lost while read: writes are refused until it is closed."""
        self._empty_reads = 0
        self._generation = 0
        """Counts opens: what a reader thread hands over for an earlier one is dropped."""
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def is_open(self) -> bool:
        return self._serial is not None

    @property
    def by_thread(self) -> bool:
        """Whether the open port is read by a thread (else the event loop watches it)."""
        return self._by_thread

    # -- opening -------------------------------------------------------------------------

    def open(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        """Open the port and read it on the running loop; raises :class:`PortError`
        saying why not (the bare reason: the caller says which port)."""
        self.close()
        loop = asyncio.get_running_loop()
        self.open_device(loop)
        self.start(loop, on_data, on_lost)

    async def open_off_loop(self, on_data: DataCallback, on_lost: LostCallback) -> None:
        """:meth:`open`, with the system's open in a thread of its own, so that one that
        hangs (a confused USB driver) can neither block the event loop nor hold up the
        program's exit.  A port that opens after its opener stopped waiting is closed."""
        self.close()
        loop = asyncio.get_running_loop()
        done: asyncio.Future[None] = loop.create_future()

        def settle(error: BaseException | None) -> None:
            if done.done():  # nobody waits for it any more
                self.close()
            elif error is not None:
                done.set_exception(error)
            else:
                done.set_result(None)

        def run() -> None:
            error: BaseException | None = None
            try:
                self.open_device(loop)
            except BaseException as failed:  # noqa: BLE001 - handed to the waiting coroutine
                error = failed
            with contextlib.suppress(RuntimeError):  # the loop is closed: the program ends
                loop.call_soon_threadsafe(settle, error)

        threading.Thread(target=run, daemon=True, name=f"open {self.name}").start()
        await done
        self.start(loop, on_data, on_lost)

    def open_device(self, loop: asyncio.AbstractEventLoop | None = None) -> None:
        """The first step of :meth:`open`: the port itself, set up for the way it will
        be read (by ``loop``, or by a thread when there is none or it cannot watch it);
        raises :class:`PortError` with the reason."""
        self._by_thread = self._use_thread if self._use_thread is not None else (
            loop is None or reads_by_thread(self.device, loop))
        s = self.settings
        options: dict[str, Any] = {
            "baudrate": s.baudrate,
            "bytesize": s.bytesize,
            "parity": s.parity,
            "stopbits": s.stopbits,
            "timeout": THREAD_READ_TIMEOUT if self._by_thread else 0,
            "write_timeout": s.write_timeout,
            "exclusive": _exclusive(s),
        }
        handle = None
        try:
            handle = _opened(self.device, s, options)
            if s.flush_on_open:
                handle.reset_input_buffer()
        except SERIAL_ERRORS as exc:
            if handle is not None:
                with contextlib.suppress(*SERIAL_ERRORS):
                    handle.close()
            raise PortError(reason(exc)) from exc
        self._serial = handle
        self._fd = _descriptor(handle)

    def start(self, loop: asyncio.AbstractEventLoop, on_data: DataCallback,
              on_lost: LostCallback) -> None:
        """The second step of :meth:`open`: hand what arrives to ``on_data`` on ``loop``."""
        if self._serial is None:
            raise PortError(f"{self.name} is not open")
        self._loop = loop
        self._on_data, self._on_lost = on_data, on_lost
        self._generation += 1
        self._gone = False
        self._stop.clear()
        self._empty_reads = 0
        if self._by_thread:
            self._thread = threading.Thread(
                target=self._pump, args=(self._serial, loop, self._generation),
                name=f"serial {self.name}", daemon=True)
            self._thread.start()
            return
        if self._fd is None:
            self.close()
            raise PortError(f"{self.name} has no descriptor to watch")
        try:
            loop.add_reader(self._fd, self._readable)
        except (OSError, ValueError, NotImplementedError) as exc:
            self.close()
            raise PortError(f"cannot watch {self.name}: {reason(exc)}") from exc
        self._watching = True

    # -- reading -------------------------------------------------------------------------

    def _readable(self) -> None:
        """The loop saw the descriptor readable."""
        fd = self._fd
        if fd is None or not self._watching:
            return
        try:
            data = os.read(fd, READ_SIZE)
        except BlockingIOError:
            return
        except OSError as exc:
            self._lost(f"reading failed: {exc.strerror or exc}")
            return
        if not data:
            # A port read with VMIN 0 gives nothing both when it hung up and when the
            # loop woke it with nothing to read: only the first is a lost port.
            self._empty_reads += 1
            if hung_up(fd) or self._empty_reads > MAX_EMPTY_READS:
                self._lost(HUNG_UP)
            return
        self._empty_reads = 0
        if self._on_data is not None:
            self._on_data(data)

    def _pump(self, handle: Any, loop: asyncio.AbstractEventLoop, generation: int) -> None:
        """The reader thread: wait for bytes, hand them to the loop."""
        while not self._stop.is_set():
            try:
                data = handle.read(max(1, handle.in_waiting))
            except Exception as exc:  # noqa: BLE001 - whatever it is, this port is done
                if not self._stop.is_set():
                    why = _lost_reason(handle, exc)
                    with contextlib.suppress(RuntimeError):  # the loop is closed
                        loop.call_soon_threadsafe(self._lost_in, generation, why)
                return
            if data:
                with contextlib.suppress(RuntimeError):
                    loop.call_soon_threadsafe(self._deliver, generation, bytes(data))

    def _deliver(self, generation: int, data: bytes) -> None:
        if generation == self._generation and self._serial is not None \
                and self._on_data is not None:
            self._on_data(data)

    def _lost_in(self, generation: int, why: str) -> None:
        if generation == self._generation:
            self._lost(why)

    def _lost(self, why: str) -> None:
        """Tell the owner once; the port stays open (and refuses writes) until closed."""
        callback, self._on_lost = self._on_lost, None
        self._on_data = None
        self._gone = True
        self._stop_reading()
        if callback is not None:
            callback(why)

    # -- writing -------------------------------------------------------------------------

    def write(self, data: bytes) -> None:
        """Write all of ``data`` now; raises :class:`PortError` when the port is not open,
        was lost, or the write fails."""
        handle = self._serial
        if handle is None or self._gone:
            raise PortError(f"{self.name} is not open")
        fd = self._fd
        try:
            if fd is not None:
                # Straight to the system: a few dozen bytes fit the driver's buffer at once;
                # only what does not (a full buffer) waits, in pyserial, up to write_timeout.
                try:
                    written = os.write(fd, data)
                except BlockingIOError:
                    written = 0
                if written == len(data):
                    return
                data = data[written:]
            handle.write(data)
        except SERIAL_ERRORS as exc:
            raise PortError(f"writing to {self.name} failed: {reason(exc)}") from exc

    # -- closing -------------------------------------------------------------------------

    def _stop_reading(self) -> None:
        if self._watching and self._fd is not None and self._loop is not None:
            with contextlib.suppress(Exception):
                self._loop.remove_reader(self._fd)
        self._watching = False
        self._stop.set()

    def close(self) -> None:
        """Close the port, quietly, whatever state it is in; no callback comes after."""
        self._stop_reading()
        self._generation += 1
        self._on_data = self._on_lost = None
        handle, self._serial, self._fd = self._serial, None, None
        self._gone = False
        thread, self._thread = self._thread, None
        if thread is not None and handle is not None and thread is not threading.current_thread():
            # Let the reader leave its read before the port closes under it.
            with contextlib.suppress(*SERIAL_ERRORS, AttributeError):
                handle.cancel_read()
            thread.join(timeout=1)
        if handle is not None:
            with contextlib.suppress(*SERIAL_ERRORS):
                handle.close()
        self._loop = None


def _opened(device: str, s: PortSettings, options: dict[str, Any]) -> Any:
    """The pyserial port of ``device``, open, with its DTR and RTS lines as ``s`` says
    (set before the open when asked, so they never change once it is open)."""
    lines = s.dtr is not None or s.rts is not None
    if s.urls:
        handle = serial.serial_for_url(device, do_not_open=lines, **options)
    elif lines:
        handle = serial.Serial(None, **options)
        handle.port = device
    else:
        return serial.Serial(device, **options)
    if not lines:
        return handle
    try:
        if s.dtr is not None:
            handle.dtr = s.dtr
        if s.rts is not None:
            handle.rts = s.rts
        handle.open()
    except BaseException:
        with contextlib.suppress(*SERIAL_ERRORS):
            handle.close()
        raise
    return handle


def _lost_reason(handle: Any, exc: BaseException) -> str:
    """Why a reader thread's read failed: a hang-up if the system says so (the same
    words as when the loop watches the port), else the error."""
    fd = _descriptor(handle)
    with contextlib.suppress(OSError, ValueError):
        if fd is not None and hung_up(fd):
            return HUNG_UP
    return f"reading failed: {reason(exc)}"


def _descriptor(handle: Any) -> int | None:
    """The system descriptor of an open pyserial port (POSIX devices), else None."""
    if sys.platform == "win32":
        return None
    fd = getattr(handle, "fd", None)
    return fd if isinstance(fd, int) else None


__all__ = [
    "HUNG_UP",
    "MAX_EMPTY_READS",
    "POLL_SEES_HANG_UPS",
    "SERIAL_ERRORS",
    "DataCallback",
    "LostCallback",
    "PortSettings",
    "SerialPort",
    "hung_up",
    "reads_by_thread",
    "reason",
]
