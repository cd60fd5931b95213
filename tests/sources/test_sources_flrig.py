"""The flrig source against a stand-in flrig (tests/sources/flrig_fake.py) over real HTTP on loopback.

flrig is a window program (Debian has it, but it needs a display and a rig),
so the tests use a small XML-RPC server answering the same methods with the
same types.  The recorded answer below is the form flrig's XmlRpc++ server
writes (its ``Server: XMLRPC++ 0.8`` head, as in the public Hamlib flrig
backend trace, gist.github.com/tedwardd/bade7d94fadd69842451e313370accbb;
``rig.get_vfo`` answers a string of Hz, xml_server.cxx).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator

import pytest
import pytest_asyncio
from flrig_fake import FakeFlrig

from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import FrequencyReport, SourceHub
from moas_gui.sources.flrig import FlrigSource
from moas_gui.sources.flrig_rpc import FlrigReplyError, ResponseParser, flag, hz, request

BODY = (b"<?xml version=\"1.0\"?>\r\n<methodResponse><params><param>\r\n\t"
        b"<value>14070000</value>\r\n</param></params></methodResponse>\r\n")
RECORDED = (b"HTTP/1.1 200 OK\r\nServer: XMLRPC++ 0.8\r\nContent-Type: text/xml\r\n"
            b"Content-length: " + str(len(BODY)).encode() + b"\r\n\r\n" + BODY)


def test_the_recorded_answer_reads_as_a_string_of_hz() -> None:
    parser = ResponseParser()
    assert parser.feed(RECORDED) == ["14070000"]
    assert hz("14070000", "rig.get_vfo") == 14070000
    assert not parser.closing


def test_two_answers_in_pieces() -> None:
    parser = ResponseParser()
    data = RECORDED * 2
    values = [v for i in range(0, len(data), 7) for v in parser.feed(data[i:i + 7])]
    assert values == ["14070000", "14070000"]


def test_the_request_is_an_http_post_of_the_method() -> None:
    text = request("rig.get_vfo", "127.0.0.1", 12345).decode()
    assert text.startswith("POST /RPC2 HTTP/1.1\r\n")
    assert "<methodName>rig.get_vfo</methodName>" in text


@pytest.mark.parametrize(("data", "reason"), [
    (b"garbage\r\n\r\n", "not_http"),
    (b"HTTP/1.1 500 Oops\r\nContent-Length: 0\r\n\r\n", "http_status"),
    (b"HTTP/1.1 200 OK\r\n\r\n", "no_length"),
    (b"HTTP/1.1 200 OK\r\nContent-Length: 99999999\r\n\r\n", "too_long"),
    (b"X" * 9000, "too_long"),
    (RECORDED.replace(b"<value>14070000", b"<value>1407<oops"), "not_xmlrpc"),
])
def test_malformed_answers_are_refused_with_a_reason(data: bytes, reason: str) -> None:
    with pytest.raises(FlrigReplyError) as refused:
        ResponseParser().feed(data)
    assert refused.value.reason == reason


def test_a_document_with_entities_is_refused_before_parsing() -> None:
    body = (b'<?xml version="1.0"?><!DOCTYPE lol [<!ENTITY a "aaaaaaaa">]>'
            b"<methodResponse><params><param><value>&a;</value></param></params>"
            b"</methodResponse>")
    data = b"HTTP/1.1 200 OK\r\nContent-Length: " + str(len(body)).encode() + b"\r\n\r\n" + body
    with pytest.raises(FlrigReplyError) as refused:
        ResponseParser().feed(data)
    assert refused.value.reason == "entities"


@pytest.mark.parametrize("value", ["0", "-5", "1e30", "nan", "VFOA", True, None])
def test_absurd_frequencies_are_refused(value: object) -> None:
    with pytest.raises(FlrigReplyError):
        hz(value, "rig.get_vfo")


def test_split_and_ptt_flags() -> None:
    assert (flag(1, "x"), flag("0", "x"), flag(False, "x")) == (True, False, False)
    with pytest.raises(FlrigReplyError):
        flag(2, "rig.get_ptt")


class Events(list[FrequencyReport]):
    async def until(self, check: object, timeout: float = 5.0) -> FrequencyReport:
        async def wait() -> FrequencyReport:
            while True:
                for event in reversed(self):
                    if check(event):  # type: ignore[operator]
                        return event
                await asyncio.sleep(0.01)
        return await asyncio.wait_for(wait(), timeout)


@pytest_asyncio.fixture
async def flrig() -> AsyncIterator[tuple[FakeFlrig, FlrigSource, Events]]:
    fake = FakeFlrig()
    port = await fake.start()
    events = Events()
    source = FlrigSource(4, 2, events.append, port=port, interval=0.02, timeout=1.0)
    source._backoff = Pauses(Backoff(first=0.01, most=0.02))  # a daemon back is found at once
    await source.start()
    yield fake, source, events
    await source.close()
    await fake.close()


@pytest.mark.asyncio
async def test_the_radio_and_its_split_reach_the_sink(flrig: tuple) -> None:
    fake, _source, events = flrig
    first = await events.until(lambda e: True)
    assert (first.station, first.radio, first.rx_khz, first.tx_khz) == (4, 2, 14070.0, 14070.0)
    assert first.origin == f"flrig 127.0.0.1:{fake.port}"
    fake.rig.update(split=1)
    split = await events.until(lambda e: e.tx_khz == 14075.0)
    assert split.rx_khz == 14070.0
    fake.rig.update(AB="B", ptt=1)
    swapped = await events.until(lambda e: e.rx_khz == 14075.0)
    assert (swapped.tx_khz, swapped.transmitting) == (14070.0, True)
    assert fake.connections == 1  # one kept-alive connection for every call


@pytest.mark.asyncio
async def test_a_server_that_closes_after_each_answer_is_followed_quietly(
        flrig: tuple, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources")
    fake, _source, events = flrig
    fake.close_each = True
    await events.until(lambda e: True)
    fake.rig.update(vfoA=7030000)
    await events.until(lambda e: e.rx_khz == 7030.0)
    assert fake.connections > 3
    assert [r for r in caplog.records if r.levelno >= logging.WARNING] == []


@pytest.mark.asyncio
async def test_flrig_that_goes_away_and_returns_is_logged_once_each_way(
        flrig: tuple, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources")
    fake, source, events = flrig
    await events.until(lambda e: True)
    await fake.close()
    while source.link.failures < 4:
        await asyncio.sleep(0.02)
    fake.rig.update(vfoA=21025000)
    await fake.start(fake.port)
    await events.until(lambda e: e.rx_khz == 21025.0)
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and "flrig at 127.0.0.1" in warnings[0]
    assert sum("is back" in r.getMessage() for r in caplog.records) == 1


@pytest.mark.asyncio
async def test_garbage_answers_reach_nothing(flrig: tuple,
                                             caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources")
    fake, source, events = flrig
    await events.until(lambda e: True)
    before = len(events)
    fake.garbage = b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello"
    while source.bad.total < 3:
        await asyncio.sleep(0.02)
    fake.rig.update(vfoA=3525000)
    seen = source.bad.total  # two more polls after the change, both answered with garbage
    await until_true(lambda: source.bad.total >= seen + 2)
    assert len(events) == before
    assert len([r for r in caplog.records if "dropped" in r.getMessage()]) == 1


@pytest.mark.asyncio
async def test_two_rig_daemons_for_one_radio_the_newest_wins_logged_once(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.sources")
    first, second = FakeFlrig(), FakeFlrig()
    second.rig.update(vfoA=7010000)
    delivered: list[FrequencyReport] = []
    hub = SourceHub(delivered.append)  # type: ignore[arg-type]
    sources = [FlrigSource(1, 1, hub, port=await fake.start(), interval=0.02)
               for fake in (first, second)]
    try:
        for source in sources:
            await source.start()
        await until_true(lambda: {r.rx_khz for r in delivered} >= {14070.0, 7010.0})
        first.rig.update(vfoA=14080000)
        await until_true(lambda: delivered[-1].rx_khz == 14080.0)
        second.rig.update(vfoA=7020000)
        await until_true(lambda: delivered[-1].rx_khz == 7020.0)
    finally:
        for source in sources:
            await source.close()
        for fake in (first, second):
            await fake.close()
    lines = [r.getMessage() for r in caplog.records if "two sources" in r.getMessage()]
    assert len(lines) == 1 and f"flrig 127.0.0.1:{first.port}" in lines[0]
    assert hub.overlaps >= 3


async def until_true(check: object, timeout: float = 5.0) -> None:
    async def wait() -> None:
        while not check():  # type: ignore[operator]
            await asyncio.sleep(0.01)
    await asyncio.wait_for(wait(), timeout)
