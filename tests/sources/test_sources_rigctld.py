"""The rigctld source against the real Hamlib rigctld (dummy rig, ``-m 1``) on loopback.

The recorded session below was captured from Debian's rigctld (Hamlib 4.5.4,
``rigctld -m 1 -T 127.0.0.1``) answering ``+f +i +s +t`` after
``rigctl -m 2 F 14025000``, ``S 1 VFOB`` and ``I 14030000``: the dummy rig
cannot read PTT, so ``get_ptt`` answers ``RPRT -11``.  The frequency changes
in the tests are made with the real ``rigctl -m 2`` (Hamlib's NET rigctl
backend), as an operator's other program would.
"""

from __future__ import annotations

import asyncio
import logging
import shutil
import subprocess
from collections.abc import AsyncIterator, Iterator

import pytest
import pytest_asyncio
from helpers import free_port
from rig_support import rigctl, start_rigctld

from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import FrequencyReport, SourceEvent
from moas_gui.sources.rigctld import RigctldSource
from moas_gui.sources.rigctld_reply import (
    MAX_LINE,
    ReplyParser,
    RigctldReplyError,
    RigReading,
)

pytestmark = pytest.mark.skipif(shutil.which("rigctld") is None or shutil.which("rigctl") is None,
                                reason="Hamlib's rigctld and rigctl (Debian libhamlib-utils)")

RECORDED = (b"get_freq:\nFrequency: 14025000\nRPRT 0\n"
            b"get_split_vfo:\nSplit: 1\nTX VFO: VFOB\nRPRT 0\n"
            b"get_split_freq:\nTX Frequency: 14030000\nRPRT 0\n"
            b"get_ptt:\nRPRT -11\n")


# -- the parser -------------------------------------------------------------------------

def test_the_recorded_session_reads_as_split_with_no_ptt() -> None:
    readings = ReplyParser().feed(RECORDED)
    assert readings == [RigReading(rx_hz=14025000, split=True, tx_hz=14030000, ptt=None)]
    assert readings[0].transmit_hz == 14030000


def test_the_reply_may_arrive_a_byte_at_a_time() -> None:
    parser = ReplyParser()
    readings = [r for byte in RECORDED for r in parser.feed(bytes([byte]))]
    assert [r.rx_hz for r in readings] == [14025000]


def test_not_split_transmits_on_the_receive_frequency() -> None:
    text = RECORDED.replace(b"Split: 1", b"Split: 0").replace(b"RPRT -11", b"PTT: 1\nRPRT 0")
    reading = ReplyParser().feed(text)[0]
    assert (reading.transmit_hz, reading.ptt) == (14025000, True)


@pytest.mark.parametrize(("reply", "reason"), [
    (b"garbage\n", "out_of_step"),
    (b"get_freq:\nFrequency 14025000\n", "not_a_record"),
    (b"get_freq:\nRPRT zero\n", "bad_rprt"),
    (b"x" * (MAX_LINE + 1), "too_long"),
    (RECORDED.replace(b"14025000", b"fourteen"), "bad_number"),
    (RECORDED.replace(b"14025000", b"9" * 30), "absurd"),
    (RECORDED.replace(b"14025000", b"nan"), "absurd"),
    (RECORDED.replace(b"Split: 1", b"Split: 7"), "bad_value"),
])
def test_a_malformed_reply_is_refused_with_a_reason(reply: bytes, reason: str) -> None:
    with pytest.raises(RigctldReplyError) as refused:
        ReplyParser().feed(reply)
    assert refused.value.reason == reason


# -- the real daemon ----------------------------------------------------------------------

@pytest.fixture
def rigctld() -> Iterator[tuple[int, list[subprocess.Popen[bytes]]]]:
    port = free_port()
    processes = [start_rigctld(port)]
    yield port, processes
    for process in processes:
        if process.poll() is None:
            process.terminate()
            process.wait(5)


class Events:
    def __init__(self) -> None:
        self.items: list[SourceEvent] = []
        self._changed = asyncio.Event()

    def __call__(self, event: SourceEvent) -> None:
        self.items.append(event)
        self._changed.set()

    async def until(self, check: object, timeout: float = 10.0) -> FrequencyReport:
        async def wait() -> FrequencyReport:
            while True:
                for event in reversed(self.items):
                    if isinstance(event, FrequencyReport) and check(event):  # type: ignore[operator]
                        return event
                self._changed.clear()
                await self._changed.wait()
        return await asyncio.wait_for(wait(), timeout)


