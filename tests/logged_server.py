"""A real ``moas-server`` process that a test module's tests share, its stderr read line by
line, so that each test reads only what the server said while it ran.

A module starts one (a module-scoped fixture), and each test calls :meth:`begin` first:
what a test before left to be said (a repeated line's count is told with the next line)
is said before a barrier's line, and is not this test's.  :meth:`said` is what the
server wrote since the test began, up to now.
"""

from __future__ import annotations

import json
import shutil
import socket
import subprocess
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TypeVar

import pytest
from helpers import short_runtime_dir, wait_for

S = TypeVar("S", bound="LoggedServer")


class LoggedServer:
    """``command`` (a server's whole command line) started with ``env``; its client port
    is ``tcp`` on 127.0.0.1."""

    def __init__(self, command: list[str], env: dict[str, str], tcp: int) -> None:
        self.env = env
        self.tcp = tcp
        self.lines: list[str] = []
        self.since = 0
        self.barriers = 0
        self.process = subprocess.Popen(command, env=env, stderr=subprocess.PIPE, text=True)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stderr is not None
        for line in self.process.stderr:
            self.lines.append(line)

    def begin(self) -> None:
        """A test begins: the server must still run, and what it says from here on is the
        test's."""
        assert self.process.poll() is None, "".join(self.lines)
        self.since = len(self.lines)
        self.said()
        self.since = len(self.lines)

    def said(self) -> str:
        """What the server wrote to stderr since the test began, up to now: a hello from
        this computer under a new name is logged after everything the server did before
        it, so once its line is read, nothing written earlier is still in the pipe."""
        self.barriers += 1
        name = f"barrier {self.barriers}"
        with socket.create_connection(("127.0.0.1", self.tcp), timeout=5) as conn:
            conn.sendall(json.dumps({"id": 1, "cmd": "hello", "client": name}).encode() + b"\n")
            with conn.makefile("rb") as reader:
                reply = json.loads(reader.readline())
        assert reply.get("ok"), reply
        wait_for(lambda: any(f'is "{name}"' in line for line in self.lines[self.since:]),
                 what="the server's log line of the hello")
        lines = self.lines[self.since:]
        upto = next(n for n, line in enumerate(lines) if f'is "{name}"' in line)
        return "".join(lines[:upto])

    def stop(self) -> str:
        """Ends the server (SIGTERM); it must exit cleanly.  Returns all it wrote."""
        self.process.terminate()
        try:
            self.process.wait(timeout=15)
        finally:
            if self.process.poll() is None:
                self.process.kill()
                self.process.wait()
        self._reader.join(10)
        if self.process.stderr is not None:
            self.process.stderr.close()
        assert self.process.returncode == 0, "".join(self.lines)
        return "".join(self.lines)


def module_server(make: Callable[[Path, Path], S], factory: pytest.TempPathFactory,
                  name: str) -> Iterator[S]:
    """The body of a module-scoped fixture: ``make(folder, runtime)`` started in a folder
    ``name`` of its own and a short runtime directory, stopped (cleanly) after the module."""
    runtime = short_runtime_dir()
    try:
        server = make(factory.mktemp(name), runtime)
        try:
            yield server
        finally:
            server.stop()
    finally:
        shutil.rmtree(runtime, ignore_errors=True)
