"""Starting the local MOAS Rotator program (appendix B, ``StartMOASRotator``).

When any Serial rotator is on this computer (Address 127.0.0.1, localhost,
::1) and the configuration does not set ``StartMOASRotator`` to false, the
server starts the program as a child process and stops it on exit.  If a
program already answers on the port (started by hand), none is started.
The child's output goes to the log under this module's logger.

A started program that exits by itself (a crash, killed) is started again
after ``restart_min`` seconds, twice as long each time it dies again soon
(at most ``restart_max``): the rotators it serves come back online without
anyone restarting the server.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import re
import sys
from collections.abc import Sequence

from moas_gui.clock import LOOP_CLOCK, Clock
from moas_gui.retry import Backoff, Pauses

log = logging.getLogger(__name__)


def default_command(port: int, allow: Sequence[str] = ()) -> list[str]:
    """``python -m moas_gui.cli.rotator`` (the ``moas-rotator`` program), on ``port``.

    The program the server starts serves this computer's rotators to this server
    only, so it listens on the loopback address; it may open the ``CommPort`` of
    each of ``allow`` (the configuration's rotators: serial devices, and the
    ``socket://`` ports the configuration names)."""
    command = [sys.executable, "-m", "moas_gui.cli.rotator", "--bind", "127.0.0.1"]
    for comm_port in dict.fromkeys(allow):  # as they are: no pattern characters
        command += ["--allow", comm_port.replace("[", "[[]").replace("*", "[*]")
                    .replace("?", "[?]")]
    if port != 13020:
        command += ["--port", str(port)]
    return command


STEADY = 60.0
"""Seconds a program must have run for its next restart to wait ``restart_min`` again."""


_PROGRAM_LOG = re.compile(
    r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d[,.]\d+ (?P<level>[A-Z]+) [\w.]+: (?P<text>.*)$")


def relayed_line(text: str) -> tuple[int, str]:
    """The level and message of a line the program logged (its own time stamp,
    level and logger name dropped: the server's log adds its own)."""
    match = _PROGRAM_LOG.match(text)
    if match is None:
        return logging.INFO, text
    level = logging.getLevelName(match["level"])
    return (level if isinstance(level, int) else logging.INFO), match["text"]


class LocalMoasRotator:
    def __init__(self, command: Sequence[str], port: int, *, start_timeout: float = 5.0,
                 stop_timeout: float = 3.0, restart_min: float = 1.0,
                 restart_max: float = 30.0, clock: Clock = LOOP_CLOCK) -> None:
        self.command = list(command)
        self.port = port
        self.start_timeout = start_timeout
        self.stop_timeout = stop_timeout
        self.restart_min = restart_min
        self.restart_max = restart_max
        self.clock = clock
        """Times the program's life and waits out its restarts."""
        self._restarts = Pauses(Backoff(first=restart_min, factor=2.0, most=restart_max))
        self._started_at = 0.0
        self._listening = asyncio.Event()
        self.process: asyncio.subprocess.Process | None = None
        self._output: asyncio.Task[None] | None = None
        self._restart: asyncio.Task[None] | None = None

    async def start(self) -> None:
        """Start the program unless one already answers; never raises."""
        if await _answers("127.0.0.1", self.port):
            log.info("a MOAS Rotator program already answers on port %d; not starting another",
                     self.port)
            return
        try:
            self.process = await asyncio.create_subprocess_exec(
                *self.command, stdin=asyncio.subprocess.DEVNULL,
                stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.STDOUT,
            )
        except OSError as exc:
            log.error("could not start the MOAS Rotator program (%s): %s",
                      " ".join(self.command), exc)
            return
        log.info("started the MOAS Rotator program (pid %d): %s",
                 self.process.pid, " ".join(self.command))
        self._started_at = self.clock.now()
        self._listening = asyncio.Event()
        self._output = asyncio.create_task(self._relay(self.process), name="MOAS Rotator output")
        # let it open its port before the first connection attempt (it says
        # "listening on ..."); if it never says so, the link just keeps trying
        with contextlib.suppress(TimeoutError):
            await asyncio.wait_for(self._listening.wait(), self.start_timeout)

    async def stop(self) -> None:
        restart, self._restart = self._restart, None
        if restart is not None:
            restart.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await restart
        process, self.process = self.process, None
        if process is not None and process.returncode is None:
            process.terminate()
            try:
                await asyncio.wait_for(process.wait(), self.stop_timeout)
            except TimeoutError:
                log.warning("the MOAS Rotator program (pid %d) did not stop; killing it",
                            process.pid)
                process.kill()
                await process.wait()
            log.info("stopped the MOAS Rotator program (pid %d)", process.pid)
        task, self._output = self._output, None
        if task is not None:
            with contextlib.suppress(asyncio.CancelledError):
                await task

    async def _relay(self, process: asyncio.subprocess.Process) -> None:
        assert process.stdout is not None
        while line := await process.stdout.readline():
            text = line.decode("utf-8", "replace").rstrip()
            if "listening on" in text:
                self._listening.set()
            level, text = relayed_line(text)
            log.log(level, "MOAS Rotator: %s", text)
        self._listening.set()
        code = await process.wait()
        if self.process is process:
            if self.clock.now() - self._started_at >= STEADY:
                self._restarts.reset()
            wait = self._restarts.next()
            log.error("the MOAS Rotator program (pid %d) exited with code %d; starting it "
                      "again in %g s", process.pid, code, wait)
            self._restart = asyncio.create_task(self._start_again(process, wait),
                                                name="MOAS Rotator restart")

    async def _start_again(self, dead: asyncio.subprocess.Process, wait: float) -> None:
        await self.clock.sleep(wait)
        if self.process is dead:  # not stopped meanwhile
            self.process = None
            await self.start()


async def _answers(host: str, port: int) -> bool:
    try:
        _, writer = await asyncio.wait_for(asyncio.open_connection(host, port), 1.0)
    except (OSError, TimeoutError):
        return False
    writer.close()
    with contextlib.suppress(OSError):
        await writer.wait_closed()
    return True


__all__ = ["LocalMoasRotator", "default_command"]
