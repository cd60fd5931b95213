"""Sources and the forwarder of ``moas-client --headless`` end when closed, whatever
their request or poll is doing at that moment.

On Python 3.11 ``asyncio.wait_for`` returns the awaited result instead of raising
CancelledError when the cancellation and the result come at the same moment, so a
request or a poll can swallow the cancellation of ``close()``.  Everything must end
all the same (``moas-client`` hung on SIGTERM when the server's answer crossed it).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

import pytest

from moas_gui.client.connection import LinkState
from moas_gui.sources.base import FrequencyReport, SourceEvent
from moas_gui.sources.forwarder import Forwarder
from moas_gui.sources.polling import PolledRig, RigState


class SwallowingConnection:
    """Stands in for the client connection: connected, and a frequency request that, when
    cancelled, returns as if its reply had come at that moment."""

    def __init__(self) -> None:
        self.link = LinkState.CONNECTED
        self.asked: list[tuple[int, int, float]] = []
        self.in_flight = asyncio.Event()

    def subscribe(self, listener: Callable[[object], None]) -> Callable[[], None]:
        return lambda: None

    async def frequency(self, station: int, radio: int, khz: float, tx: float | None) -> None:
        self.asked.append((station, radio, khz))
        self.in_flight.set()
        try:
            await asyncio.Event().wait()  # the reply is slow ...
        except asyncio.CancelledError:
            return  # ... and arrives just as the request is cancelled: swallowed


@pytest.mark.asyncio
async def test_closing_ends_the_forwarder_even_when_its_request_swallows_the_cancel() -> None:
    connection = SwallowingConnection()
    forwarder = Forwarder(connection)  # type: ignore[arg-type]
    forwarder.start()
    forwarder(FrequencyReport(1, 1, 14025.0, 14025.0, "rigctld 127.0.0.1:4532"))
    forwarder(FrequencyReport(1, 2, 7025.0, 7025.0, "rigctld 127.0.0.1:4534"))
    await asyncio.wait_for(connection.in_flight.wait(), 5)
    await asyncio.wait_for(forwarder.aclose(), 5)
    assert connection.asked == [(1, 1, 14025.0)], "nothing is sent once closing"


class CrossingRig(PolledRig):
    """A polled daemon whose answer the test gives; :attr:`asked` is set while it waits."""

    kind = "test"
    label = "test rig"

    def __init__(self, port: int, events: list[SourceEvent]) -> None:
        super().__init__(1, 1, events.append, host="127.0.0.1", port=port, interval=0.01)
        self.asked = asyncio.Event()
        self.answer: asyncio.Future[RigState] | None = None

    async def poll(self, reader: asyncio.StreamReader,
                   writer: asyncio.StreamWriter) -> RigState:
        self.answer = asyncio.get_running_loop().create_future()
        self.asked.set()
        return await self.answer


@pytest.mark.asyncio
async def test_closing_a_polled_rig_whose_answer_comes_at_that_moment_ends_it() -> None:
    accepted: list[asyncio.StreamWriter] = []
    server = await asyncio.start_server(lambda r, w: accepted.append(w), "127.0.0.1", 0)
    events: list[SourceEvent] = []
    rig = CrossingRig(server.sockets[0].getsockname()[1], events)
    try:
        await rig.start()
        await asyncio.wait_for(rig.asked.wait(), 5)
        assert rig.answer is not None
        rig.answer.set_result(RigState(14025.0, 14025.0, False))  # the answer arrives ...
        await asyncio.wait_for(rig.close(), 5)  # ... as the source is closed
    finally:
        server.close()
        for writer in accepted:
            writer.close()
        await server.wait_closed()
    assert rig._task is None
    assert len(events) <= 1, "the answer may count, nothing after it"
