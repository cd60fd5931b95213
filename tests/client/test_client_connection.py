"""The asyncio client against the real protocol server (fake backend) on 127.0.0.1,
and against small raw servers that misbehave on purpose."""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import AsyncIterator, Awaitable, Callable

import pytest
from client_support import LOOPBACK, LiveServer
from helpers import until

from moas_gui.client import (
    Backoff,
    ClientConnection,
    ClientEvent,
    ConnectionLost,
    LayoutChanged,
    LinkChanged,
    LinkState,
    NotConnected,
    ProblemSeen,
    RadioChanged,
    RequestTimeout,
    RotatorChanged,
    ServerError,
    StateReceived,
    SwitchChanged,
)

FAST = Backoff(first=0.02, factor=2.0, most=0.1)


class Recorder:
    """Keeps every event a connection reports."""

    def __init__(self) -> None:
        self.events: list[ClientEvent] = []

    def __call__(self, event: ClientEvent) -> None:
        self.events.append(event)

    def of(self, kind: type) -> list[ClientEvent]:
        return [e for e in self.events if isinstance(e, kind)]


@contextlib.asynccontextmanager
async def connected(port: int, **kwargs: object) -> AsyncIterator[tuple[ClientConnection,
                                                                        Recorder]]:
    connection = ClientConnection(LOOPBACK, port, backoff=FAST, timeout=2.0, **kwargs)  # type: ignore[arg-type]
    recorder = Recorder()
    connection.subscribe(recorder)
    connection.start()
    try:
        yield connection, recorder
    finally:
        await connection.aclose()


@contextlib.asynccontextmanager
async def raw_server(handler: Callable[[asyncio.StreamReader, asyncio.StreamWriter],
                                       Awaitable[None]]) -> AsyncIterator[int]:
    server = await asyncio.start_server(handler, LOOPBACK, 0)
    try:
        yield server.sockets[0].getsockname()[1]
    finally:
        server.close()
        with contextlib.suppress(Exception):
            await asyncio.wait_for(server.wait_closed(), 1.0)


@pytest.mark.asyncio
async def test_hello_is_answered_and_the_snapshot_arrives() -> None:
    async with LiveServer() as live, connected(live.port, name="pytest client") as (conn, rec):
        await conn.wait_connected(5)
        await until(lambda: conn.snapshot is not None, what="the state event")
        assert conn.link is LinkState.CONNECTED
        assert conn.server["protocol"] == 1
        assert conn.snapshot is not None
        radio = conn.snapshot.radio(1, 1)
        assert radio is not None and radio.tx == 2 and radio.khz == 14025.0
        assert conn.snapshot.antenna(2) is not None
        assert conn.snapshot.antenna(2).long == "20m stack all"  # type: ignore[union-attr]
        assert [r.id for r in conn.snapshot.rotators] == [1, 2, 3]
        assert rec.of(StateReceived) and rec.of(LinkChanged)[-1].state is LinkState.CONNECTED  # type: ignore[attr-defined]
        assert any(info.name == "pytest client" for info in live.server.clients())  # type: ignore[union-attr]


@pytest.mark.asyncio
async def test_select_returns_the_antennas_and_the_radio_event_updates_the_snapshot() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, rec):
        await conn.wait_connected(5)
        selection = await conn.select(1, 1, 1)
        assert (selection.tx, selection.rx) == (1, 1)
        await until(lambda: rec.of(RadioChanged), what="the radio event")
        assert conn.snapshot is not None and conn.snapshot.radio(1, 1).tx == 1  # type: ignore[union-attr]
        assert live.calls("select")[-1] == (1, 1, 1, "both", False)


@pytest.mark.asyncio
async def test_exclusive_and_receive_only_selection_reach_the_backend() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, _):
        await conn.wait_connected(5)
        await conn.select(1, 1, 1, exclusive=True)
        await conn.frequency(1, 1, 7150.0)
        await conn.select(1, 1, 6, target="rx")
        assert live.calls("select") == [(1, 1, 1, "both", True), (1, 1, 6, "rx", False)]
        assert live.calls("frequency") == [(1, 1, 7150.0, None)]


@pytest.mark.asyncio
async def test_a_refusal_raises_server_error_with_the_code_and_sentence() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, _):
        await conn.wait_connected(5)
        await conn.frequency(1, 1, 7150.0)
        with pytest.raises(ServerError) as refused:
            await conn.select(1, 1, 3)  # the 40 m beam is in use by station 2
        assert refused.value.code == "unavailable"
        assert "in use by station 2 radio 1" in refused.value.message
        with pytest.raises(ServerError) as missing:
            await conn.rotate(99, 10)
        assert missing.value.code == "not_found"


