"""The rotctld-compatible port under the one admission policy, over real sockets from
127.0.0.x: a cap with a fair share, deadlines on a FakeClock, log lines one a minute a
kind whoever sends them."""

from __future__ import annotations

import asyncio
import contextlib
import logging

import pytest
from helpers import until

from moas_gui.clock import FakeClock
from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.edge.admission import NO_DEADLINES, Admission, Deadlines
from moas_gui.net.rotctld_server import RotctldServer

ROTATOR = Rotator(
    id=6,
    short_name="Stack",
    control=RotatorControl.TEST,
    ccw_limit=180,
    rotation=360,
    has_stop=True,
    rotctld_port=0,
)


class NoService:
    """get_info and unknown commands never reach the rotators."""

    def view(self, rotator_id: int) -> object:
        raise AssertionError("not asked in these tests")


async def listening(admission: Admission, deadlines: Deadlines = NO_DEADLINES) -> RotctldServer:
    server = RotctldServer(
        NoService(),
        ROTATOR,
        "127.0.0.1",
        0,
        admission,  # type: ignore[arg-type]
        deadlines,
    )
    await server.start()
    return server


async def connect(port: int, source: str) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    return await asyncio.open_connection("127.0.0.1", port, local_addr=(source, 0))


async def info(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> bytes:
    writer.write(b"_\n")
    async with asyncio.timeout(5):
        return await reader.readline()


async def ended(reader: asyncio.StreamReader) -> bool:
    async with asyncio.timeout(10):
        return await reader.read() == b""


async def shut(writer: asyncio.StreamWriter) -> None:
    writer.close()
    with contextlib.suppress(OSError):
        await writer.wait_closed()


@pytest.mark.asyncio
async def test_a_crowd_gives_way_to_a_newcomer_from_another_address() -> None:
    admission = Admission(3, 3)
    server = await listening(admission)
    crowd = [await connect(server.port, "127.0.0.2") for _ in range(3)]
    try:
        for reader, writer in crowd:
            assert await info(reader, writer) == b"MOAS Stack\n"
        reader, writer = await connect(server.port, "127.0.0.3")
        assert await info(reader, writer) == b"MOAS Stack\n"
        assert admission.open_from("127.0.0.2") == 2
        assert await ended(crowd[0][0])  # the longest idle of the crowd
        # the crowd's next newcomer is refused: its address holds the most
        late_reader, late_writer = await connect(server.port, "127.0.0.2")
        assert await ended(late_reader)
        await shut(late_writer)
        await shut(writer)
    finally:
        for _, crowd_writer in crowd:
            await shut(crowd_writer)
        await server.close()
    await until(lambda: admission.count == 0)


@pytest.mark.asyncio
async def test_deadlines_close_the_silent_on_the_admissions_clock() -> None:
    clock = FakeClock()
    admission = Admission(10, 10, clock=clock)
    server = await listening(admission, Deadlines(hello=30, idle=600))
    try:
        mute_reader, mute_writer = await connect(server.port, "127.0.0.2")
        talker = await connect(server.port, "127.0.0.3")
        assert await info(*talker) == b"MOAS Stack\n"
        await until(lambda: admission.count == 2)
        await clock.advance(31)
        assert await ended(mute_reader)
        await clock.advance(500)
        assert await info(*talker) == b"MOAS Stack\n"  # a command keeps it
        await clock.advance(599)
        assert not talker[0].at_eof()
        await clock.advance(2)
        assert await ended(talker[0])
        await shut(mute_writer)
        await shut(talker[1])
    finally:
        await server.close()


@pytest.mark.asyncio
async def test_bad_commands_from_many_addresses_write_one_line(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui")
    admission = Admission(100, 10)
    server = await listening(admission)
    held = []
    try:
        for n in range(30):
            reader, writer = await connect(server.port, f"127.0.0.{2 + n % 5}")
            writer.write(b"Z\n" * 10 + b"_\n")  # ten unknown commands, then one answered
            assert (await asyncio.wait_for(reader.readline(), 5)) == b"MOAS Stack\n"
            held.append(writer)
        unknown = [r for r in caplog.records if "not a rotctld command" in r.getMessage()]
        assert len(unknown) == 1, len(unknown)
    finally:
        for writer in held:
            await shut(writer)
        await server.close()
