"""The asyncio protocol client (moas_gui.net.client) against a scripted peer on 127.0.0.1."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator

import pytest
import pytest_asyncio

from moas_gui.net.backend import ErrorCode, RequestError
from moas_gui.net.client import ConnectionClosed, ProtocolClient


class ScriptedPeer:
    """A server that answers each request line with the lines it is given."""

    def __init__(self) -> None:
        self.answers: list[bytes] = []
        self.received: list[bytes] = []
        self.server: asyncio.Server | None = None
        self.writers: list[asyncio.StreamWriter] = []

    async def start(self) -> int:
        self.server = await asyncio.start_server(self._serve, "127.0.0.1", 0)
        return int(self.server.sockets[0].getsockname()[1])

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.writers.append(writer)
        while line := await reader.readline():
            self.received.append(line)
            if self.answers:
                writer.write(self.answers.pop(0))

    async def close(self) -> None:
        for writer in self.writers:
            writer.close()
        assert self.server is not None
        self.server.close()
        await self.server.wait_closed()


@pytest_asyncio.fixture
async def peer() -> AsyncIterator[tuple[ScriptedPeer, ProtocolClient]]:
    scripted = ScriptedPeer()
    port = await scripted.start()
    client = await ProtocolClient.connect("127.0.0.1", port)
    yield scripted, client
    await client.close()
    await scripted.close()


@pytest.mark.asyncio
async def test_a_reply_is_matched_to_its_request_by_id(
    peer: tuple[ScriptedPeer, ProtocolClient],
) -> None:
    scripted, client = peer
    scripted.answers.append(b'{"event": "radio", "station": 1}\n{"id": 1, "ok": true, '
                            b'"result": {"tx": 4}}\n')
    assert await client.request("select", station=1, radio=1, antenna=4) == {"tx": 4}
    assert scripted.received == [
        b'{"id": 1, "cmd": "select", "station": 1, "radio": 1, "antenna": 4}\n']
    assert await client.next_event("radio") == {"event": "radio", "station": 1}


@pytest.mark.asyncio
async def test_an_error_reply_raises_request_error(
    peer: tuple[ScriptedPeer, ProtocolClient],
) -> None:
    scripted, client = peer
    scripted.answers.append(b'{"id": 1, "ok": false, "error": {"code": "not_found", '
                            b'"message": "there is no antenna 9"}}\n')
    with pytest.raises(RequestError) as caught:
        await client.request("select", station=1, radio=1, antenna=9)
    assert (caught.value.code, caught.value.message) == ("not_found", "there is no antenna 9")


@pytest.mark.asyncio
async def test_an_error_code_from_a_later_protocol_is_kept_in_the_message(
    peer: tuple[ScriptedPeer, ProtocolClient],
) -> None:
    scripted, client = peer
    scripted.answers.append(b'{"id": 1, "ok": false, "error": {"code": "busy", '
                            b'"message": "try later"}}\n')
    with pytest.raises(RequestError) as caught:
        await client.request("state")
    assert caught.value.code is ErrorCode.INTERNAL and caught.value.message == "busy: try later"


@pytest.mark.asyncio
async def test_replies_nobody_waits_for_go_to_stray_and_garbage_is_skipped(
    peer: tuple[ScriptedPeer, ProtocolClient], caplog: pytest.LogCaptureFixture,
) -> None:
    scripted, client = peer
    scripted.answers.append(b'not json\n[1]\n{"id": null, "ok": false}\n{"id": true, "ok": true}\n'
                            b'{"id": 1, "ok": true, "result": {}}\n')
    assert await client.request("stop", rotator=1) == {}
    assert client.stray.get_nowait() == {"id": None, "ok": False}
    assert client.stray.get_nowait() == {"id": True, "ok": True}
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 2 and "not JSON" in warnings[0]


@pytest.mark.asyncio
async def test_a_server_sending_garbage_without_end_writes_a_line_a_minute_per_kind(
    peer: tuple[ScriptedPeer, ProtocolClient], caplog: pytest.LogCaptureFixture,
) -> None:
    scripted, client = peer
    scripted.answers.append(b"not json\n[1]\n" * 5_000 + b'{"id": 1, "ok": true, "result": {}}\n')
    assert await client.request("stop", rotator=1) == {}
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 2, warnings[:5]
    assert "not JSON" in warnings[0] and "not an object" in warnings[1]


@pytest.mark.asyncio
async def test_a_closed_connection_fails_the_waiting_request(
    peer: tuple[ScriptedPeer, ProtocolClient],
) -> None:
    scripted, client = peer
    waiting = asyncio.create_task(client.request("state"))
    async with asyncio.timeout(5):
        while not scripted.received:
            await asyncio.sleep(0.005)
    await scripted.close()
    with pytest.raises(ConnectionClosed):
        await asyncio.wait_for(waiting, 5)
    with pytest.raises(ConnectionClosed):
        await client.request("state")