@pytest.mark.asyncio
async def test_layout_is_followed_and_its_changes_arrive_as_events() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, rec):
        await conn.wait_connected(5)
        layout = await conn.layout(1, 1, 4, 3)
        states = {b.label: b.state.value for b in layout.buttons}
        assert states["20 Stack"] == "selected" and states["Tribander"] == "available"
        await conn.select(1, 1, 1)
        await until(lambda: rec.of(LayoutChanged), what="the layout event")
        changed = rec.of(LayoutChanged)[-1].layout  # type: ignore[attr-defined]
        assert {b.label: b.state.value for b in changed.buttons}["Tribander"] == "selected"


@pytest.mark.asyncio
async def test_relative_function_rotate_and_stop() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, rec):
        await conn.wait_connected(5)
        step = await conn.relative(1, 1, step=1)
        assert step.tx == 1
        chosen = await conn.relative(1, 1, index=0)
        assert chosen.tx == 2
        await conn.select(1, 1, 1, target="tx")
        await conn.function(1, 1, 1)  # RX=TX
        assert conn.snapshot is not None
        await until(lambda: conn.snapshot.radio(1, 1).rx == 1, what="RX=TX")  # type: ignore[union-attr]
        await conn.rotate(2, 180)
        await until(lambda: conn.snapshot.rotator(2).moving, what="the rotator event")  # type: ignore[union-attr]
        assert conn.snapshot.rotator(2).target == 180  # type: ignore[union-attr]
        await conn.stop(2)
        await until(lambda: not conn.snapshot.rotator(2).moving, what="the stop")  # type: ignore[union-attr]
        assert live.calls("relative") == [(1, 1, 1, None), (1, 1, None, 0)]
        assert rec.of(RotatorChanged)


@pytest.mark.asyncio
async def test_switch_events_update_the_snapshot() -> None:
    async with LiveServer() as live, connected(live.port) as (conn, rec):
        await conn.wait_connected(5)
        await until(lambda: conn.snapshot is not None)
        live.backend.set_switch_status(1, "unresponsive")
        await until(lambda: rec.of(SwitchChanged), what="the switch event")
        assert conn.snapshot.switches[0].status == "unresponsive"  # type: ignore[union-attr]


@pytest.mark.asyncio
async def test_reconnects_after_the_server_restarts_and_gets_a_fresh_snapshot() -> None:
    live = LiveServer()
    await live.start()
    async with connected(live.port) as (conn, rec):
        await conn.wait_connected(5)
        await live.stop()
        await until(lambda: conn.link is LinkState.RECONNECTING, what="noticing the loss")
        with pytest.raises(NotConnected):
            await conn.select(1, 1, 1)
        await live.start()
        await until(lambda: conn.connects == 2, timeout=5, what="the reconnection")
        await until(lambda: len(rec.of(StateReceived)) == 2, what="the second state event")
        assert (await conn.select(1, 1, 1)).tx == 1
        await live.stop()
        states = [e.state for e in rec.of(LinkChanged)]  # type: ignore[attr-defined]
        assert states[:3] == [LinkState.CONNECTED, LinkState.RECONNECTING, LinkState.CONNECTED]


@pytest.mark.asyncio
async def test_keeps_trying_when_nobody_listens_and_says_why() -> None:
    async with raw_server(_silent) as port:
        pass  # the port is free again: nobody listens there now
    async with connected(port) as (conn, rec):
        await until(lambda: len([e for e in rec.of(LinkChanged)
                                 if e.state is LinkState.RECONNECTING]) >= 3,  # type: ignore[attr-defined]
                    what="three attempts")
        detail = rec.of(LinkChanged)[-1].detail  # type: ignore[attr-defined]
        assert detail.startswith(f"Cannot reach the server at 127.0.0.1:{port} \u2014 trying "
                                 "again in ")
        assert detail.endswith(" s (nothing answers on that port: is the server running?)")
        assert "Connect call failed" not in detail and "Errno" not in detail
        assert conn.connects == 0


