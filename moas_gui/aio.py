"""Small asyncio helpers shared by every part that owns a background task."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import signal
import sys
import threading
from collections.abc import Callable, Coroutine
from typing import Any, Final, Self

log = logging.getLogger(__name__)


async def cancel_and_wait(task: asyncio.Task[Any], poll: float = 0.2) -> None:
    """Cancel ``task`` and return once it has really ended.

    Python 3.11's ``asyncio.wait_for`` can swallow a cancellation that arrives
    together with the result it waits for (or with its error); the task then
    runs on, and a plain ``cancel(); await task`` waits forever.  This keeps
    cancelling until the task is done.  Whatever the task ended with is
    retrieved, never raised.
    """
    while not task.done():
        task.cancel()
        await asyncio.wait({task}, timeout=poll)
    if not task.cancelled():
        task.exception()


class BackgroundTasks:
    """The background tasks of one owner (a window's menu actions, a manager's turns).

    Each task is kept until it ends; what it ended with is handed to ``failed`` (an
    error is never lost, a cancellation is not an error); :meth:`idle` waits for all
    of them, :meth:`close` cancels what still runs and returns once it has ended.
    Nothing started here outlives its owner's close.
    """

    def __init__(self, failed: Callable[[str, BaseException], None]) -> None:
        self._failed = failed
        self._tasks: dict[asyncio.Task[Any], str] = {}

    def spawn(self, work: Coroutine[Any, Any, Any], what: str) -> asyncio.Task[Any]:
        """Run ``work`` as a task of this owner; ``what`` names it in messages."""
        task = asyncio.ensure_future(work)
        task.set_name(what)
        self._tasks[task] = what
        task.add_done_callback(self._done)
        return task

    def _done(self, task: asyncio.Task[Any]) -> None:
        what = self._tasks.pop(task, "a background task")
        if not task.cancelled() and (error := task.exception()) is not None:
            self._failed(what, error)

    def __len__(self) -> int:
        return len(self._tasks)

    async def idle(self) -> None:
        """Wait until every task has ended, those started meanwhile too."""
        while self._tasks:
            await asyncio.wait(list(self._tasks))

    def cancel(self) -> None:
        """Ask every task to end (where the owner cannot wait: :meth:`close` also waits)."""
        for task in list(self._tasks):
            task.cancel()

    async def close(self) -> None:
        """Cancel every task and wait until each has really ended."""
        while self._tasks:
            for task in list(self._tasks):
                await cancel_and_wait(task)


# -- stopping cleanly ----------------------------------------------------------------------

CTRL_CLOSE_EVENT: Final = 2
"""Windows: the console window is being closed."""
CTRL_LOGOFF_EVENT: Final = 5
CTRL_SHUTDOWN_EVENT: Final = 6
CONSOLE_ENDINGS: Final = frozenset({CTRL_CLOSE_EVENT, CTRL_LOGOFF_EVENT, CTRL_SHUTDOWN_EVENT})
CLOSE_GRACE_S: Final = 4.5
"""How long a console-close handler holds Windows back while the program finishes
(Windows ends the process about 5 s after the close, whatever the handler does)."""

SignalSetter = Callable[[int, Any], Any]
ConsoleHook = Callable[[Callable[[int], bool]], Callable[[], None]]
"""Registers a console control handler and returns what removes it (Windows)."""


def stop_signals(platform: str = sys.platform) -> tuple[tuple[str, int], ...]:
    """The signals that ask a program to stop on ``platform``, by name and number.

    POSIX: SIGINT (Ctrl+C), SIGTERM (``kill``, systemd, launchd) and SIGHUP (the terminal
    closed; left alone when the program was started with it ignored, as ``nohup`` does).  Windows: SIGINT (Ctrl+C) and SIGBREAK (Ctrl+Break); SIGTERM is listed too,
    though Windows itself never sends it (another Python may, with ``os.kill``).
    """
    if platform == "win32":
        # the numbers of Windows' C runtime, which Python's signal module uses there
        return (("SIGINT", 2), ("SIGBREAK", 21), ("SIGTERM", 15))
    return (("SIGINT", int(signal.SIGINT)), ("SIGTERM", int(signal.SIGTERM)),
            ("SIGHUP", int(getattr(signal, "SIGHUP", 1))))


class CleanStop:
    """Calls ``on_stop`` (on the loop's thread) when the program is asked to stop.

    One way for every entry point:

    * where the loop has signal handlers (asyncio on POSIX), SIGINT, SIGTERM and SIGHUP
      go through ``loop.add_signal_handler``;
    * where it has not (Windows, or a Qt loop through qasync), plain ``signal.signal``
      handlers hand the request to the loop with ``call_soon_threadsafe``: on Windows
      these are SIGINT and SIGBREAK (Ctrl+C, Ctrl+Break);
    * on Windows, a console control handler catches the console window being closed
      (and log-off, shut-down), asks the loop to stop and then holds Windows back until
      :meth:`remove` (the end of the ``with`` block, after the program has written its
      state) or :data:`CLOSE_GRACE_S`;
    * KeyboardInterrupt stays the last resort: :func:`run_until_stopped` turns it into
      a normal exit, and asyncio's runner has already cancelled the main task, whose
      ``finally`` blocks ran.

    Use it as a context manager around the wait and the tidying up::

        stop = asyncio.Event()
        with CleanStop(stop.set):
            await stop.wait()
            await program.close()

    ``platform``, ``set_signal`` and ``console`` are there for tests, which fake
    Windows on Linux.
    """

    def __init__(self, on_stop: Callable[[], None], *,
                 loop: asyncio.AbstractEventLoop | None = None,
                 platform: str = sys.platform,
                 set_signal: SignalSetter | None = None,
                 console: ConsoleHook | None = None,
                 close_grace: float = CLOSE_GRACE_S) -> None:
        self._on_stop = on_stop
        self._loop = loop
        self._platform = platform
        self._set_signal = set_signal or signal.signal
        self._console = console
        self._close_grace = close_grace
        self._on_loop: list[tuple[int, Any]] = []
        self._replaced: list[tuple[int, Any]] = []
        self._remove_console: Callable[[], None] | None = None
        self._finished = threading.Event()
        self.reason: str | None = None
        """What asked to stop ("SIGTERM", "console closed", ...), once something has."""

    # -- installing -----------------------------------------------------------------------

    def install(self) -> Self:
        loop = self._loop or asyncio.get_running_loop()
        self._loop = loop
        self._finished.clear()
        for name, number in stop_signals(self._platform):
            if name == "SIGHUP" and _ignored(number):
                continue  # started with nohup (or the like): a hang-up is not a stop
            if self._platform != "win32":
                try:
                    before = signal.getsignal(number)
                    loop.add_signal_handler(number, self._stop, name)
                except (NotImplementedError, RuntimeError, ValueError):
                    pass  # a loop without them (qasync): a plain handler below
                else:
                    # put back on removal (asyncio.run's own Ctrl+C handler, say)
                    self._on_loop.append((number, before))
                    continue
            try:
                previous = self._set_signal(number, self._signal_handler(name))
            except (ValueError, OSError):  # not the main thread, or no such signal here
                continue
            self._replaced.append((number, previous))
        if self._platform == "win32":
            hook = self._console or _windows_console_hook
            try:
                self._remove_console = hook(self._console_event)
            except OSError as exc:  # no console (a window program): nothing to close
                log.debug("No console close handler: %s", exc)
        return self

    def remove(self) -> None:
        """Undo :meth:`install` and let a waiting console-close handler return."""
        loop = self._loop
        for number, before in self._on_loop:
            if loop is not None and not loop.is_closed():
                loop.remove_signal_handler(number)
            if before is not None:
                with contextlib.suppress(ValueError, OSError, TypeError):
                    signal.signal(number, before)
        self._on_loop.clear()
        for number, previous in reversed(self._replaced):
            with contextlib.suppress(ValueError, OSError, TypeError):
                self._set_signal(number, previous)
        self._replaced.clear()
        if self._remove_console is not None:
            self._remove_console()
            self._remove_console = None
        self._finished.set()

    def __enter__(self) -> Self:
        return self.install()

    def __exit__(self, *_exc: object) -> None:
        self.remove()

    # -- what the handlers do --------------------------------------------------------------

    def _stop(self, reason: str) -> None:
        if self.reason is None:
            self.reason = reason
            log.info("Stopping (%s)", reason)
        self._on_stop()

    def _signal_handler(self, name: str) -> Callable[[int, object], None]:
        def handler(_number: int, _frame: object) -> None:
            loop = self._loop
            if loop is None or loop.is_closed():
                raise KeyboardInterrupt  # no loop to tell: the last resort
            loop.call_soon_threadsafe(self._stop, name)
        return handler

    def _console_event(self, event: int) -> bool:
        """Windows calls this on its own thread; True means "handled"."""
        if event not in CONSOLE_ENDINGS:
            return False  # Ctrl+C and Ctrl+Break go on to Python's signal handlers
        loop = self._loop
        if loop is None or loop.is_closed():
            return False
        what = {CTRL_CLOSE_EVENT: "console closed", CTRL_LOGOFF_EVENT: "logging off",
                CTRL_SHUTDOWN_EVENT: "shutting down"}[event]
        loop.call_soon_threadsafe(self._stop, what)
        # Windows ends the process as soon as this returns: wait for the tidying up
        self._finished.wait(self._close_grace)
        return True


def _ignored(number: int) -> bool:
    try:
        return signal.getsignal(number) is signal.SIG_IGN
    except ValueError:  # not a signal of this system (a faked platform)
        return False


def _windows_console_hook(handler: Callable[[int], bool]) -> Callable[[], None]:
    """Register ``handler`` with ``SetConsoleCtrlHandler``; returns its removal."""
    if sys.platform != "win32":
        raise OSError("console control handlers are Windows only")
    import ctypes
    from ctypes import wintypes

    prototype = ctypes.WINFUNCTYPE(wintypes.BOOL, wintypes.DWORD)
    callback = prototype(lambda event: bool(handler(int(event))))
    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    if not kernel32.SetConsoleCtrlHandler(callback, True):
        raise ctypes.WinError(ctypes.get_last_error())

    def remove() -> None:
        kernel32.SetConsoleCtrlHandler(callback, False)  # keeps ``callback`` alive till now

    return remove


def run_until_stopped(main: Coroutine[Any, Any, int | None]) -> int:
    """``asyncio.run(main)``; a KeyboardInterrupt that got past :class:`CleanStop` (one
    before it was installed) ends the program normally: asyncio has cancelled ``main``
    and run its ``finally`` blocks by then.  Returns ``main``'s exit status (0 for None)."""
    try:
        return asyncio.run(main) or 0
    except KeyboardInterrupt:
        return 0


__all__ = ["BackgroundTasks", "CleanStop", "cancel_and_wait", "run_until_stopped", "stop_signals"]
