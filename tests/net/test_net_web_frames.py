"""The WebSocket refuses unmasked client frames (RFC 6455, 5.1): the frame follower on
its own, and a raw socket speaking to the real web server."""

from __future__ import annotations

import asyncio
import base64
import contextlib
import json
import logging
import os

import pytest
from test_net_web import HOST, make_web

from moas_gui.net.web_frames import CLOSE_PROTOCOL_ERROR, MaskCheck


def frame(payload: bytes, *, masked: bool = True, opcode: int = 1) -> bytes:
    head = bytearray([0x80 | opcode])
    size = len(payload)
    bit = 0x80 if masked else 0
    if size < 126:
        head.append(bit | size)
    elif size < 65536:
        head.append(bit | 126)
        head += size.to_bytes(2, "big")
    else:
        head.append(bit | 127)
        head += size.to_bytes(8, "big")
    if not masked:
        return bytes(head) + payload
    key = os.urandom(4)
    return bytes(head) + key + bytes(b ^ key[i % 4] for i, b in enumerate(payload))


@pytest.mark.parametrize("sizes", [(0, 5, 125), (126, 300), (65535, 65536, 3)])
def test_masked_frames_pass_however_they_are_cut(sizes: tuple[int, ...]) -> None:
    stream = b"".join(frame(b"x" * size) for size in sizes)
    for piece in (1, 3, 7, 4096, len(stream)):
        check = MaskCheck()
        assert all(check.feed(stream[at : at + piece]) for at in range(0, len(stream), piece))


@pytest.mark.parametrize("piece", [1, 2, 5, 1000])
def test_an_unmasked_frame_is_caught_after_masked_ones(piece: int) -> None:
    stream = frame(b"a" * 200) + frame(b"") + frame(b"hello", masked=False)
    check = MaskCheck()
    results = [check.feed(stream[at : at + piece]) for at in range(0, len(stream), piece)]
    assert results[-1] is False and check.unmasked
    assert check.feed(frame(b"later")) is False  # failed for good


async def handshake(port: int) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    reader, writer = await asyncio.open_connection(HOST, port)
    key = base64.b64encode(os.urandom(16)).decode()
    writer.write(
        (
            f"GET /ws HTTP/1.1\r\nHost: {HOST}:{port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
            "Sec-WebSocket-Version: 13\r\n\r\n"
        ).encode()
    )
    async with asyncio.timeout(5):
        answer = await reader.readuntil(b"\r\n\r\n")
    assert answer.startswith(b"HTTP/1.1 101 ")
    return reader, writer


async def next_frame(reader: asyncio.StreamReader) -> tuple[int, bytes]:
    async with asyncio.timeout(5):
        head = await reader.readexactly(2)
        size = head[1] & 0x7F
        if size == 126:
            size = int.from_bytes(await reader.readexactly(2), "big")
        return head[0] & 0x0F, await reader.readexactly(size)


HELLO = json.dumps({"id": 1, "cmd": "hello", "client": "raw"}).encode()


@pytest.mark.asyncio
async def test_the_web_socket_closes_on_an_unmasked_frame_and_answers_masked_ones(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.net")
    made = await make_web()
    try:
        reader, writer = await handshake(made.web.port)  # masked: served
        writer.write(frame(HELLO))
        opcode, payload = await next_frame(reader)
        assert opcode == 1 and json.loads(payload)["id"] == 1
        writer.close()

        reader, writer = await handshake(made.web.port)  # unmasked: failed
        writer.write(frame(HELLO, masked=False))
        async with asyncio.timeout(5):
            rest = await reader.read()
        assert rest == CLOSE_PROTOCOL_ERROR  # a Close 1002 and the end; no hello answered
        writer.close()
        said = [r.getMessage() for r in caplog.records if "unmasked frame" in r.getMessage()]
        assert len(said) == 1 and "RFC 6455" in said[0]
    finally:
        with contextlib.suppress(Exception):
            writer.close()
        await made.session.close()
        await made.web.close()
        await made.clients.close()