@pytest.mark.asyncio
async def test_a_server_that_never_answers_hello_is_retried_with_the_reason() -> None:
    async with raw_server(_silent) as port:
        conn = ClientConnection(LOOPBACK, port, backoff=FAST, timeout=0.2)
        recorder = Recorder()
        conn.subscribe(recorder)
        conn.start()
        try:
            await until(lambda: any(e.state is LinkState.RECONNECTING  # type: ignore[attr-defined]
                                    for e in recorder.of(LinkChanged)), what="hello timing out")
            detail = recorder.of(LinkChanged)[-1].detail  # type: ignore[attr-defined]
            assert "did not answer hello" in detail and "within 0.2 s" in detail
        finally:
            await conn.aclose()


@pytest.mark.asyncio
async def test_a_request_without_a_reply_times_out_and_the_link_stays_up() -> None:
    async def handler(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            while line := await reader.readline():
                if b'"hello"' in line:
                    writer.write(b'{"id": 1, "ok": true, "result": {"protocol": 1}}\n')
                    await writer.drain()
        finally:
            writer.close()

    async with raw_server(handler) as port:
        conn = ClientConnection(LOOPBACK, port, backoff=FAST, timeout=0.2)
        conn.start()
        try:
            await conn.wait_connected(5)
            with pytest.raises(RequestTimeout, match="rotate: no reply from .* within 0.2 s"):
                await conn.rotate(1, 90)
            assert conn.link is LinkState.CONNECTED
        finally:
            await conn.aclose()


@pytest.mark.asyncio
async def test_garbage_from_the_server_is_reported_and_the_connection_carries_on() -> None:
    async def handler(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            await _garbage_then_hello(reader, writer)
        finally:
            writer.close()

    async def _garbage_then_hello(reader: asyncio.StreamReader,
                                  writer: asyncio.StreamWriter) -> None:
        while line := await reader.readline():
            if b'"hello"' in line:
                writer.write(b'\xff\xfe not utf8\n[1, 2]\n{"neither": 1}\n')
                writer.write(b'{"event": "radio", "station": "one", "radio": 1}\n')
                writer.write(b'{"id": 1, "ok": true, "result": {"server": "odd", '
                             b'"version": "9", "protocol": 1}}\n')
                writer.write(b'{"event": "state", "config": "x.moas", "radios": [], '
                             b'"antennas": [], "rotators": []}\n')
            else:
                writer.write(b'{"id": 2, "ok": false, "error": {"code": "unavailable", '
                             b'"message": "no"}}\n')
            await writer.drain()

    async with raw_server(handler) as port, connected(port) as (conn, rec):
        await conn.wait_connected(5)
        await until(lambda: conn.snapshot is not None, what="the state after the garbage")
        problems = [e.message for e in rec.of(ProblemSeen)]  # type: ignore[attr-defined]
        assert any("line 1 is not UTF-8" in p for p in problems)
        assert any("line 2 is a JSON list, not an object" in p for p in problems)
        assert any("line 3 is neither a reply" in p for p in problems)
        assert any("'station' is the string 'one', not a whole number" in p for p in problems)
        with pytest.raises(ServerError):
            await conn.stop(1)
        assert conn.link is LinkState.CONNECTED


@pytest.mark.asyncio
async def test_a_dropped_connection_fails_the_waiting_request() -> None:
    async def handler(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        while line := await reader.readline():
            if b'"hello"' in line:
                writer.write(b'{"id": 1, "ok": true, "result": {"protocol": 1}}\n')
                await writer.drain()
            else:
                writer.close()
                return

    async with raw_server(handler) as port, connected(port) as (conn, _):
        await conn.wait_connected(5)
        with pytest.raises(ConnectionLost):
            await conn.rotate(1, 90)


async def _silent(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    with contextlib.suppress(Exception):
        await reader.read()
    writer.close()


@pytest.mark.asyncio
async def test_repeated_attempts_stay_out_of_the_info_log(caplog: pytest.LogCaptureFixture) -> None:
    import logging

    caplog.set_level(logging.DEBUG, logger="moas_gui")
    async with raw_server(_silent) as port:
        pass  # nobody listens there now
    async with connected(port) as (_conn, rec):
        await until(lambda: len([e for e in rec.of(LinkChanged)
                                 if e.state is LinkState.RECONNECTING]) >= 3,  # type: ignore[attr-defined]
                    what="three attempts")
    attempts = [r for r in caplog.records if "Client link" in r.getMessage()
                and "reconnecting" in r.getMessage()]
    assert len(attempts) >= 3
    assert [r.levelno for r in attempts].count(logging.INFO) == 1, "only the first is news"
