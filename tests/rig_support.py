"""Helpers shared by the tests that use a radio's side: Hamlib's real rigctld and rigctl
(the dummy rig), and a pseudo-terminal behind a fixed path, as a logger's OTRSP port."""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import time
from pathlib import Path


def start_rigctld(port: int) -> subprocess.Popen[bytes]:
    process = subprocess.Popen(["rigctld", "-m", "1", "-T", "127.0.0.1", "-t", str(port)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for _ in range(500):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return process
        except OSError:
            time.sleep(0.01)
    raise AssertionError(f"rigctld did not listen on {port}")


async def rigctl(port: int, *args: str) -> None:
    process = await asyncio.create_subprocess_exec(
        "rigctl", "-m", "2", "-r", f"127.0.0.1:{port}", *args,
        stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.DEVNULL)
    assert await asyncio.wait_for(process.wait(), 10) == 0



class Pty:
    """A pseudo-terminal whose slave is reached by a fixed path (like a udev link)."""

    def __init__(self, link: Path) -> None:
        self.link = link
        self.master = -1
        self.open()

    def open(self) -> None:
        master, slave = os.openpty()
        self.master = master
        name = os.ttyname(slave)
        os.close(slave)
        if self.link.is_symlink():
            self.link.unlink()
        self.link.symlink_to(name)

    def write(self, data: bytes) -> None:
        os.write(self.master, data)

    def vanish(self) -> None:
        os.close(self.master)
        self.master = -1

    async def read_until(self, end: bytes, timeout: float = 5.0) -> bytes:
        loop = asyncio.get_running_loop()
        got = b""
        deadline = loop.time() + timeout
        os.set_blocking(self.master, False)
        while not got.endswith(end):
            try:
                got += os.read(self.master, 100)
            except BlockingIOError:
                if loop.time() > deadline:
                    raise AssertionError(f"no {end!r} from the source, got {got!r}") from None
                await asyncio.sleep(0.01)
        return got
