"""The browser client's web server over real sockets on 127.0.0.1: the page, the client
protocol over a WebSocket (the same dispatcher as TCP), ClientAllow, Host and Origin."""

from __future__ import annotations

import asyncio
import json
import logging
from collections.abc import AsyncIterator
from dataclasses import dataclass
from typing import Any

import aiohttp
import pytest
import pytest_asyncio

from moas_gui.config import load_config
from moas_gui.net.client import ProtocolClient
from moas_gui.net.framing import MAX_LINE
from moas_gui.net.server import ClientServer
from moas_gui.net.web import WebServer, page_files, start_web
from moas_gui.net.web_guard import host_allowed, local_names, origin_complaint, split_host
from moas_gui.testing.fake_backend import FakeBackend

HOST = "127.0.0.1"


@dataclass
class Web:
    backend: FakeBackend
    clients: ClientServer
    web: WebServer
    session: aiohttp.ClientSession

    @property
    def base(self) -> str:
        return f"http://{HOST}:{self.web.port}"

    async def socket(self, **headers: str) -> aiohttp.ClientWebSocketResponse:
        origin = headers.pop("origin", self.base)
        extra = {"Origin": origin} if origin else {}
        return await self.session.ws_connect(self.base + "/ws", headers=extra | headers)


async def make_web(allow: list[str] | None = None, request_deadline: float | None = None,
                   **limits: Any) -> Web:
    """``request_deadline``: the web port's (its default when None); ``limits``: the
    client port's."""
    backend = FakeBackend()
    clients = ClientServer(backend, host=HOST, port=0, allow=allow, **limits)
    backend.attach(clients)
    await clients.start()
    web = (WebServer(clients, host=HOST, port=0) if request_deadline is None
           else WebServer(clients, host=HOST, port=0, request_deadline=request_deadline))
    await web.start()
    return Web(backend, clients, web, aiohttp.ClientSession())


@pytest_asyncio.fixture
async def rig() -> AsyncIterator[Web]:
    made = await make_web()
    yield made
    await made.session.close()
    await made.web.close()
    await made.clients.close()


async def receive(ws: aiohttp.ClientWebSocketResponse, timeout: float = 5.0) -> dict[str, Any]:
    message = await ws.receive(timeout)
    assert message.type is aiohttp.WSMsgType.TEXT, message
    data = json.loads(message.data)
    assert isinstance(data, dict)
    return data


async def until_event(ws: aiohttp.ClientWebSocketResponse, name: str) -> dict[str, Any]:
    while True:
        data = await receive(ws)
        if data.get("event") == name:
            return data


async def raw_get(port: int, target: str, host: str = HOST) -> str:
    """A GET written by hand, so that the target reaches the server exactly as given."""
    reader, writer = await asyncio.open_connection(HOST, port)
    writer.write(f"GET {target} HTTP/1.1\r\nHost: {host}:{port}\r\nConnection: close\r\n\r\n"
                 .encode())
    head = (await reader.read(200)).decode("latin-1")
    writer.close()
    await writer.wait_closed()
    return head.split("\r\n", 1)[0]


# ---- the page ----------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_the_page_and_its_files_are_served_from_package_data(rig: Web) -> None:
    async with rig.session.get(rig.base + "/") as response:
        assert response.status == 200
        assert response.content_type == "text/html"
        body = await response.text()
        assert "/app.js" in body and "http" not in body.replace("http-equiv", "")
        assert "frame-ancestors 'none'" in response.headers["Content-Security-Policy"]
        assert response.headers["X-Content-Type-Options"] == "nosniff"
    for name, kind in (("app.js", "text/javascript"), ("style.css", "text/css"),
                       ("compass.js", "text/javascript")):
        async with rig.session.get(f"{rig.base}/{name}") as response:
            assert (response.status, response.content_type) == (200, kind)
            assert await response.read() == page_files()["/" + name].body


@pytest.mark.asyncio
@pytest.mark.parametrize("target", [
    "/../pyproject.toml", "/%2e%2e/%2e%2e/app.py", "/..%2f..%2fapp.py", "/web/",
    "/resources/", "/icons/", "//etc/passwd", "/app.js/", "/index.html%00.js", "/nothing",
])
async def test_no_path_leads_out_of_the_page_files_and_no_directory_is_listed(
        rig: Web, target: str) -> None:
    status = await raw_get(rig.web.port, target)
    assert status.split(" ")[1] in ("404", "400"), status


@pytest.mark.asyncio
async def test_other_methods_are_refused(rig: Web) -> None:
    async with rig.session.post(rig.base + "/", data=b"x") as response:
        assert response.status == 405


@pytest.mark.asyncio
async def test_a_host_name_that_is_not_this_computer_is_refused(rig: Web) -> None:
    status = await raw_get(rig.web.port, "/", host="attacker.example")
    assert " 421 " in status
    assert " 200 " in await raw_get(rig.web.port, "/", host="localhost")


