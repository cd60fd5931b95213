"""Emulated controllers on pseudo-terminals, and the drivers that talk to them, on a
fake clock.

The pseudo-terminals and the emulator host's thread are real, and take real time; the
drivers' polls, quiet times, reply timeouts and retries, and the emulators' turning,
are on the bench's :class:`FakeClock`.  A driver (or the MOAS Rotator program) opens
its ports through :meth:`PtyBench.open`, which counts the bytes each way, and the bench
moves the clock on only once every byte written has been read and handled at the other
end: a reply is never late on the fake clock because the machine was busy, and a turn
of a minute takes a fraction of a second.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Self

from helpers import FakeClock

from moas_gui.hw.rotators.controllers.base import ControllerEmulator, SerialSettings
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort
from moas_gui.rotator_program.serial_link import ControllerPort, open_serial, split_port

STEP = 0.02
"""Seconds the clock moves at a time: shorter than any poll, quiet time or timeout."""
SETTLE_LIMIT = 5.0
"""Real seconds the bytes in flight may take before the bench gives up."""


class CountedLink:
    """A port a driver opened on the bench, counting what goes each way."""

    def __init__(self, inner: ControllerPort, port: ServedPort | None, sent_before: int) -> None:
        self.name = inner.name
        self.port = port
        """The emulator's port it reaches (None: nothing served there)."""
        self.sent_before = sent_before
        """What the emulator had sent before this link opened (not for this link)."""
        self.written = 0
        self.delivered = 0
        self.open = True
        self._inner = inner

    def write(self, data: bytes) -> None:
        self._inner.write(data)
        self.written += len(data)

    def close(self) -> None:
        self.open = False
        self._inner.close()


class PtyBench:
    """An :class:`EmulatorHost` on a fake clock, and an opener that counts bytes."""

    def __init__(self) -> None:
        self.clock = FakeClock()
        self.host = EmulatorHost(clock=self.clock.now)
        self._links: list[CountedLink] = []
        self._opening = 0

    def __enter__(self) -> Self:
        self.host.start()
        return self

    def __exit__(self, *_: object) -> None:
        self.host.close()

    def add(self, emulator: ControllerEmulator, link: str | None = None) -> ServedPort:
        return self.host.add(emulator, link=link)

    async def open(self, port: str, settings: SerialSettings, on_data: Callable[[bytes], None],
                   on_lost: Callable[[Exception], None], *,
                   use_thread: bool | None = None) -> ControllerPort:
        """The drivers' opener (:data:`~moas_gui.rotator_program.serial_link.Opener`)."""
        counted: list[CountedLink] = []

        def deliver(data: bytes) -> None:
            counted[0].delivered += len(data)
            on_data(data)

        self._opening += 1
        try:
            inner = await open_serial(port, settings, deliver, on_lost, use_thread=use_thread)
        finally:
            self._opening -= 1
        served = self.host.find(split_port(port)[0])
        traffic = None if served is None else self.host.traffic(served)
        link = CountedLink(inner, served, 0 if traffic is None else traffic[1])
        counted.append(link)
        self._links.append(link)
        return link

    def quiet(self) -> bool:
        """True when no byte is on its way: every byte a driver wrote was read by its
        emulator, every answer reached the driver, and no port is being opened."""
        if self._opening:
            return False
        written: dict[int, int] = {}
        for link in self._links:
            if link.port is not None:
                written[id(link.port)] = written.get(id(link.port), 0) + link.written
        for link in self._links:
            if link.port is None:
                continue
            traffic = self.host.traffic(link.port)
            if traffic is None:
                continue  # removed: its bytes are lost, as on a pulled adapter
            received, sent = traffic
            if received != written[id(link.port)]:
                return False
            if link.open and link.delivered < sent - link.sent_before:
                return False
        return True

    async def settle(self) -> None:
        """Waits (in real time) until :meth:`quiet`."""
        loop = asyncio.get_running_loop()
        give_up = loop.time() + SETTLE_LIMIT
        while not self.quiet():
            if loop.time() > give_up:
                raise AssertionError(f"bytes still in flight after {SETTLE_LIMIT} s")
            await asyncio.sleep(0.001)

    async def step(self, seconds: float = STEP) -> None:
        """Once quiet, moves the clock on and lets the emulators catch up."""
        await self.settle()
        await self.clock.advance(seconds)
        self.host.catch_up()
        await self.settle()

    async def advance(self, seconds: float) -> None:
        """Moves the clock on by ``seconds``, a step at a time."""
        end = self.clock.now() + seconds
        while self.clock.now() < end - 1e-9:
            await self.step(min(STEP, end - self.clock.now()))

    async def until(self, condition: Callable[[], object], timeout: float = 10.0,
                    what: str = "the condition") -> None:
        """Moves the clock on until ``condition()`` holds; gives up after ``timeout``
        seconds on the clock."""
        deadline = self.clock.now() + timeout
        await self.settle()
        while not condition():
            if self.clock.now() >= deadline:
                raise AssertionError(f"gave up waiting for {what} ({timeout:g} s on the clock)")
            await self.step()
