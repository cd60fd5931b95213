"""The hook between the client protocol and the admission policy, over real sockets:
a valid hello greets a connection's ticket (a WebSocket's connection holds its web
connection's), a ticket promoted to
operator (what identity does after a hello with a token) takes its place from the
operators' own capacity and is never evicted by a crowd, and a connection evicted to
make room is told why."""

from __future__ import annotations

import asyncio
import json

import pytest
from helpers import until
from test_net_fairness import closed, from_address, shut
from test_net_server import HOST, dispose, make_rig
from test_net_web import make_web, receive

from moas_gui.edge.admission import GRACE, Standing, Ticket


def tickets_of(tickets: list[Ticket], host: str) -> list[Ticket]:
    return [t for t in tickets if t.address.startswith(f"{host}:")]


@pytest.mark.asyncio
async def test_a_hello_greets_and_an_operator_outlasts_a_crowd() -> None:
    rig = await make_rig(max_clients=4, per_address=4)
    crowd: list[asyncio.StreamWriter] = []
    try:
        operator = await rig.connect("operator")
        (ticket,) = tickets_of(rig.server.admission.tickets(), HOST)
        assert ticket.standing is Standing.GREETED  # the hello did it
        assert ticket.operator()  # what identity calls once a token named an operator
        assert rig.server.admission.operator_count == 1
        for n in range(2, 10):  # newcomers from eight addresses, each making room
            crowd.append((await from_address(rig.server.port, f"127.0.0.{n}"))[1])
            await until(lambda n=n: rig.server.admission.open_from(f"127.0.0.{n}") == 1)
        assert rig.server.admission.count == 5  # four places, and the operator's own
        assert await operator.request("stop", rotator=1) == {}
        assert not ticket.released
    finally:
        for writer in crowd:
            await shut(writer)
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_connection_evicted_to_make_room_is_told_why() -> None:
    rig = await make_rig(max_clients=2, per_address=4)
    try:
        first = await from_address(rig.server.port, "127.0.0.2")
        first[1].write(b'{"id": 1, "cmd": "hello", "client": "idle"}\n')
        await first[0].readline()  # the hello's reply
        second = await from_address(rig.server.port, "127.0.0.2")
        await until(lambda: rig.server.admission.count == 2)
        await asyncio.sleep(GRACE)  # past the grace a connection just opened has
        newcomer = await rig.connect("newcomer")  # 127.0.0.1 holds none: it takes a place
        said = (await closed(second[0])).decode()
        told = [json.loads(line) for line in said.splitlines() if '"error"' in line]
        assert told and told[-1]["error"]["code"] == "unavailable"
        assert "took the place of this one" in told[-1]["error"]["message"]
        assert await newcomer.request("stop", rotator=1) == {}
        await shut(first[1])
        await shut(second[1])
    finally:
        await dispose(rig)


@pytest.mark.asyncio
async def test_a_web_socket_carries_its_web_connections_ticket() -> None:
    made = await make_web()
    try:
        ws = await made.session.ws_connect(f"http://{HOST}:{made.web.port}/ws")
        await ws.send_str(json.dumps({"id": 1, "cmd": "hello", "client": "page"}))
        assert (await receive(ws))["id"] == 1
        (ticket,) = tickets_of(made.clients.admission.tickets(), HOST)
        # greeted by its complete request already; the protocol's connection holds the
        # same ticket, so that identity can make it an operator after its hello
        assert ticket.front == "web connection" and ticket.standing is Standing.GREETED
        assert [conn.ticket for conn in made.clients._connections] == [ticket]
        await ws.close()
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()