@pytest_asyncio.fixture
async def polling(rigctld: tuple[int, list[subprocess.Popen[bytes]]]
                  ) -> AsyncIterator[tuple[RigctldSource, Events, int,
                                           list[subprocess.Popen[bytes]]]]:
    port, processes = rigctld
    events = Events()
    # short pauses before new attempts: a daemon that went away is found again at once
    source = RigctldSource(2, 1, events, port=port, interval=0.02, timeout=1.0, retry=0.01)
    await source.start()
    yield source, events, port, processes
    await source.close()


@pytest.mark.realtime  # the real rigctld daemon
@pytest.mark.asyncio
async def test_rigctl_changing_the_frequency_reaches_the_sink(polling: tuple) -> None:
    _, events, port, _ = polling
    first = await events.until(lambda e: True)
    assert (first.station, first.radio, first.origin) == (2, 1, f"rigctld 127.0.0.1:{port}")
    await rigctl(port, "F", "14025000")
    report = await events.until(lambda e: e.rx_khz == 14025.0)
    assert report.tx_khz == 14025.0
    await rigctl(port, "S", "1", "VFOB")
    await rigctl(port, "I", "14030000")
    split = await events.until(lambda e: e.tx_khz == 14030.0)
    assert split.rx_khz == 14025.0


@pytest.mark.realtime  # the real rigctld daemon
@pytest.mark.asyncio
async def test_an_unchanged_radio_is_reported_once(polling: tuple) -> None:
    source, events, _, _ = polling
    await events.until(lambda e: True)
    polls = source.polls
    while source.polls < polls + 5:  # the dummy rig's PTT becomes readable after its first poll
        await asyncio.sleep(0.02)
    reported = len(events.items)
    while source.polls < polls + 20:
        await asyncio.sleep(0.02)
    assert len(events.items) == reported <= 2


@pytest.mark.realtime  # the real rigctld daemon
@pytest.mark.asyncio
async def test_a_daemon_that_goes_away_and_returns_is_logged_once_each_way(
        polling: tuple, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources")
    source, events, port, processes = polling
    await events.until(lambda e: True)
    processes[0].terminate()
    processes[0].wait(5)
    while source.link.failures < 3:
        await asyncio.sleep(0.05)
    processes.append(await asyncio.to_thread(start_rigctld, port))
    await rigctl(port, "F", "7025000")
    await events.until(lambda e: e.rx_khz == 7025.0)
    warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
    backs = [r for r in caplog.records if "is back" in r.getMessage()]
    assert len(warnings) == 1, [r.getMessage() for r in warnings]
    assert "rigctld at 127.0.0.1" in warnings[0].getMessage()
    assert len(backs) == 1


# -- a daemon that answers garbage --------------------------------------------------------

@pytest.mark.realtime  # the real rigctld daemon
@pytest.mark.asyncio
async def test_garbage_replies_reach_nothing_and_log_one_debug_line(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources")
    replies = [b"\x00\xff garbage\n", RECORDED.replace(b"14025000", b"99999999999999999"),
               b"y" * 5000]
    served = 0

    async def serve(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        nonlocal served
        await reader.readline()
        writer.write(replies[served % len(replies)])
        served += 1
        await writer.drain()
        await reader.read(100)
        writer.close()

    server = await asyncio.start_server(serve, "127.0.0.1", 0)
    port = server.sockets[0].getsockname()[1]
    events = Events()
    source = RigctldSource(1, 1, events, port=port, interval=0.01, timeout=0.5)
    source._backoff = Pauses(Backoff(first=0.01, most=0.01))
    await source.start()
    try:
        # the source connects again only once it has read the last reply: a tenth
        # connection means the ninth reply was judged
        while served < 10:
            await asyncio.sleep(0.01)
    finally:
        await source.close()
        server.close()
        await server.wait_closed()
    assert events.items == []
    assert source.bad.total >= 9
    dropped = [r for r in caplog.records if "dropped" in r.getMessage()]
    assert len(dropped) == 3  # one per kind of fault, the repeats held back
    assert {r.levelno for r in dropped} == {logging.DEBUG}
