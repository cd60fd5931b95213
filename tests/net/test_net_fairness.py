"""Fair service under hostile peers, over real sockets on 127.0.0.x: a per-address limit
shared by the client port and the web port, the hello deadline and the keepalive of both
transports, the web port's request deadline, and aiohttp's own log lines kept short.
(The whole attack against a real server process: tests/faults/test_fault_hostile_load.py.)"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from typing import Any

import aiohttp
import pytest
from helpers import until
from test_net_server import HOST, dispose, make_rig
from test_net_web import make_web, receive

from moas_gui.client.connection import ClientConnection
from moas_gui.net.client import ProtocolClient

ATTACKER = "127.0.0.2"


async def from_address(port: int, source: str = ATTACKER) -> tuple[asyncio.StreamReader,
                                                                    asyncio.StreamWriter]:
    return await asyncio.open_connection(HOST, port, local_addr=(source, 0))


async def closed(reader: asyncio.StreamReader) -> bytes:
    """What the server said before it closed the connection."""
    async with asyncio.timeout(10):
        return await reader.read()


async def shut(writer: asyncio.StreamWriter) -> None:
    """Closes a connection and waits until it is closed (none is left to the loop's end)."""
    writer.close()
    with contextlib.suppress(OSError):
        await writer.wait_closed()


def lines(caplog: pytest.LogCaptureFixture, words: str) -> list[logging.LogRecord]:
    return [r for r in caplog.records if words in r.getMessage()]


@pytest.mark.asyncio
async def test_one_address_over_its_limit_is_refused_while_another_is_served(
        caplog: pytest.LogCaptureFixture) -> None:
    made = await make_web(per_address=4, max_clients=50)
    held: list[asyncio.StreamWriter] = []
    try:
        for _ in range(2):  # two on the client port, two on the web port: the four allowed
            held.append((await from_address(made.clients.port))[1])
            held.append((await from_address(made.web.port))[1])
        await until(lambda: made.clients.admission.open_from(ATTACKER) == 4)
        reader, writer = await from_address(made.clients.port)
        refusal = json.loads(await closed(reader))
        assert refusal["error"]["code"] == "unavailable"
        assert "this address already holds 4 connections" in refusal["error"]["message"]
        await shut(writer)
        reader, writer = await from_address(made.web.port)
        assert (await closed(reader)).startswith(b"HTTP/1.1 503 ")
        await shut(writer)
        # 127.0.0.1 is another address: served on both ports
        client = await ProtocolClient.connect(HOST, made.clients.port)
        assert (await client.request("hello", client="legit"))["server"] == "moas-gui"
        async with made.session.get(f"http://{HOST}:{made.web.port}/") as page:
            assert page.status == 200
        await client.close()
        refused = lines(caplog, "--max-per-address")
        assert len(refused) == 1 and refused[0].levelno == logging.WARNING
    finally:
        for writer in held:
            await shut(writer)
        await made.session.close()
        await made.web.close()
        await made.clients.close()
    assert made.clients.admission.count == 0


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_a_connection_that_never_says_hello_is_closed(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    rig = await make_rig(hello_deadline=0.3)
    try:
        silent = [await from_address(rig.server.port) for _ in range(5)]
        for reader, writer in silent:
            assert await closed(reader) == b""
            await shut(writer)
        await until(lambda: rig.server.admission.count == 0)
        said = lines(caplog, "no hello within 0.3 s")
        assert len(said) == 1, [r.getMessage() for r in said]  # once a minute, for five
        # a client that says hello in time stays
        client = await ProtocolClient.connect(HOST, rig.server.port)
        rig.clients.append(client)
        await client.request("hello", client="in time")
        await asyncio.sleep(0.6)
        assert await client.request("stop", rotator=1) == {}
    finally:
        await dispose(rig)


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_a_silent_client_is_closed_and_the_projects_client_keeps_itself_alive(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    rig = await make_rig(keepalive=0.5)
    connection = ClientConnection(HOST, rig.server.port, name="desktop", keepalive=0.15)
    try:
        silent = await ProtocolClient.connect(HOST, rig.server.port)
        rig.clients.append(silent)
        await silent.request("hello", client="silent")
        connection.start()
        await connection.wait_connected(5)
        await until(lambda: silent.closed.is_set(), timeout=10)
        assert lines(caplog, '"silent"') and "silent for 0.5 s" in lines(
            caplog, 'Client "silent"')[-1].getMessage()
        await asyncio.sleep(1.5)  # three keepalives' worth: the desktop client is still there
        assert connection.connects == 1
        assert [c.name for c in rig.server.clients()] == ["desktop"]
    finally:
        await connection.aclose()
        await dispose(rig)


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_a_websocket_has_the_same_hello_deadline_and_keepalive() -> None:
    made = await make_web(hello_deadline=0.3, keepalive=0.6)
    try:
        mute = await made.socket()
        message = await mute.receive(10)
        assert message.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED)
        page = await made.socket()
        await page.send_str('{"id": 1, "cmd": "hello", "client": "page"}')
        assert (await receive(page))["ok"]
        for _ in range(6):  # an empty message now and then is enough
            await asyncio.sleep(0.2)
            await page.send_str("")
        assert made.clients.client_count == 1
        while (await page.receive(10)).type is aiohttp.WSMsgType.TEXT:
            pass  # events, until the silence closes it
        await until(lambda: made.clients.client_count == 0)
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


async def slow_request(port: int, head: bytes) -> bytes:
    reader, writer = await asyncio.open_connection(HOST, port)
    writer.write(head)
    try:
        return await closed(reader)
    finally:
        await shut(writer)


@pytest.mark.asyncio
async def test_a_request_that_never_completes_is_closed(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.net")
    made = await make_web(request_deadline=0.3)
    try:
        port = made.web.port
        # headers never finished, a body never sent, a kept-alive connection left idle
        half = slow_request(port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")
        body = slow_request(port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                                  b"Content-Length: 100\r\n\r\nabc")
        idle = slow_request(port, b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        nothing = slow_request(port, b"")
        said = await asyncio.gather(half, body, idle, nothing)
        assert said[0] == b"" and said[3] == b""
        assert said[1].startswith(b"HTTP/1.1 200") and said[2].startswith(b"HTTP/1.1 200")
        await until(lambda: made.clients.admission.count == 0)
        assert len(lines(caplog, "no complete request within")) == 1
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


@pytest.mark.asyncio
async def test_malformed_requests_write_one_short_line(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    made = await make_web()
    try:
        port = made.web.port
        bad = [b"GET / HTTP/1.1\r\n\r\n",  # no Host
               b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: 127.0.0.1\r\n\r\n",
               b"GET /" + b"a" * 9000 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
               b"GET * HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"] * 25
        for head in bad:
            reader, writer = await asyncio.open_connection(HOST, port)
            writer.write(head)
            await closed(reader)
            await shut(writer)
        from_aiohttp = [r for r in caplog.records if r.name.startswith("aiohttp")]
        assert all(r.exc_info is None and "Traceback" not in r.getMessage()
                   for r in from_aiohttp)
        kinds: dict[Any, int] = {}
        for record in from_aiohttp:
            key = (record.name, record.getMessage().split(": ")[1])  # the exception's name
            kinds[key] = kinds.get(key, 0) + 1
        assert all(count == 1 for count in kinds.values()), kinds
        assert len(from_aiohttp) <= 4
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


@pytest.mark.asyncio
async def test_the_origin_must_be_the_served_one_and_only_one() -> None:
    made = await make_web()
    try:
        url = f"http://{HOST}:{made.web.port}/ws"
        for headers in ({"Origin": f"https://{HOST}:{made.web.port}"},
                        {"Origin": f"http://{HOST}:{made.web.port + 1}"}):
            with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                await made.session.ws_connect(url, headers=headers)
            assert refused.value.status == 403
        # two Origin headers, the first of them right: refused
        reader, writer = await asyncio.open_connection(HOST, made.web.port)
        writer.write(f"GET /ws HTTP/1.1\r\nHost: {HOST}:{made.web.port}\r\n"
                     f"Origin: http://{HOST}:{made.web.port}\r\nOrigin: http://evil.example\r\n"
                     "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                     "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n".encode())
        assert (await reader.readline()).startswith(b"HTTP/1.1 403")
        await shut(writer)
        ws = await made.session.ws_connect(url, headers={"Origin": f"http://{HOST}:{made.web.port}"})
        await ws.send_str('{"id": 1, "cmd": "hello", "client": "page"}')
        assert (await receive(ws))["ok"]
        await ws.close()
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


@pytest.mark.asyncio
async def test_programs_greeting_in_a_loop_from_many_addresses_share_one_log_budget(
        caplog: pytest.LogCaptureFixture) -> None:
    from moas_gui.net.server import CHATTER_BURST

    caplog.set_level(logging.INFO, logger="moas_gui.net")
    rig = await make_rig()
    sources = [f"127.0.0.{n}" for n in range(2, 6)]
    try:
        for n in range(CHATTER_BURST):  # a hello and a goodbye each: twice the share
            reader, writer = await from_address(rig.server.port, sources[n % len(sources)])
            writer.write(b'{"id": 1, "cmd": "hello", "client": "loop"}\n')
            await reader.readline()
            await shut(writer)
            await until(lambda: rig.server.admission.count == 0)
        about = [r.getMessage() for r in caplog.records
                 if any(f"{source}:" in r.getMessage() for source in sources)]
        assert len(about) == CHATTER_BURST, len(about)  # four addresses, one share
        # another address is within the same share: nothing more this minute
        client = await ProtocolClient.connect(HOST, rig.server.port)
        rig.clients.append(client)
        await client.request("hello", client="other")
        assert not any('is "other"' in r.getMessage() for r in caplog.records)
    finally:
        await dispose(rig)


def test_aiohttp_lines_lose_their_traceback_except_at_debug() -> None:
    from moas_gui.net.web_limits import QuietAiohttp

    logger = logging.getLogger("aiohttp.server")
    quiet = QuietAiohttp()
    try:
        raise ValueError("bad\n  request line")
    except ValueError as exc:
        error = exc
    saved = logger.level
    try:
        for level, kept in ((logging.INFO, False), (logging.DEBUG, True)):
            logger.setLevel(level)
            record = logger.makeRecord("aiohttp.server", logging.ERROR, __file__, 1,
                                       "Error handling request from %s", ("127.0.0.2",),
                                       (type(error), error, error.__traceback__))
            quiet.limiter = type(quiet.limiter)()  # a fresh minute for each level
            assert quiet.filter(record)
            assert (record.exc_info is not None) is kept
            if not kept:
                assert record.getMessage() == ("Error handling request from 127.0.0.2: "
                                               "ValueError: bad request line")
                assert record.levelno == logging.WARNING
            # the same kind again within the minute: held back
            again = logger.makeRecord("aiohttp.server", logging.ERROR, __file__, 1,
                                      "Error handling request from %s", ("127.0.0.3",),
                                      (type(error), error, error.__traceback__))
            assert not quiet.filter(again)
    finally:
        logger.setLevel(saved)


@pytest.mark.asyncio
async def test_a_browsers_preconnect_that_sends_nothing_is_closed_at_debug_only(
        caplog: pytest.LogCaptureFixture) -> None:
    """Chromium opens a connection ahead and never uses it: it is closed at the deadline
    like any other, but that is no trouble for the Info log (issue 30)."""
    caplog.set_level(logging.DEBUG, logger="moas_gui.net")
    made = await make_web(request_deadline=0.3)
    try:
        assert await slow_request(made.web.port, b"") == b""
        await until(lambda: made.clients.admission.count == 0)
        closed_lines = [r for r in caplog.records if "a browser's preconnect" in r.getMessage()]
        assert len(closed_lines) == 1 and closed_lines[0].levelno == logging.DEBUG
        assert not lines(caplog, "no complete request within")
        assert not [r for r in caplog.records if r.levelno >= logging.INFO
                    and "web connection" in r.getMessage()]
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()