@pytest.mark.asyncio
async def test_the_page_is_not_served_outside_client_allow(
        caplog: pytest.LogCaptureFixture) -> None:
    made = await make_web(allow=["10.0.0.0/8"])
    made.clients.local_addresses = ()  # 127.0.0.1 plays a computer outside ClientAllow
    try:
        with caplog.at_level(logging.WARNING, logger="moas_gui.net"):
            async with made.session.get(made.base + "/") as response:
                assert response.status == 403
                assert "ClientAllow" in await response.text()
            with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
                await made.socket()
            assert refused.value.status == 403
        assert "not in the allowed networks" in caplog.text
        assert made.clients.client_count == 0
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


# ---- the protocol over a WebSocket -------------------------------------------------------


@pytest.mark.asyncio
async def test_a_websocket_speaks_the_client_protocol_with_the_same_dispatcher(rig: Web) -> None:
    ws = await rig.socket()
    await ws.send_str(json.dumps({"id": 1, "cmd": "hello", "client": "tablet"}))
    reply = await receive(ws)
    assert reply["id"] == 1 and reply["ok"] and reply["result"]["protocol"] == 1
    state = await receive(ws)
    assert state["event"] == "state"
    assert {k: v for k, v in state.items() if k != "event"} == rig.backend.snapshot()
    assert rig.clients.client_count == 1
    assert [c.name for c in rig.clients.clients()] == ["tablet"]
    await ws.close()
    await _until(lambda: rig.clients.client_count == 0)


@pytest.mark.asyncio
async def test_a_selection_by_tcp_reaches_the_page_and_one_by_the_page_reaches_tcp(
        rig: Web) -> None:
    ws = await rig.socket()
    await ws.send_str('{"id": 1, "cmd": "hello", "client": "tablet"}')
    await until_event(ws, "state")
    tcp = await ProtocolClient.connect(HOST, rig.clients.port)
    try:
        await tcp.request("hello", client="desktop")
        await tcp.next_event("state")
        await tcp.request("frequency", station=1, radio=1, khz=14200.0)
        radio = await until_event(ws, "radio")
        assert (radio["station"], radio["radio"], radio["khz"]) == (1, 1, 14200.0)

        await ws.send_str('{"id": 2, "cmd": "layout", "station": 1, "radio": 1, '
                          '"rows": 4, "columns": 3}')
        layout = await receive(ws)
        assert layout["id"] == 2 and layout["ok"]
        free = next(b for b in layout["result"]["buttons"]
                    if b["type"] == "Antenna" and b["state"] == "available")
        await ws.send_str(json.dumps({"id": 3, "cmd": "select", "station": 1, "radio": 1,
                                      "antenna": free["id"]}))
        while True:
            data = await receive(ws)
            if data.get("id") == 3:
                break
        assert data["ok"] and free["id"] in (data["result"]["tx"], data["result"]["rx"])
        async with asyncio.timeout(5):
            while True:  # the frequency's own radio event comes first
                seen = await tcp.next_event("radio")
                if free["id"] in (seen["tx"], seen["rx"]):
                    break
    finally:
        await tcp.close()
        await ws.close()


@pytest.mark.asyncio
async def test_bad_messages_get_the_protocols_errors_and_three_close_the_socket(
        rig: Web) -> None:
    ws = await rig.socket()
    await ws.send_str('{"id": 9, "cmd": "launch"}')
    reply = await receive(ws)
    assert reply["id"] == 9 and reply["error"]["code"] == "unknown_cmd"
    await ws.send_str('{"id": 10, "cmd": "select", "station": 1}')
    reply = await receive(ws)
    assert reply["error"]["code"] == "bad_request" and '"radio" is missing' in \
        reply["error"]["message"]
    await ws.send_str("x" * (MAX_LINE + 10))
    reply = await receive(ws)
    assert reply == {"id": None, "ok": False, "error": {
        "code": "bad_request", "message": f"the line is longer than {MAX_LINE:,} bytes"}}
    await ws.send_bytes(b"\xff\xfe")
    reply = await receive(ws)
    assert "not UTF-8" in reply["error"]["message"]
    await ws.send_str("[1, 2]")
    reply = await receive(ws)
    assert "not an object" in reply["error"]["message"]
    closing = await ws.receive(5.0)
    assert closing.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED)
    await _until(lambda: rig.clients.client_count == 0)
    # the server carries on for everyone else
    again = await rig.socket()
    await again.send_str('{"id": 1, "cmd": "state"}')
    assert (await receive(again))["ok"]
    await again.close()


@pytest.mark.asyncio
async def test_a_websocket_from_another_sites_page_is_refused(
        rig: Web, caplog: pytest.LogCaptureFixture) -> None:
    with (caplog.at_level(logging.WARNING, logger="moas_gui.net"),
          pytest.raises(aiohttp.WSServerHandshakeError) as refused):
        await rig.socket(origin="http://evil.example")
    assert refused.value.status == 403
    assert "another site" in caplog.text
    # a program that is not a browser sends no Origin: ClientAllow alone decides
    ws = await rig.socket(origin="")
    await ws.send_str('{"id": 1, "cmd": "state"}')
    assert (await receive(ws))["ok"]
    await ws.close()


