"""The client server's bounds against hostile or broken peers, over real sockets on
127.0.0.1: a cap on connections, a bound on the sum of unread output, and log lines
that repeat at most once a minute however often the fault does."""

from __future__ import annotations

import asyncio
import json
import logging
import os
import socket
import sys

import pytest
from helpers import until
from test_net_server import HOST, Rig, dispose, make_rig

from moas_gui.log_limit import LogLimiter
from moas_gui.net.client import ProtocolClient
from moas_gui.net.server import ClientServer


def warnings(caplog: pytest.LogCaptureFixture, words: str) -> list[str]:
    return [r.getMessage() for r in caplog.records
            if r.levelno == logging.WARNING and words in r.getMessage()]


async def read_all(reader: asyncio.StreamReader) -> bytes:
    async with asyncio.timeout(5):
        return await reader.read()


@pytest.mark.asyncio
async def test_connections_over_the_limit_are_told_why_and_logged_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(max_clients=3)
    try:
        served = [await rig.connect(f"client {i}") for i in range(3)]
        replies: list[bytes] = []
        for _ in range(20):
            reader, writer = await asyncio.open_connection(HOST, rig.server.port)
            replies.append(await read_all(reader))
            writer.close()
        for reply in replies:
            message = json.loads(reply)
            assert message["ok"] is False and message["error"]["code"] == "unavailable"
            assert "already serves 3 clients" in message["error"]["message"]
        assert len(warnings(caplog, "--max-clients")) == 1
        assert rig.server.client_count == 3
        assert await served[2].request("stop", rotator=1) == {}
        await served[0].close()
        await until(lambda: rig.server.client_count == 2)
        assert await (await rig.connect("after one left")).request("stop", rotator=1) == {}
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_refused_address_writes_one_warning_a_minute_with_a_count(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(allow=["10.0.0.0/8"])  # 127.0.0.2 plays a computer outside it
    now = [0.0]
    rig.server.trouble = LogLimiter(60.0, clock=lambda: now[0])
    try:
        for _ in range(50):
            reader, writer = await asyncio.open_connection(HOST, rig.server.port,
                                                         local_addr=("127.0.0.2", 0))
            await read_all(reader)
            writer.close()
        assert len(warnings(caplog, "Refused a client from 127.0.0.2")) == 1
        now[0] += 61.0
        reader, writer = await asyncio.open_connection(HOST, rig.server.port,
                                                         local_addr=("127.0.0.2", 0))
        await read_all(reader)
        writer.close()
        lines = warnings(caplog, "Refused a client from 127.0.0.2")
        assert len(lines) == 2 and "(49 more refused that were not allowed" in lines[1]
    finally:
        await dispose(rig)


async def never_reading_client(port: int, hello: bytes = b"") -> socket.socket:
    """A client with a tiny receive window that never reads a byte."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.setblocking(False)
    await asyncio.get_running_loop().sock_connect(sock, (HOST, port))
    sock.send(hello)
    return sock


def keep_small_send_buffers(rig: Rig, socks: list[socket.socket]) -> None:
    """The kernel's share of the server's side of each of ``socks`` kept small (it grows to
    4 MiB on its own): what piles up waits in the server, where the bounds are, sooner."""
    ports = {sock.getsockname()[1] for sock in socks}
    for conn in rig.server._connections:
        if conn.writer.get_extra_info("peername")[1] in ports:
            conn.writer.get_extra_info("socket").setsockopt(
                socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)


@pytest.mark.asyncio
@pytest.mark.timeout(60)
async def test_the_sum_of_unread_output_is_bounded_and_the_slowest_are_cut_first(
    caplog: pytest.LogCaptureFixture,
) -> None:
    budget = 1 << 20
    rig = await make_rig(max_pending=256 * 1024, max_pending_total=budget)
    socks: list[socket.socket] = []
    try:
        healthy = await rig.connect("reads everything", log=True)
        hello = b'{"id": 1, "cmd": "hello", "client": "stuck", "log": true}\n'
        socks = [await never_reading_client(rig.server.port, hello) for _ in range(12)]
        await until(lambda: sum(i.name == "stuck" for i in rig.server.clients()) == 12)
        peak = published = 0
        while rig.server.client_count > 1 and published < 5000:
            rig.server.publish_log("info", f"{published} " + "x" * 4000)
            published += 1
            peak = max(peak, rig.server.pending_total)
            if published % 8 == 0:
                await asyncio.sleep(0)
        assert rig.server.client_count == 1, "the stuck clients were never cut off"
        assert peak <= budget + budget // 16 + 8 * 1024, f"{peak:,} bytes waited at once"
        cut = warnings(caplog, "the output waiting for all clients reached")
        assert cut, "clients were cut for the sum, before each reached its own limit"
        for number in range(published):
            assert (await healthy.next_event("log"))["message"].startswith(f"{number} ")
        assert rig.server.pending_total == 0
    finally:
        for sock in socks:
            sock.close()
        await dispose(rig)


@pytest.mark.asyncio
@pytest.mark.timeout(60)
async def test_clients_flooding_requests_they_never_read_are_cut_and_others_served_meanwhile(
    caplog: pytest.LogCaptureFixture,
) -> None:
    rig = await make_rig(max_pending=256 * 1024)
    socks: list[socket.socket] = []
    try:
        healthy = await rig.connect("reads everything")
        socks = [await never_reading_client(rig.server.port) for _ in range(10)]
        await until(lambda: rig.server.client_count == 11, what="the 10 connections taken")
        keep_small_send_buffers(rig, socks)
        requests = b'{"cmd": "state"}\n' * 2000
        for _round in range(20):
            for sock in socks:
                try:
                    sock.send(requests)
                except (BlockingIOError, ConnectionError):
                    pass
            async with asyncio.timeout(2):  # others are served all along
                assert await healthy.request("stop", rotator=1) == {}
        await until(lambda: rig.server.client_count == 1, timeout=20)
        assert len(warnings(caplog, "it stopped reading")) == 10
    finally:
        for sock in socks:
            sock.close()
        await dispose(rig)


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
@pytest.mark.skipif(sys.platform != "linux", reason="glibc's malloc_trim gives memory back")
async def test_memory_is_given_back_once_a_crowd_of_clients_has_left(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.net")
    # a crowd from one address that does not say hello, on purpose
    rig = await make_rig(per_address=100, before_hello=100)
    try:
        crowd = [await rig.connect(None) for _ in range(40)]
        await until(lambda: rig.server.client_count == 40)
        for client in crowd[:15]:
            await client.close()
        await until(lambda: rig.server.client_count == 25)
        await asyncio.sleep(0.7)
        gave = [r.getMessage() for r in caplog.records if "Gave freed memory" in r.getMessage()]
        assert gave == [], "15 of 40 leaving is no crowd gone"
        for client in crowd[15:]:
            await client.close()
        await until(lambda: any("Gave freed memory back" in r.getMessage()
                                for r in caplog.records))
    finally:
        await dispose(rig)


@pytest.mark.asyncio
@pytest.mark.skipif(sys.platform != "linux", reason="counts open files in /proc/self/fd")
@pytest.mark.timeout(60)
async def test_running_out_of_file_handles_writes_one_line_and_the_server_recovers(
    caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch,
) -> None:
    import resource

    rig = await make_rig(max_clients=1000, per_address=1000, before_hello=1000)
    listener = rig.server._server
    assert listener is not None
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    waiting: list[socket.socket] = []
    try:
        # Forty clients connect before the server runs again; then the process may open
        # only a few more files, so accepting them fails for want of file handles.
        for _ in range(40):
            sock = socket.create_connection((HOST, rig.server.port))
            waiting.append(sock)
        resource.setrlimit(resource.RLIMIT_NOFILE, (len(os.listdir("/proc/self/fd")) + 4, hard))
        try:  # the fault repeats: three more tries, each failing, each waiting longer
            await until(lambda: len(listener.pauses) >= 3, timeout=10)
        finally:
            resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
        assert listener.pauses[:3] == [0.1, 0.2, 0.4]  # backs off: no spinning
        faults = [r for r in caplog.records if "Cannot accept" in r.getMessage()]
        assert len(faults) == 1, [r.getMessage() for r in faults]
        assert faults[0].levelno == logging.WARNING and faults[0].exc_info is None
    finally:
        for sock in waiting:
            sock.close()
    try:
        await until(lambda: rig.server.client_count == 0, timeout=10)
        client = await ProtocolClient.connect(HOST, rig.server.port)
        rig.clients.append(client)
        assert await client.request("stop", rotator=1) == {}
    finally:
        await dispose(rig)


def test_max_clients_must_be_positive() -> None:
    from moas_gui.testing.fake_backend import FakeBackend

    with pytest.raises(ValueError, match="at least 1"):
        ClientServer(FakeBackend(), max_clients=0)
