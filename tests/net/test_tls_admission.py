"""The TLS handshake inside the admission policy, over real sockets on loopback addresses
with a real :class:`ClientServer` and :class:`WebServer` serving TLS: a connection takes
its place (its address's reserve) on the bare socket, before its handshake; one over the
reserve is closed before a byte of TLS; a handshake that never finishes gives its place
back when it ends; and silent connections never hold the accept loop."""

from __future__ import annotations

import asyncio
import json
import socket
import ssl
from pathlib import Path

import pytest
from helpers import until

from moas_gui.edge.admission import Standing
from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.tls import Certificate, client_context, make_self_signed, server_context

pytestmark = pytest.mark.realtime

HOST = "127.0.0.1"


def tls_context(tmp_path: Path) -> ssl.SSLContext:
    where = Certificate(tmp_path / "cert.pem", tmp_path / "key.pem")
    make_self_signed(where, "localhost")
    return server_context(where)


async def silent(port: int, source: str) -> socket.socket:
    """A TCP connection from ``source`` that never sends a byte (never starts TLS)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setblocking(False)
    sock.bind((source, 0))
    await asyncio.get_running_loop().sock_connect(sock, (HOST, port))
    return sock


async def tls_hello(port: int, source: str = HOST) -> dict[str, object]:
    async with asyncio.timeout(30):  # far less than the minute a stuck handshake once took
        reader, writer = await asyncio.open_connection(
            HOST, port, ssl=client_context(), local_addr=(source, 0),
            server_hostname="localhost")
        try:
            writer.write(b'{"id": 1, "cmd": "hello", "client": "tls test"}\n')
            while True:
                reply = json.loads(await reader.readline())
                if reply.get("id") == 1:
                    return reply  # type: ignore[no-any-return]
        finally:
            writer.close()


async def closed_by_server(sock: socket.socket) -> bool:
    """Whether the server closed ``sock`` (end of stream or a reset) without a byte."""
    try:
        data = await asyncio.get_running_loop().sock_recv(sock, 1024)
    except ConnectionError:
        return True
    return data == b""


@pytest.mark.asyncio
async def test_a_connection_in_its_handshake_takes_its_address_reserve(tmp_path: Path) -> None:
    # a long hello deadline: the handshakes stay under way for the whole test
    server = ClientServer(FakeBackend(), host=HOST, port=0, tls=tls_context(tmp_path),
                          before_hello=4, hello_deadline=120.0)
    port = await server.start()
    held: list[socket.socket] = []
    try:
        held += [await silent(port, "127.0.0.3") for _ in range(4)]
        await until(lambda: server.admission.open_from("127.0.0.3") == 4, timeout=30,
                    what="four handshakes under way, admitted")
        assert all(t.standing is Standing.NEW for t in server.admission.tickets())
        # the fifth from that address: closed on the bare socket, no handshake started
        fifth = await silent(port, "127.0.0.3")
        held.append(fifth)
        async with asyncio.timeout(30):
            assert await closed_by_server(fifth)
        assert server.admission.open_from("127.0.0.3") == 4
        # and over TLS it fails the same way, while another address is served
        with pytest.raises((ConnectionError, ssl.SSLError)):
            await tls_hello(port, "127.0.0.3")
        reply = await tls_hello(port, "127.0.0.4")
        assert reply["ok"] is True, reply
        # handshakes given up by their peers give their places back
        for sock in held:
            sock.close()
        held.clear()
        await until(lambda: server.admission.open_from("127.0.0.3") == 0, timeout=30,
                    what="the abandoned handshakes' places given back")
    finally:
        for sock in held:
            sock.close()
        await server.close()


@pytest.mark.asyncio
async def test_a_silent_handshake_is_closed_by_its_deadline_and_its_place_freed(
        tmp_path: Path) -> None:
    server = ClientServer(FakeBackend(), host=HOST, port=0, tls=tls_context(tmp_path),
                          hello_deadline=0.5)
    port = await server.start()
    try:
        sock = await silent(port, "127.0.0.5")
        async with asyncio.timeout(30):
            assert await closed_by_server(sock)
        sock.close()
        await until(lambda: server.admission.open_from("127.0.0.5") == 0, timeout=30,
                    what="the late handshake's place given back")
    finally:
        await server.close()


@pytest.mark.asyncio
async def test_silent_crowds_hold_neither_port_while_a_loopback_client_is_served(
        tmp_path: Path) -> None:
    # the default deadlines: the silent ones stay silent for the whole of the checks
    server = ClientServer(FakeBackend(), host=HOST, port=0, tls=tls_context(tmp_path),
                          hello_deadline=120.0)
    port = await server.start()
    web = WebServer(server, host=HOST, port=0, request_deadline=120.0)
    web_port = await web.start()
    held: list[socket.socket] = []
    try:
        # far more than the accept loop ever waited for, from one address then ten
        for sources in (["127.0.0.2"], [f"127.0.0.{n}" for n in range(2, 12)]):
            for source in sources:
                for each in (port, web_port):
                    held += [await silent(each, source) for _ in range(50)]
            reply = await tls_hello(port)
            assert reply["ok"] is True, reply
            reader, writer = await asyncio.open_connection(
                HOST, web_port, ssl=client_context(), server_hostname="localhost")
            writer.write(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
            async with asyncio.timeout(30):
                head = await reader.readline()
            writer.close()
            assert head.startswith(b"HTTP/1.1 200"), head
    finally:
        for sock in held:
            sock.close()
        await web.close()
        await server.close()


@pytest.mark.asyncio
async def test_a_handshake_under_way_gives_its_place_to_the_fair_share(tmp_path: Path) -> None:
    # the server full of handshakes from one address: a newcomer from another takes the
    # place of the one waiting longest, whose handshake is ended there and then
    server = ClientServer(FakeBackend(), host=HOST, port=0, tls=tls_context(tmp_path),
                          max_clients=3, hello_deadline=120.0)
    port = await server.start()
    held: list[socket.socket] = []
    try:
        held += [await silent(port, "127.0.0.6") for _ in range(3)]
        await until(lambda: server.admission.open_from("127.0.0.6") == 3, timeout=30,
                    what="three handshakes admitted")
        reply = await tls_hello(port, "127.0.0.7")
        assert reply["ok"] is True, reply
        async with asyncio.timeout(30):
            assert await closed_by_server(held[0])  # the one waiting longest
        assert server.admission.open_from("127.0.0.6") == 2
    finally:
        for sock in held:
            sock.close()
        await server.close()