@pytest.mark.asyncio
async def test_pages_count_towards_the_servers_client_limit() -> None:
    made = await make_web(max_clients=2)
    try:
        tcp = await ProtocolClient.connect(HOST, made.clients.port)
        await tcp.request("hello", client="desktop")
        first = await made.socket()
        await first.send_str('{"id": 1, "cmd": "hello", "client": "tablet 1"}')
        await until_event(first, "state")
        # a TCP client and a page hold the two places: the next web connection is
        # refused before its request is read, and so is the next TCP client
        with pytest.raises(aiohttp.WSServerHandshakeError) as refused:
            await made.socket()
        assert refused.value.status == 503
        reader, writer = await asyncio.open_connection(HOST, made.clients.port)
        refusal = json.loads(await reader.readline())
        assert refusal["error"]["code"] == "unavailable" and "limit" in refusal["error"]["message"]
        writer.close()
        await writer.wait_closed()
        assert made.clients.client_count == 2
        await first.close()
        await _until(lambda: made.clients.admission.count == 1)
        third = await made.socket()
        await third.send_str('{"id": 1, "cmd": "hello", "client": "tablet 2"}')
        assert (await receive(third))["ok"]
        await third.close()
        await tcp.close()
    finally:
        await made.session.close()
        await made.web.close()
        await made.clients.close()


@pytest.mark.asyncio
async def test_closing_the_server_closes_the_pages(rig: Web) -> None:
    ws = await rig.socket()
    await ws.send_str('{"id": 1, "cmd": "hello", "client": "tablet"}')
    await until_event(ws, "state")
    await rig.web.close()
    message = await ws.receive(5.0)
    while message.type is aiohttp.WSMsgType.TEXT:  # what was on its way before the stop
        message = await ws.receive(5.0)
    # each page is told the server goes away (then its handler ends at once: no page
    # holds the stop up for aiohttp's shutdown timeout)
    assert (message.type, message.data, message.extra) == (
        aiohttp.WSMsgType.CLOSE, aiohttp.WSCloseCode.GOING_AWAY, "server stopping"), message
    assert rig.web._pages == set()


@pytest.mark.asyncio
async def test_a_port_in_use_is_said_and_nothing_else_stops(
        rig: Web, caplog: pytest.LogCaptureFixture) -> None:
    with caplog.at_level(logging.ERROR, logger="moas_gui.net"):
        assert await start_web(rig.clients, HOST, rig.web.port) is None
    assert f"TCP port {rig.web.port}" in caplog.text and "WebPort" in caplog.text
    async with rig.session.get(rig.base + "/") as response:
        assert response.status == 200


# ---- the guard's rules, and the configuration ----------------------------------------------


def test_host_names_of_this_computer_and_addresses_pass_others_do_not() -> None:
    names = frozenset({"localhost", "shack", "shack.local"})
    assert host_allowed("192.168.1.20:8080", names)
    assert host_allowed("[fe80::1]:8080", names)
    assert host_allowed("Shack.local:80", names)
    assert host_allowed("localhost", names)
    assert not host_allowed("evil.example:8080", names)
    assert not host_allowed("shack:http", names)
    assert not host_allowed(None, names)
    assert not host_allowed("", names)
    assert split_host("[::1]:99") == ("::1", "99")
    assert "localhost" in local_names()


def test_origin_must_be_the_servers_own_page() -> None:
    assert origin_complaint(None, "10.0.0.5:8080") is None
    assert origin_complaint("http://10.0.0.5:8080", "10.0.0.5:8080") is None
    assert origin_complaint("http://SHACK:8443", "shack:8443") is None
    assert origin_complaint(["http://shack"], "shack:80") is None
    assert origin_complaint([], "shack:80") is None
    assert "not a web page" in str(origin_complaint("https://shack:8443", "shack:8443"))
    assert "not a web page" in str(origin_complaint("http://shack:8443/x", "shack:8443"))
    assert "not a web page" in str(origin_complaint("http://a@shack:8443", "shack:8443"))
    assert "2 Origin headers" in str(origin_complaint(
        ["http://10.0.0.5:8080", "http://evil.example"], "10.0.0.5:8080"))
    assert "another site" in str(origin_complaint("http://10.0.0.5:8081", "10.0.0.5:8080"))
    assert "another site" in str(origin_complaint("http://evil.example", "10.0.0.5:8080"))
    assert "not a web page" in str(origin_complaint("null", "10.0.0.5:8080"))
    assert "not a web page" in str(origin_complaint("file://", "10.0.0.5:8080"))


def test_web_port_is_read_from_the_configuration(tmp_path: Any) -> None:
    from helpers import EXAMPLES

    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    assert load_config(EXAMPLES / "small-station.moas").unwrap().web_port is None
    data["WebPort"] = 8080
    path = tmp_path / "web.moas"
    path.write_text(json.dumps(data))
    assert load_config(path).unwrap().web_port == 8080
    data["WebPort"] = 70000
    path.write_text(json.dumps(data))
    result = load_config(path)
    assert result.config is None
    assert any("WebPort" in str(p) for p in result.errors)


async def _until(condition: Any, timeout: float = 5.0) -> None:
    async with asyncio.timeout(timeout):
        while not condition():
            await asyncio.sleep(0.005)
