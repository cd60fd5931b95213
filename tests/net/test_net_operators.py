"""Operators, tokens and roles over real sockets: the client protocol server with the fake
backend, peers on 127.0.0.1 (this computer) and 127.0.0.2/3 (other hosts on the LAN or
outside it), with and without TLS."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from helpers import until

from moas_gui.net.backend import ErrorCode, RequestError
from moas_gui.net.client import ProtocolClient
from moas_gui.net.identity import Forbidden, Identity, as_operator
from moas_gui.net.server import ClientServer
from moas_gui.operators import OperatorBook, Role
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.tls import (
    Certificate,
    client_context,
    fingerprint,
    make_self_signed,
    peer_fingerprint,
    server_context,
)

HOST = "127.0.0.1"
LAN = "127.0.0.2"
OUTSIDE = "127.0.0.3"
ALLOW = ["127.0.0.2"]


async def serve(tmp_path: Path, **options: Any) -> tuple[ClientServer, FakeBackend]:
    backend = FakeBackend()
    server = ClientServer(backend, host=HOST, port=0, allow=ALLOW,
                          operators=OperatorBook(tmp_path / "operators.json"), **options)
    backend.attach(server)
    await server.start()
    return server, backend


async def forbidden(peer: ProtocolClient, cmd: str, **args: Any) -> str:
    with pytest.raises(RequestError) as caught:
        await peer.request(cmd, **args)
    assert caught.value.code is ErrorCode.FORBIDDEN, caught.value.message
    return caught.value.message


@pytest.mark.asyncio
async def test_an_open_lan_client_acts_without_a_token_but_may_not_stop_the_switches(
        tmp_path: Path) -> None:
    server, _backend = await serve(tmp_path)
    client = await ProtocolClient.connect(HOST, server.port, local_host=LAN)
    try:
        await client.request("hello", client="lan")
        result = await client.request("select", station=1, radio=1, antenna=2)
        assert result["tx"] == 2
        assert "admin" in await forbidden(client, "stop_switches")
        assert server.clients()[0].name == "lan"
        assert not next(iter(server._connections)).identity.is_operator
    finally:
        await client.close()
        await server.close()


@pytest.mark.asyncio
async def test_this_computer_never_needs_a_token_and_may_stop_the_switches(
        tmp_path: Path) -> None:
    server, backend = await serve(tmp_path, require_token=True)
    client = await ProtocolClient.connect(HOST, server.port)
    try:
        await client.request("hello", client="local")
        assert await client.request("stop_switches") == {}
        assert ("switches", ("stop",)) in backend.calls
        assert not backend.running
        assert await client.request("start_switches") == {}
        assert backend.running
    finally:
        await client.close()
        await server.close()


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_with_require_token_a_lan_client_without_one_is_refused_and_closed(
        tmp_path: Path) -> None:
    server, backend = await serve(tmp_path, require_token=True, hello_deadline=1.0)
    client = await ProtocolClient.connect(HOST, server.port, local_host=LAN)
    try:
        assert "token" in await forbidden(client, "select", station=1, radio=1, antenna=2)
        assert "token" in await forbidden(client, "hello", client="no token")
        assert "token" in await forbidden(client, "state")  # still nobody
        await asyncio.wait_for(client.closed.wait(), 10)  # the hello deadline
        assert [c for c in backend.calls if c[0] == "select"] == []
    finally:
        await client.close()
        await server.close()


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_a_wrong_token_is_refused_and_never_logged(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG)
    server, _backend = await serve(tmp_path, require_token=True)
    book = OperatorBook(tmp_path / "operators.json")
    _op, token = book.add("alice", Role.ADMIN)
    wrong = token[:-4] + ("AAAA" if not token.endswith("AAAA") else "BBBB")
    client = await ProtocolClient.connect(HOST, server.port, local_host=LAN)
    try:
        assert "not one of this station's operators" in await forbidden(
            client, "hello", client="guess", token=wrong)
        assert "token" in await forbidden(client, "select", station=1, radio=1, antenna=2)
        # it may try again, once the back-off of that key id (1 s after a failure) is over
        assert "try again in 1 s" in await forbidden(client, "hello", client="right",
                                                     token=token)
        while True:
            try:
                await client.request("hello", client="right", token=token)
                break
            except RequestError as refused:
                assert "try again" in refused.message
                await asyncio.sleep(0.1)
        assert (await client.request("select", station=1, radio=1, antenna=2))["tx"] == 2
    finally:
        await client.close()
        await server.close()
    secret = token.rsplit(".", 1)[1]
    assert all(secret[:12] not in r.getMessage() and wrong.rsplit(".", 1)[1][:12]
               not in r.getMessage() for r in caplog.records)


@pytest.mark.asyncio
async def test_roles_view_operate_and_admin_over_real_sockets(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    server, backend = await serve(tmp_path, require_token=True)
    book = OperatorBook(tmp_path / "operators.json")
    _v, view = book.add("vera", Role.VIEW)
    _o, operate = book.add("otto", Role.OPERATE, frozenset({(1, 1)}))
    _a, admin = book.add("ada", Role.ADMIN)
    clients = [await ProtocolClient.connect(HOST, server.port, local_host=LAN)
               for _ in range(3)]
    v, o, a = clients
    told: list[str] = []
    await until(lambda: len(server._connections) == 3)  # accepted one a loop turn
    for conn in server._connections:
        promote = conn.identified  # the admission's: an operator gets its own pool

        def note(identity: Identity, promote: Callable[[Identity], None] | None = promote
                 ) -> None:
            told.append(identity.name)
            if promote is not None:
                promote(identity)
        conn.identified = note
    try:
        await v.request("hello", client="v", token=view)
        await o.request("hello", client="o", token=operate)
        await a.request("hello", client="a", token=admin)
        assert (await v.request("state"))["radios"]  # view sees everything
        assert "view role" in await forbidden(v, "select", station=1, radio=1, antenna=2)
        assert (await o.request("select", station=1, radio=1, antenna=2))["tx"] == 2
        assert await o.request("focus", station=1, radio=1) == {}
        assert "2/1" in await forbidden(o, "select", station=2, radio=1, antenna=3)
        assert "2/1" in await forbidden(o, "active", station=2, radio=1)
        assert "admin" in await forbidden(o, "stop_switches")
        assert (await a.request("select", station=2, radio=1, antenna=3))["tx"] == 3
        assert await a.request("stop_switches") == {}
        assert not backend.running
        assert {c.identity.is_operator for c in server._connections} == {True}
        assert server.admission.operator_count == 3  # in the operators' own pool
        assert sorted(told) == ["ada", "otto", "vera"]
    finally:
        for client in clients:
            await client.close()
        await server.close()
    said = [r.getMessage() for r in caplog.records]
    assert any(m.startswith(f"otto at {LAN}:") and "selecting antennas of radio 1/1" in m
               for m in said)
    assert any(m.startswith(f"ada at {LAN}:") and "stop the switches" in m for m in said)


@pytest.mark.asyncio
async def test_removing_an_operator_ends_its_sessions_and_its_token(tmp_path: Path) -> None:
    server, _backend = await serve(tmp_path, require_token=True)
    book = OperatorBook(tmp_path / "operators.json")
    _o, token = book.add("otto", Role.OPERATE)
    client = await ProtocolClient.connect(HOST, server.port, local_host=LAN)
    try:
        await client.request("hello", client="o", token=token)
        book.remove("otto")
        assert server.end_operator("otto") == 1
        await asyncio.wait_for(client.closed.wait(), 5)
        again = await ProtocolClient.connect(HOST, server.port, local_host=LAN)
        assert "not one of" in await forbidden(again, "hello", client="o", token=token)
        await again.close()
    finally:
        await client.close()
        await server.close()


@pytest.mark.asyncio
async def test_outside_the_allowed_networks_only_tls_with_a_token_gets_in(
        tmp_path: Path) -> None:
    where = Certificate(tmp_path / "cert.pem", tmp_path / "key.pem")
    make_self_signed(where, "localhost")
    book = OperatorBook(tmp_path / "operators.json")
    _o, token = book.add("remote", Role.OPERATE)
    plain, _b = await serve(tmp_path)
    try:  # without TLS an outside address is refused by address, as before
        refused = await ProtocolClient.connect(HOST, plain.port, local_host=OUTSIDE)
        await asyncio.wait_for(refused.closed.wait(), 5)
        assert plain.client_count == 0
        await refused.close()
    finally:
        await plain.close()
    server, _backend = await serve(tmp_path, tls=server_context(where))
    try:
        anonymous = await ProtocolClient.connect(HOST, server.port, local_host=OUTSIDE,
                                                 ssl=client_context())
        assert "token" in await forbidden(anonymous, "state")
        assert "token" in await forbidden(anonymous, "hello", client="anon")
        await anonymous.close()
        client = await ProtocolClient.connect(HOST, server.port, local_host=OUTSIDE,
                                              ssl=client_context())
        seen = peer_fingerprint(client.writer.get_extra_info("ssl_object"))
        assert seen == fingerprint(where)
        await client.request("hello", client="remote", token=token)
        assert (await client.request("select", station=1, radio=1, antenna=2))["tx"] == 2
        await client.close()
    finally:
        await server.close()


@pytest.mark.asyncio
async def test_a_task_a_request_started_acts_for_nobody_once_the_request_is_answered() -> None:
    from moas_gui.net.identity import Action, Party, current, enforce, serving
    from moas_gui.operators import Operator

    viewer = as_operator(Operator("vera", Role.VIEW), "127.0.0.2:1")
    seen: list[object] = []

    async def later() -> None:
        await asyncio.sleep(0)
        seen.append(current())
        enforce(Action("tuning radio 1/1", frozenset({(1, 1)})))  # the server's own: allowed

    with serving(viewer):
        assert current() is viewer
        with pytest.raises(Forbidden):
            enforce(Action("tuning radio 1/1", frozenset({(1, 1)})))
        task = asyncio.ensure_future(later())
    await task
    assert seen == [None] and current() is None
    assert Party.OPERATOR is viewer.kind
