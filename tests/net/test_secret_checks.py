"""Secret checks off the loop, on one bounded worker, budgeted per address and per
operator (moas_gui/net/secrets.py), through a real client server on real sockets: a
flood of wrong hellos carrying a real key id leaves the loop serving, a known device
is not held back by a guesser, a full worker answers "busy", an unknown key id costs
the hash a known one does, and an operators file that is a FIFO or 1 GB neither hangs
nor blocks a hello."""

from __future__ import annotations

import asyncio
import json
import os
import threading
from pathlib import Path
from typing import Any

import pytest
from helpers import until

import moas_gui.operators as operators_module
from moas_gui.edge.admission import PATIENCE
from moas_gui.net.backend import ErrorCode, RequestError
from moas_gui.net.client import ProtocolClient
from moas_gui.net.secrets import (
    ADDRESS_FREE,
    BACKOFF_CAP,
    FailureBackoff,
    SecretGuard,
    SecretWorker,
    budget_key,
    delay,
)
from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer
from moas_gui.operators import KnownDevices, OperatorBook, Role
from moas_gui.testing.fake_backend import FakeBackend

HOST = "127.0.0.1"
GUESSER = "127.0.0.2"
DEVICE = "127.0.0.3"
ALLOW = ["127.0.0.0/8"]


class HashCount:
    """Counts the scrypt hashes made (the real ones: it only wraps them)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.made = 0
        self._lock = threading.Lock()
        real = operators_module._hash

        def counted(secret: str, salt: bytes) -> bytes:
            with self._lock:
                self.made += 1
            return real(secret, salt)

        monkeypatch.setattr(operators_module, "_hash", counted)


async def serve(book: OperatorBook, **options: Any) -> ClientServer:
    backend = FakeBackend()
    server = ClientServer(backend, host=HOST, port=0, allow=ALLOW, require_token=True,
                          operators=book, **options)
    backend.attach(server)
    await server.start()
    return server


async def hello(port: int, token: str | None, source: str = HOST) -> dict[str, Any]:
    """One hello on a new connection; the reply."""
    reader, writer = await asyncio.open_connection(HOST, port, local_addr=(source, 0))
    try:
        message: dict[str, Any] = {"id": 1, "cmd": "hello", "client": "t"}
        if token is not None:
            message["token"] = token
        writer.write(json.dumps(message).encode() + b"\n")
        while True:
            line = await asyncio.wait_for(reader.readline(), 30)
            if not line:
                return {"closed": True}
            reply: dict[str, Any] = json.loads(line)
            if reply.get("id") == 1:
                return reply
    finally:
        writer.close()


def wrong_secret(token: str, n: int) -> str:
    """The token's key id with a wrong secret."""
    return token.rsplit(".", 1)[0] + "." + f"guess{n:06d}".ljust(43, "x")


# -- the rules, alone --------------------------------------------------------------------

def test_the_back_off_doubles_from_one_second_to_a_minute_and_spares_the_free_budget() -> None:
    assert [delay(n) for n in range(1, 9)] == [1, 2, 4, 8, 16, 32, 60, 60]
    keys = FailureBackoff()
    keys.failed("k", 100.0)
    assert keys.wait("k", 100.0) == 1.0 and keys.wait("k", 101.0) == 0.0
    for _ in range(20):
        keys.failed("k", 200.0)
    assert keys.wait("k", 200.0) == BACKOFF_CAP
    addresses = FailureBackoff(ADDRESS_FREE)
    for _ in range(ADDRESS_FREE):
        addresses.failed("a", 0.0)
    assert addresses.wait("a", 0.0) == 0.0  # the free budget: no wait yet
    addresses.failed("a", 0.0)
    assert addresses.wait("a", 0.0) == 1.0


def test_an_ipv6_64_is_one_address_and_ipv4_is_itself() -> None:
    assert budget_key("2001:db8:1:2::1") == budget_key("2001:db8:1:2:ffff:1:2:3") \
        == "2001:db8:1:2::/64"
    assert budget_key("2001:db8:1:3::1") != budget_key("2001:db8:1:2::1")
    assert budget_key("fe80::1%eth0") == "fe80::/64"
    assert budget_key("::ffff:192.0.2.7") == "192.0.2.7"
    assert budget_key("192.0.2.7") != budget_key("192.0.2.8")


