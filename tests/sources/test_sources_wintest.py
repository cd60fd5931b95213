"""The Win-Test source over real UDP on 127.0.0.1, and its frame parser.

The recorded frame is the STATUS sample published in tk5ep/WtNetwork's
wtnetwork.py comment (also quoted in shared/specs/logger-network.md 2.2):
``STATUS: "STN1" "" 0 5 1 0 140751 "0" 0 "1"  143400 "TK5EP"`` followed by the
checksum byte and a NUL; the sample shows those two bytes as ``??``, so they
are computed here by the published rule (sum of the bytes before, modulo 256,
top bit set).
"""

from __future__ import annotations

import asyncio
import logging
import socket
from collections.abc import AsyncIterator

import pytest
import pytest_asyncio

from moas_gui.sources.base import FrequencyReport, SourceEvent, SourceHub
from moas_gui.sources.wintest import WinTestListener
from moas_gui.sources.wintest_frame import (
    WinTestFrameError,
    checksum,
    make_frame,
    parse_frame,
    parse_status,
    status_frame,
)

SAMPLE_TEXT = b'STATUS: "STN1" "" 0 5 1 0 140751 "0" 0 "1"  143400 "TK5EP"'
SAMPLE = SAMPLE_TEXT + bytes([checksum(SAMPLE_TEXT)]) + b"\x00"


def test_the_published_status_sample_reads_as_14075_1_khz_from_stn1() -> None:
    status = parse_status(SAMPLE)
    assert (status.station_name, status.khz, status.operator) == ("STN1", 14075.1, "TK5EP")


def test_fields_keep_quoted_text_and_bare_numbers() -> None:
    frame = parse_frame(SAMPLE)
    assert frame.kind == "STATUS"
    assert frame.fields == ("STN1", "", 0, 5, 1, 0, 140751, "0", 0, "1", 143400, "TK5EP")


def test_escapes_in_strings_are_read() -> None:
    data = make_frame("GAB", "caf\u00e9 \"x\" \\", "")
    assert parse_frame(data).fields == ("caf\u00e9 \"x\" \\", "")
    assert b"\\351" in data, "a byte over 127 travels as three octal digits"


def test_a_frame_without_the_trailing_nul_is_read_too() -> None:
    frame = make_frame("STATUS", "RUN", "", 0, 5, 0, 0, 70255, nul=False)
    assert not frame.endswith(b"\x00")
    assert parse_status(frame).khz == 7025.5


@pytest.mark.parametrize(("data", "reason"), [
    (b"", "not_a_frame"),
    (b"\x00\xff garbage", "not_a_frame"),
    (b"status: lower case", "not_a_frame"),
    (SAMPLE_TEXT + b"\x00\x00", "checksum"),
    (SAMPLE[:-5] + SAMPLE[-2:], "checksum"),
    (b"X" * 5000, "too_large"),
    (make_frame("STATUS", "STN1", "", 0, 5, 1, 0, 3_000_000_000_000), "bad_value"),
    (make_frame("STATUS", "STN1", "", 0, 5, 1, 0, "140751"), "bad_value"),
    (make_frame("STATUS", "STN1", ""), "bad_value"),
    (make_frame("STATUS", "STN1", "", 0, 5, 1, 0, -5), "bad_value"),
    (make_frame("ADDQSO", "STN1", "", 1440000), "not_status"),
    (make_frame("STATUS", *range(80)), "not_a_frame"),
])
def test_bad_frames_are_refused_with_a_reason(data: bytes, reason: str) -> None:
    with pytest.raises(WinTestFrameError) as caught:
        parse_status(data)
    assert caught.value.reason == reason and str(caught.value)


def test_an_unclosed_quote_is_refused() -> None:
    body = b'STATUS: "STN1'
    with pytest.raises(WinTestFrameError, match="not closed"):
        parse_frame(body + bytes([checksum(body)]))


class Sender:
    def __init__(self, port: int) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.port = port

    async def send(self, listener: WinTestListener, *frames: bytes) -> None:
        target = listener.received + len(frames)
        for frame in frames:
            self.sock.sendto(frame, ("127.0.0.1", self.port))
        async with asyncio.timeout(5):
            while listener.received < target:
                await asyncio.sleep(0.005)


