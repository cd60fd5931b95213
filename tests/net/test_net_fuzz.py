"""Fuzzing the client protocol server over real sockets: random bytes, huge
lines, deep JSON and random requests never crash it, never make it fail
(no ``internal`` error, no error logged), and never disturb another client,
which must still get its replies after every example.

The server runs on its own event loop in a thread for the whole module, so
that each hypothesis example is only a few socket calls from this thread.
"""

from __future__ import annotations

import asyncio
import json
import logging
import socket
import threading
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from moas_gui.net.framing import MAX_LINE
from moas_gui.net.requests import COMMANDS, MAX_DEPTH, MAX_ID, Kind
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend

HOST = "127.0.0.1"
TIMEOUT = 10.0


class ThreadedServer:
    """A ClientServer over a FakeBackend on an event loop in its own thread."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.loop.set_exception_handler(self._loop_error)
        self.thread = threading.Thread(target=self.loop.run_forever, name="fuzzed server")
        self.failures: list[str] = []
        self.backend = FakeBackend()
        self.server = ClientServer(self.backend, host=HOST, port=0)
        self.backend.attach(self.server)
        self.port = 0

    def _loop_error(self, loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        self.failures.append(f"event loop: {context.get('message')} {context.get('exception')!r}")

    def start(self) -> None:
        self.thread.start()
        self.port = asyncio.run_coroutine_threadsafe(self.server.start(), self.loop).result(5)

    def stop(self) -> None:
        asyncio.run_coroutine_threadsafe(self.server.close(), self.loop).result(10)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(10)
        self.loop.close()


class FailureLog(logging.Handler):
    def __init__(self, into: list[str]) -> None:
        super().__init__(logging.ERROR)
        self.into = into

    def emit(self, record: logging.LogRecord) -> None:
        self.into.append(f"log: {record.getMessage()}")


class LineSocket:
    """A blocking client socket that reads whole JSON lines."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection((HOST, port), timeout=TIMEOUT)
        self.buffer = b""

    def send(self, message: dict[str, Any]) -> None:
        self.sock.sendall(json.dumps(message).encode() + b"\n")

    def read(self) -> dict[str, Any] | None:
        """The next message, or None when the server closed the connection."""
        while b"\n" not in self.buffer:
            try:
                data = self.sock.recv(65536)
            except ConnectionResetError:
                data = b""
            if not data:
                return None
            self.buffer += data
        line, self.buffer = self.buffer.split(b"\n", 1)
        message = json.loads(line)
        assert isinstance(message, dict)
        return message

    def reply_to(self, request_id: Any) -> dict[str, Any]:
        while True:
            message = self.read()
            assert message is not None, f"closed before the reply to {request_id!r}"
            if "event" not in message:
                assert message["id"] == request_id, message
                return message

    def close(self) -> None:
        self.sock.close()


@pytest.fixture(scope="module")
def fuzzed() -> Iterator[tuple[ThreadedServer, LineSocket]]:
    server = ThreadedServer()
    handler = FailureLog(server.failures)
    logging.getLogger("moas_gui.net").addHandler(handler)
    server.start()
    bystander = LineSocket(server.port)
    bystander.send({"id": "hello", "cmd": "hello", "client": "bystander"})
    assert bystander.reply_to("hello")["ok"] is True
    try:
        yield server, bystander
    finally:
        bystander.close()
        server.stop()
        logging.getLogger("moas_gui.net").removeHandler(handler)


_probe = iter(range(10**9))


def undisturbed(server: ThreadedServer, bystander: LineSocket) -> None:
    """The bystander is still served, nothing failed, and new clients are welcome."""
    request_id = f"probe {next(_probe)}"
    bystander.send({"id": request_id, "cmd": "state"})
    reply = bystander.reply_to(request_id)
    assert reply["ok"] is True and reply["result"]["config"]
    fresh = LineSocket(server.port)
    fresh.send({"id": "fresh", "cmd": "stop", "rotator": 1})
    assert fresh.reply_to("fresh") == {"id": "fresh", "ok": True, "result": {}}
    fresh.close()
    assert server.failures == []


def exchange(port: int, data: bytes) -> list[dict[str, Any]]:
    """Sends ``data``, ends the sending side, and returns every line the server
    wrote back before closing; each must be a JSON object."""
    client = LineSocket(port)
    try:
        try:
            client.sock.sendall(data)
            client.sock.shutdown(socket.SHUT_WR)
        except (BrokenPipeError, ConnectionResetError):
            pass  # closed after three bad lines while we were still sending
        replies = []
        while (message := client.read()) is not None:
            replies.append(message)
        return replies
    finally:
        client.close()


def check_replies(replies: list[dict[str, Any]]) -> None:
    for reply in replies:
        assert "event" in reply or set(reply) in ({"id", "ok", "result"}, {"id", "ok", "error"})
        if reply.get("ok") is False:
            assert reply["error"]["code"] != "internal", reply
            assert isinstance(reply["error"]["message"], str) and reply["error"]["message"]


def fuzz(examples: int) -> settings:
    return settings(max_examples=examples, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow,
                                           HealthCheck.function_scoped_fixture])


@fuzz(120)
@given(st.lists(st.binary(max_size=300), max_size=12).map(b"\n".join))
@example(b"\x00" * 1000)
@example(b"\n" * 5000)
@example(b"\r\n\r\n{\r\n")
def test_random_bytes_never_hurt_the_server(
    fuzzed: tuple[ThreadedServer, LineSocket], data: bytes
) -> None:
    server, bystander = fuzzed
    check_replies(exchange(server.port, data + b"\n"))
    undisturbed(server, bystander)