@pytest.mark.asyncio
async def test_failures_from_a_whole_64_share_one_budget() -> None:
    guard = SecretGuard(codes={"471100": "Ann"})
    try:
        # signed in once from this /64: the codes' common back-off spares it, its own
        # budget does not
        assert (await guard.check_code("471100", "2001:db8:0:1::1")).ok
        for n in range(ADDRESS_FREE + 1):  # each from another address of that /64
            verdict = await guard.check_code("000000", f"2001:db8:0:1::{n + 2:x}")
            assert not verdict.ok and verdict.wait == 0
        held = await guard.check_code("471100", "2001:db8:0:1:abcd::9")  # the right code
        assert not held.ok and "try again" in (held.refusal or "")
        other = await guard.check_code("471100", "2001:db8:0:2::1")  # the next /64
        assert other.ok and other.name == "Ann"
    finally:
        guard.close()


@pytest.mark.asyncio
async def test_an_unknown_key_id_costs_the_one_hash_a_known_one_does(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    hashes = HashCount(monkeypatch)
    assert book.check(wrong_secret(token, 1)) is None
    assert hashes.made == 1
    unknown = "moas1.0badf00d." + token.rsplit(".", 1)[1]
    assert book.check(unknown) is None
    assert hashes.made == 2  # the same hash, against a dummy: no timing oracle
    assert book.check(token) is not None and hashes.made == 3


# -- the operators file ---------------------------------------------------------------------

@pytest.mark.asyncio
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX")
async def test_a_fifo_or_a_huge_operators_file_neither_hangs_nor_blocks_a_hello(
        tmp_path: Path) -> None:
    path = tmp_path / "operators.json"
    book = OperatorBook(path)
    _op, token = book.add("otto", Role.OPERATE)
    path.unlink()
    os.mkfifo(path)  # no writer: opening it for reading the ordinary way waits for ever
    server = await serve(book)
    try:
        refused = await hello(server.port, token, GUESSER)
        assert refused["error"]["code"] == "forbidden"
        assert (await hello(server.port, None, HOST))["ok"]  # this computer: served
        with pytest.raises(operators_module.OperatorError, match="FIFO"):
            book.operators()
        path.unlink()
        with path.open("wb") as huge:  # 1 GB, sparse: nothing of it is read
            huge.truncate(1 << 30)
        refused = await hello(server.port, token, DEVICE)
        assert refused["error"]["code"] == "forbidden"
        assert (await hello(server.port, None, HOST))["ok"]
        with pytest.raises(operators_module.OperatorError, match="1,073,741,824 bytes"):
            book.operators()
    finally:
        await server.close()


def test_the_file_is_read_again_only_when_it_changed(tmp_path: Path,
                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    book.add("otto", Role.OPERATE)
    reads: list[Path] = []
    real = operators_module.read_operators_file

    def counted(path: Path, limit: int = operators_module.MAX_FILE_BYTES) -> bytes | None:
        reads.append(path)
        return real(path, limit)

    monkeypatch.setattr(operators_module, "read_operators_file", counted)
    for _ in range(5):
        assert [op.name for op in book.operators()] == ["otto"]
    assert len(reads) == 1
    OperatorBook(book.path).add("vera", Role.VIEW)  # another process's change
    before = len(reads)
    assert [op.name for op in book.operators()] == ["otto", "vera"]
    assert len(reads) == before + 1


# -- through the client port -----------------------------------------------------------------

@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_the_loop_serves_while_80_wrong_hellos_a_second_carry_a_real_key_id(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """One LAN address sends 80 hellos a second with otto's key id and wrong secrets;
    meanwhile a program on this computer and otto's own device both say hello and are
    served, and the flood costs a few hashes, not one per hello."""
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    server = await serve(book)
    hashes = HashCount(monkeypatch)
    try:
        assert server.secrets is not None
        await until(lambda: server.secrets is not None and server.secrets.watched)
        assert (await hello(server.port, token, DEVICE))["ok"]  # otto's device, known
        sent: list[dict[str, Any]] = []

        async def guess(lane: int) -> None:  # 8 connections, 10 hellos a second each
            reader, writer = await asyncio.open_connection(HOST, server.port,
                                                           local_addr=(GUESSER, 0))
            try:
                for n in range(20):
                    line = {"id": n, "cmd": "hello", "client": "g",
                            "token": wrong_secret(token, lane * 100 + n)}
                    writer.write(json.dumps(line).encode() + b"\n")
                    reply = json.loads(await asyncio.wait_for(reader.readline(), 30))
                    sent.append(reply)
                    await asyncio.sleep(0.1)
            finally:
                writer.close()

        flood = [asyncio.create_task(guess(lane)) for lane in range(8)]
        await asyncio.sleep(0.3)  # the flood is under way
        local = await ProtocolClient.connect(HOST, server.port)
        await local.request("hello", client="this computer")
        device = await ProtocolClient.connect(HOST, server.port, local_host=DEVICE)
        await device.request("hello", client="otto's tablet", token=token)
        assert not any(task.done() for task in flood)  # served during the flood
        await asyncio.gather(*flood)
        await local.close()
        await device.close()
    finally:
        await server.close()
    assert len(sent) == 160 and all(r["error"]["code"] == "forbidden" for r in sent)
    throttled = [r for r in sent if "try again in" in r["error"]["message"]]
    assert len(throttled) > 120  # refused without a hash
    assert hashes.made < 40, hashes.made  # the flood's checks and the device's one


@pytest.mark.asyncio
async def test_a_known_device_is_not_throttled_by_a_guessers_failures(tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    server = await serve(book)
    try:
        assert (await hello(server.port, token, DEVICE))["ok"]  # signed in once: known
        for n in range(6):  # the guesser's failures grow otto's back-off
            reply = await hello(server.port, wrong_secret(token, n), GUESSER)
            assert reply["error"]["code"] == "forbidden"
        new_device = await hello(server.port, token, "127.0.0.4")  # otto, never seen here
        assert "try again in" in new_device["error"]["message"]
        for _ in range(5):  # the known device, every time at once
            assert (await hello(server.port, token, DEVICE))["ok"]
    finally:
        await server.close()


@pytest.mark.asyncio
async def test_a_known_device_stays_known_after_a_restart(tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    devices = KnownDevices(tmp_path / "state" / "known-devices.json")
    first_guard = SecretGuard(book, devices=devices)
    first = await serve(book, secrets=first_guard)
    try:
        assert (await hello(first.port, token, DEVICE))["ok"]
        await until(lambda: devices.path.exists() and DEVICE in devices.path.read_text(),
                    what="the known devices written")
    finally:
        await first.close()
        first_guard.close()
    if os.name == "posix":
        assert devices.path.stat().st_mode & 0o777 == 0o600
    guard = SecretGuard(book, devices=devices)  # the server started again
    second = await serve(book, secrets=guard)
    try:
        await until(lambda: guard.known(DEVICE, "otto"), what="the known devices read back")
        for n in range(4):
            reply = await hello(second.port, wrong_secret(token, n), GUESSER)
            assert reply["error"]["code"] == "forbidden"
        assert "try again in" in (await hello(second.port, token, "127.0.0.4"))["error"][
            "message"]
        assert (await hello(second.port, token, DEVICE))["ok"]  # at once
    finally:
        await second.close()
        guard.close()


@pytest.mark.asyncio
async def test_a_full_worker_answers_busy_at_once_and_the_hello_may_try_again(
        tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    worker = SecretWorker(most=1, known=0)
    guard = SecretGuard(book, worker=worker)
    server = await serve(book, secrets=guard)
    release = threading.Event()
    try:
        await until(lambda: guard.watched and worker.waiting == 0,
                    what="the file watcher's first read")
        holding = asyncio.ensure_future(worker.run(lambda: release.wait(30)))
        await asyncio.sleep(0)
        client = await ProtocolClient.connect(HOST, server.port, local_host=GUESSER)
        with pytest.raises(RequestError) as caught:
            await client.request("hello", client="o", token=token)
        assert caught.value.code is ErrorCode.UNAVAILABLE
        assert "busy" in caught.value.message and "try again" in caught.value.message
        release.set()
        await holding
        await client.request("hello", client="o", token=token)  # its next try is checked
        await client.close()
    finally:
        release.set()
        await server.close()
        guard.close()


@pytest.mark.asyncio
async def test_a_wrong_token_is_one_log_line_a_minute_however_many_come(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level("INFO", logger="moas_gui.net.secrets")
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    server = await serve(book)
    try:
        for n in range(60):
            source = f"127.0.1.{n % 30 + 1}"
            reply = await hello(server.port, wrong_secret(token, n), source)
            assert reply["error"]["code"] == "forbidden"
    finally:
        await server.close()
    lines = [r.getMessage() for r in caplog.records if r.name == "moas_gui.net.secrets"]
    assert sum("A wrong token" in m for m in lines) == 1
    assert sum("too many wrong tokens" in m for m in lines) == 1
    assert token.rsplit(".", 1)[1][:10] not in " ".join(lines)



@pytest.mark.asyncio
async def test_a_token_hello_waiting_for_its_check_keeps_its_place_under_a_crowd(
        tmp_path: Path) -> None:
    """The token is checked on the worker; while the hello waits for the answer (the
    worker held busy here), a crowd from twelve addresses filling the server cannot take
    its place, and the answer moves it to the operators' own capacity."""
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.OPERATE)
    worker = SecretWorker()
    guard = SecretGuard(book, worker=worker)
    server = await serve(book, secrets=guard, max_clients=4, per_address=4)
    release = threading.Event()
    crowd: list[asyncio.StreamWriter] = []
    try:
        await until(lambda: guard.watched and worker.waiting == 0,
                    what="the file watcher's first read")
        holding = asyncio.ensure_future(worker.run(lambda: release.wait(30)))
        reader, writer = await asyncio.open_connection(HOST, server.port,
                                                       local_addr=(GUESSER, 0))
        crowd.append(writer)
        writer.write(json.dumps({"id": 1, "cmd": "hello", "client": "o",
                                 "token": token}).encode() + b"\n")
        await until(lambda: worker.waiting == 2, what="the hello's check queued")
        await asyncio.sleep(PATIENCE)  # past its grace and patience: it would go first
        for n in range(1, 13):
            source = f"127.0.4.{n}"
            crowd.append((await asyncio.open_connection(HOST, server.port,
                                                        local_addr=(source, 0)))[1])
            await until(lambda source=source: server.admission.open_from(source) == 1,
                        what=f"{source} admitted")
        (waiting,) = [t for t in server.admission.tickets() if t.address.startswith(GUESSER)]
        assert not waiting.released and waiting.checks == 1
        release.set()
        await holding
        while True:
            reply = json.loads(await asyncio.wait_for(reader.readline(), 30))
            if reply.get("id") == 1:
                break
        assert reply["result"]["operator"]["name"] == "otto", reply
        assert server.admission.operator_count == 1 and waiting.checks == 0
    finally:
        release.set()
        for opened in crowd:
            opened.close()
        await server.close()
        guard.close()


@pytest.mark.asyncio
async def test_a_report_request_waiting_for_its_token_check_keeps_its_place_under_a_crowd(
        tmp_path: Path) -> None:
    """The contest report's bearer token is checked on the same worker: while the request
    waits for the answer, a crowd filling the web port cannot close its connection, and
    the request is answered."""
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("otto", Role.VIEW)
    worker = SecretWorker()
    guard = SecretGuard(book, worker=worker)
    server = await serve(book, secrets=guard, max_clients=4, per_address=4)
    web = WebServer(server, host=HOST, port=0)
    await web.start()
    release = threading.Event()
    crowd: list[asyncio.StreamWriter] = []
    try:
        await until(lambda: guard.watched and worker.waiting == 0,
                    what="the file watcher's first read")
        holding = asyncio.ensure_future(worker.run(lambda: release.wait(30)))
        reader, writer = await asyncio.open_connection(HOST, web.port, local_addr=(GUESSER, 0))
        crowd.append(writer)
        writer.write(f"GET /report HTTP/1.1\r\nHost: {HOST}:{web.port}\r\n"
                     f"Authorization: Bearer {token}\r\nConnection: close\r\n\r\n".encode())
        await until(lambda: worker.waiting == 2, what="the request's check queued")
        await asyncio.sleep(PATIENCE)
        for n in range(1, 13):
            source = f"127.0.4.{n}"
            crowd.append((await asyncio.open_connection(HOST, web.port,
                                                        local_addr=(source, 0)))[1])
            await until(lambda source=source: server.admission.open_from(source) == 1,
                        what=f"{source} admitted")
        (waiting,) = [t for t in server.admission.tickets() if t.address.startswith(GUESSER)]
        assert not waiting.released and waiting.checks == 1
        release.set()
        await holding
        answer = await asyncio.wait_for(reader.read(), 30)
        assert answer.startswith(b"HTTP/1.1 200"), answer[:200]
        assert b"antenna journal is turned off" in answer  # past the token: its page
    finally:
        release.set()
        for opened in crowd:
            opened.close()
        await web.close()
        await server.close()
        guard.close()
