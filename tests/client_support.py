"""Helpers shared by the client tests (imported as ``client_support``).

* :func:`run_on_qt` runs a coroutine on a qasync loop over the test's
  QApplication, so Qt signals and asyncio both work inside it (SETUP-NOTES:
  never ``qtbot.waitSignal`` inside a coroutine; await or poll instead).
* :class:`LiveServer` is the project's real client protocol server over its
  fake backend, on 127.0.0.1 and a port the system picks; it can be stopped
  and started again on the same port.
* :func:`until` polls a condition while the loop runs.

The one test here checks the helpers themselves, so a broken helper shows up
as its own failure rather than as a puzzle in every other test.
"""

from __future__ import annotations

import asyncio
from collections.abc import Coroutine
from typing import Any, Self, TypeVar

import qasync  # type: ignore[import-untyped]

from moas_gui.aio import cancel_and_wait
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.testing.fake_station import DEMO_STATION, FakeStation

T = TypeVar("T")

LOOPBACK = "127.0.0.1"


def run_on_qt(qapp: Any, coro: Coroutine[Any, Any, T], timeout: float = 30.0) -> T:
    """Runs ``coro`` to its end on a fresh qasync loop (failing after ``timeout``).

    Closing the last window would make Qt quit and stop the loop under the
    coroutine, so that is switched off while it runs."""
    quit_on_close = qapp.quitOnLastWindowClosed()
    qapp.setQuitOnLastWindowClosed(False)
    loop = qasync.QEventLoop(qapp)
    asyncio.set_event_loop(loop)
    try:
        return loop.run_until_complete(asyncio.wait_for(coro, timeout))
    finally:
        pending = [t for t in asyncio.all_tasks(loop) if not t.done()]
        if pending:
            loop.run_until_complete(asyncio.wait_for(
                asyncio.gather(*(cancel_and_wait(t) for t in pending)), 10))
        loop.run_until_complete(loop.shutdown_asyncgens())
        asyncio.set_event_loop(None)
        loop.close()
        qapp.setQuitOnLastWindowClosed(quit_on_close)


class LiveServer:
    """The protocol server over a :class:`FakeBackend`, on 127.0.0.1."""

    def __init__(self, station: FakeStation = DEMO_STATION) -> None:
        self.station = station
        self.backend = FakeBackend(station)
        self.server: ClientServer | None = None
        self.port = 0

    async def start(self) -> Self:
        self.server = ClientServer(self.backend, host=LOOPBACK, port=self.port)
        self.backend.attach(self.server)
        self.port = await self.server.start()
        return self

    async def stop(self) -> None:
        if self.server is not None:
            await self.server.close()
            self.backend.attach(None)
            self.server = None

    async def __aenter__(self) -> Self:
        return await self.start()

    async def __aexit__(self, *exc: object) -> None:
        await self.stop()

    def calls(self, name: str) -> list[tuple[Any, ...]]:
        """The arguments of every backend call named ``name``, in order."""
        return [args for call, args in self.backend.calls if call == name]