@fuzz(30)
@given(st.integers(min_value=MAX_LINE - 2, max_value=400_000), st.sampled_from(b"x[{\"\x00\xff "))
@example(MAX_LINE, ord("x"))
@example(MAX_LINE + 1, ord("x"))
def test_huge_lines_get_one_error_and_the_connection_goes_on(
    fuzzed: tuple[ThreadedServer, LineSocket], size: int, byte: int
) -> None:
    server, bystander = fuzzed
    after = json.dumps({"id": "after", "cmd": "stop", "rotator": 1}).encode()
    replies = exchange(server.port, bytes([byte]) * size + b"\n" + after + b"\n")
    check_replies(replies)
    if byte == ord(" ") and size <= MAX_LINE:  # a blank line: nothing to answer
        assert [r["id"] for r in replies] == ["after"]
    else:
        assert [r["id"] for r in replies] == [None, "after"]
        assert replies[0]["error"]["code"] == "bad_request"
    if size > MAX_LINE:
        assert "longer than 65,536 bytes" in replies[0]["error"]["message"]
    assert replies[-1]["ok"] is True
    undisturbed(server, bystander)


@fuzz(30)
@given(st.integers(min_value=1, max_value=100_000), st.sampled_from([b"[", b'{"a":', b'{"id":[']))
@example(100_000, b"[")
@example(30_000, b"[")
@example(10_000, b'{"a":')
@example(980, b'{"id":[')
@example(995, b'{"id":[')  # found by benchmarks/bench_properties.py: the id was echoed back
@example(MAX_DEPTH, b"[")
@example(MAX_DEPTH + 1, b"[")
def test_deep_json_gets_one_error_and_the_connection_goes_on(
    fuzzed: tuple[ThreadedServer, LineSocket], depth: int, opening: bytes
) -> None:
    server, bystander = fuzzed
    closing = b"]" if opening == b"[" else (b"}" if opening == b'{"a":' else b"]}")
    middle = b"" if opening == b"[" else b"1"
    line = opening * depth + middle + closing * depth
    after = json.dumps({"id": "after", "cmd": "stop", "rotator": 1}).encode()
    replies = exchange(server.port, line + b"\n" + after + b"\n")
    check_replies(replies)
    assert len(replies) == 2 and replies[1]["id"] == "after"
    assert replies[0]["ok"] is False and replies[0]["error"]["code"] == "bad_request"
    if depth > MAX_DEPTH:  # shallower ones are JSON, and objects among them keep their id
        assert replies[0]["id"] is None
    if len(line) > MAX_LINE:
        assert "longer than" in replies[0]["error"]["message"]
    elif depth > MAX_DEPTH:
        assert "nested too deeply" in replies[0]["error"]["message"]
    undisturbed(server, bystander)


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=12),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner,
                                                                 max_size=4),
    max_leaves=12,
)
ARG_NAMES = sorted({a.name for c in COMMANDS.values() for a in c.args})
PLAUSIBLE = st.one_of(
    st.integers(min_value=-2, max_value=9), st.floats(min_value=-400, max_value=30_000),
    st.sampled_from(["both", "tx", "rx", "", "client"]), st.booleans(), st.none(), JSON,
)
ANY_SHAPE = st.fixed_dictionaries(
    {"cmd": st.one_of(st.sampled_from(sorted(COMMANDS)), st.text(max_size=8), JSON)},
    optional={name: PLAUSIBLE for name in ARG_NAMES},
)
SMALL_ID = st.sampled_from([0, 1, 2, 3]) | st.integers(min_value=0, max_value=10) \
    | st.integers(min_value=0, max_value=MAX_ID)
OF_KIND: dict[Kind, st.SearchStrategy[Any]] = {
    Kind.NUMBER_ID: SMALL_ID,
    Kind.INDEX: SMALL_ID,
    Kind.KHZ: st.sampled_from([0, 1800, 3550.5, 7000, 7300, 14025, 14350.001, 29700])
    | st.floats(min_value=0, max_value=1e9),
    Kind.HEADING: st.floats(min_value=-360, max_value=720),
    Kind.BOOL: st.booleans(),
    Kind.TEXT: st.text(max_size=200),
    Kind.TARGET: st.sampled_from(["both", "tx", "rx"]),
    Kind.STEP: st.sampled_from([1, -1]),
    Kind.COUNT: st.integers(min_value=1, max_value=1000),
}
WELL_TYPED = st.sampled_from(sorted(COMMANDS)).flatmap(
    lambda cmd: st.fixed_dictionaries(
        {"cmd": st.just(cmd)} | {a.name: OF_KIND[a.kind] for a in COMMANDS[cmd].args
                                 if a.required},
        optional={a.name: OF_KIND[a.kind] for a in COMMANDS[cmd].args if not a.required},
    )
)
REQUESTS = st.one_of(ANY_SHAPE, WELL_TYPED, WELL_TYPED)


@fuzz(60)  # the wide random search: benchmarks/bench_properties.py
@given(st.lists(REQUESTS, min_size=1, max_size=30))
def test_random_requests_get_exactly_one_reply_each_and_never_fail_the_server(
    fuzzed: tuple[ThreadedServer, LineSocket], requests: list[dict[str, Any]]
) -> None:
    server, bystander = fuzzed
    lines = b"".join(json.dumps({**r, "id": i}).encode() + b"\n" for i, r in enumerate(requests))
    replies = [r for r in exchange(server.port, lines) if "event" not in r]
    check_replies(replies)
    assert [r["id"] for r in replies] == list(range(len(requests)))
    undisturbed(server, bystander)