@pytest_asyncio.fixture
async def wintest() -> AsyncIterator[tuple[WinTestListener, Sender, list[SourceEvent]]]:
    events: list[SourceEvent] = []
    listener = WinTestListener({"STN1": (2, 1), "mult": (3, 2)}, events.append, port=0,
                               host="127.0.0.1")
    sender = Sender(await listener.start())
    yield listener, sender, events
    sender.sock.close()
    await listener.close()


@pytest.mark.asyncio
async def test_a_status_broadcast_sets_the_named_stations_radio(
    wintest: tuple[WinTestListener, Sender, list[SourceEvent]],
) -> None:
    listener, sender, events = wintest
    await sender.send(listener, SAMPLE, status_frame("MULT", 21025.0), SAMPLE)
    assert [(e.station, e.radio, e.rx_khz, e.tx_khz) for e in events
            if isinstance(e, FrequencyReport)] == [(2, 1, 14075.1, 14075.1), (3, 2, 21025.0, 21025.0)]
    assert events[0].origin == "Win-Test STN1 (127.0.0.1)"


@pytest.mark.asyncio
async def test_malformed_and_unknown_frames_change_nothing_and_log_once_each(
    wintest: tuple[WinTestListener, Sender, list[SourceEvent]],
    caplog: pytest.LogCaptureFixture,
) -> None:
    listener, sender, events = wintest
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.wintest")
    bad = [b"garbage", SAMPLE_TEXT + b"\x01\x00", b"Z" * 5000,
           make_frame("STATUS", "STN1", "", 0, 5, 1, 0, 3_000_000_000_000),
           status_frame("OTHER", 7000.0), make_frame("GAB", "STN1", "", "hello")]
    await sender.send(listener, *(bad * 3))
    await sender.send(listener, status_frame("STN1", 3525.0))
    assert [e.rx_khz for e in events if isinstance(e, FrequencyReport)] == [3525.0]
    debug = [r.getMessage() for r in caplog.records if r.levelno == logging.DEBUG]
    assert len(debug) == 5, debug
    assert listener.bad.counts == {"not_a_frame": 3, "checksum": 3, "too_large": 3,
                                   "bad_value": 3}
    assert listener.ignored == 3


@pytest.mark.asyncio
async def test_a_burst_acts_on_each_radios_newest_frequency_only() -> None:
    events: list[SourceEvent] = []
    listener = WinTestListener({"STN1": (1, 1)}, events.append, port=0, host="127.0.0.1")
    sender = Sender(await listener.start())
    try:
        listener.begin_burst()
        for khz in (14000.0, 14001.0, 14002.0):
            listener.handle(status_frame("STN1", khz), "127.0.0.1")
        listener.end_burst()
    finally:
        sender.sock.close()
        await listener.close()
    assert [e.rx_khz for e in events if isinstance(e, FrequencyReport)] == [14002.0]
    assert listener.superseded == 2


@pytest.mark.asyncio
async def test_win_test_and_another_source_for_one_radio_newest_wins(
    caplog: pytest.LogCaptureFixture,
) -> None:
    got: list[SourceEvent] = []
    hub = SourceHub(got.append)
    listener = WinTestListener({"STN1": (1, 1)}, hub, port=0, host="127.0.0.1")
    sender = Sender(await listener.start())
    caplog.set_level(logging.INFO, logger="moas_gui.sources")
    try:
        await sender.send(listener, status_frame("STN1", 14000.0))
        hub(FrequencyReport(1, 1, 7000.0, 7000.0, "rigctld 127.0.0.1:4532"))
        await sender.send(listener, status_frame("STN1", 14001.0))
    finally:
        sender.sock.close()
        await listener.close()
    assert [e.rx_khz for e in got if isinstance(e, FrequencyReport)] == [14000.0, 7000.0, 14001.0]
    assert len([r for r in caplog.records if "two sources" in r.getMessage()]) == 1


@pytest.mark.asyncio
async def test_a_sender_that_stops_and_returns_is_heard_again_without_a_restart(
    wintest: tuple[WinTestListener, Sender, list[SourceEvent]],
) -> None:
    listener, sender, events = wintest
    await sender.send(listener, status_frame("STN1", 14000.0))
    sender.sock.close()  # Win-Test quits ...
    again = Sender(sender.port)  # ... and comes back from another socket
    try:
        await again.send(listener, status_frame("STN1", 7000.0))
    finally:
        again.sock.close()
    assert [e.rx_khz for e in events if isinstance(e, FrequencyReport)] == [14000.0, 7000.0]
