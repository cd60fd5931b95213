"""Removing an operator ends every session it has on every front -- the client port, the
WebSocket (no further command obeyed), the Antenna Genius front, the contest report --
of a real ``moas-server`` process, whether or not it runs with ``--new-instance`` and
whether or not ``--remove-operator`` could reach it: the server notices the operators
file's change itself."""

from __future__ import annotations

import asyncio
import json
import os
import socket
import subprocess
import sys
from pathlib import Path
from typing import Any

import aiohttp
import pytest
from ag_client import AgClient
from helpers import free_port, until

from moas_gui.operators import FILE_NAME, OperatorBook, Role
from moas_gui.places import APP

pytestmark = pytest.mark.realtime

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
LAN = "127.0.0.2"


def environment(tmp_path: Path, runtime: Path) -> dict[str, str]:
    return dict(os.environ, XDG_RUNTIME_DIR=str(runtime), XDG_CONFIG_HOME=str(tmp_path / "cfg"),
                XDG_STATE_HOME=str(tmp_path / "state"), XDG_DATA_HOME=str(tmp_path / "data"),
                PYTHONUNBUFFERED="1", QT_QPA_PLATFORM="offscreen")


def command(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args], env=env,
                          capture_output=True, text=True, check=False, timeout=60)


class Fronts:
    """One session of the operator on each front, from a LAN address."""

    def __init__(self) -> None:
        self.tcp: tuple[asyncio.StreamReader, asyncio.StreamWriter] | None = None
        self.http: aiohttp.ClientSession | None = None
        self.ws: aiohttp.ClientWebSocketResponse | None = None
        self.ag: AgClient | None = None

    async def open(self, ports: dict[str, int], token: str, code: str) -> None:
        reader, writer = await asyncio.open_connection("127.0.0.1", ports["tcp"],
                                                       local_addr=(LAN, 0))
        self.tcp = reader, writer
        writer.write(json.dumps({"id": 1, "cmd": "hello", "client": "t", "token": token})
                     .encode() + b"\n")
        assert (await reply_to(reader, 1))["ok"]
        self.http = aiohttp.ClientSession(
            connector=aiohttp.TCPConnector(local_addr=(LAN, 0), force_close=True))
        self.ws = await self.http.ws_connect(f"http://127.0.0.1:{ports['web']}/ws")
        await self.ws.send_str(json.dumps({"id": 1, "cmd": "hello", "client": "w",
                                           "token": token}))
        assert (await ws_reply(self.ws, 1))["ok"]
        self.ag = await AgClient.connect(ports["ag"], local=LAN)
        while "try again" in (answer := await self.ag.ask(f"auth code={code}")).message:
            await asyncio.sleep(0.2)
        assert answer.code == 0, answer

    async def report(self, ports: dict[str, int], token: str) -> int:
        assert self.http is not None
        async with self.http.get(f"http://127.0.0.1:{ports['web']}/report",
                                 headers={"Authorization": f"Bearer {token}"}) as response:
            return response.status

    async def all_ended(self) -> None:
        assert self.tcp is not None and self.ws is not None and self.ag is not None
        reader = self.tcp[0]
        while await asyncio.wait_for(reader.read(65536), 10):  # the events, then the end
            pass
        # the WebSocket obeys nothing more: a command gets no answer, the socket closes
        try:
            await self.ws.send_str(json.dumps({"id": 9, "cmd": "state"}))
        except ConnectionError:
            pass
        while True:
            message = await asyncio.wait_for(self.ws.receive(), 10)
            if message.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED,
                                aiohttp.WSMsgType.CLOSING, aiohttp.WSMsgType.ERROR):
                break
            assert json.loads(message.data).get("id") != 9, "a command was obeyed"
        assert await self.ag.closed()

    async def close(self) -> None:
        if self.tcp is not None:
            self.tcp[1].close()
        if self.ws is not None:
            await self.ws.close()
        if self.http is not None:
            await self.http.close()
        if self.ag is not None:
            await self.ag.close()


async def reply_to(reader: asyncio.StreamReader, wanted: int) -> dict[str, Any]:
    while True:
        line = await asyncio.wait_for(reader.readline(), 30)
        assert line, "the server closed the connection"
        reply: dict[str, Any] = json.loads(line)
        if reply.get("id") == wanted:
            return reply


async def ws_reply(ws: aiohttp.ClientWebSocketResponse, wanted: int) -> dict[str, Any]:
    while True:
        message = await asyncio.wait_for(ws.receive(), 30)
        assert message.type is aiohttp.WSMsgType.TEXT, message
        reply: dict[str, Any] = json.loads(message.data)
        if reply.get("id") == wanted:
            return reply


@pytest.mark.asyncio
@pytest.mark.timeout(120)
@pytest.mark.parametrize("alone", [True, False], ids=["new-instance", "told"])
async def test_removing_an_operator_ends_its_sessions_on_every_front(
        tmp_path: Path, runtime_dir: Path, alone: bool) -> None:
    env = environment(tmp_path, runtime_dir)
    # the operators written as --add-operator writes them (tests/server/test_server_operators.py
    # runs that command): here in this process, the server and --remove-operator are processes
    book = OperatorBook(Path(env["XDG_CONFIG_HOME"]) / APP / FILE_NAME)
    token = book.add("otto", Role.OPERATE, ag_code="471100")[1]
    vera = book.add("vera", Role.VIEW)[1]
    ports = {"tcp": free_port(socket.SOCK_STREAM), "web": free_port(socket.SOCK_STREAM),
             "ag": free_port(socket.SOCK_STREAM)}
    server = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", str(EXAMPLES / "small-station.moas"),
        "--headless", "--bind", "127.0.0.1", "--tcp-port", str(ports["tcp"]),
        "--web-port", str(ports["web"]), "--ag-port", str(ports["ag"]), "--udp-port", "0",
        "--no-rotator-program", "--require-token", "--log-level", "info",
        *(["--new-instance"] if alone else []),
        env=env, stderr=asyncio.subprocess.PIPE)
    said: list[str] = []

    async def collect() -> None:
        assert server.stderr is not None
        async for line in server.stderr:
            said.append(line.decode(errors="replace"))

    collector = asyncio.create_task(collect())
    fronts = Fronts()
    other = Fronts()
    try:
        await until(lambda: any("Antenna Genius device 1" in line for line in said), 60,
                    "the server's fronts")
        await fronts.open(ports, token, "471100")
        assert await fronts.report(ports, token) == 200
        reader, writer = await asyncio.open_connection("127.0.0.1", ports["tcp"],
                                                       local_addr=(LAN, 0))
        other.tcp = reader, writer
        writer.write(json.dumps({"id": 1, "cmd": "hello", "client": "v", "token": vera})
                     .encode() + b"\n")
        assert (await reply_to(reader, 1))["ok"]

        removed = await asyncio.to_thread(
            command, env, "--remove-operator", "otto", *(["--new-instance"] if alone else []))
        assert removed.returncode == 0, removed.stderr
        if alone:  # this launch told nobody, and says so
            assert "No running server was told" in removed.stdout
            assert "notices the change itself" in removed.stdout
        else:
            assert "sessions of operator otto ended" in removed.stdout
        await fronts.all_ended()
        assert await fronts.report(ports, token) == 401
        writer.write(json.dumps({"id": 2, "cmd": "state"}).encode() + b"\n")
        assert "result" in await reply_to(reader, 2)  # another operator goes on
    finally:
        await fronts.close()
        await other.close()
        server.terminate()
        await asyncio.wait_for(server.wait(), 30)
        await collector
    text = "".join(said)
    assert 'Operator "otto" was removed: 3 sessions ended' in text
    assert token.rsplit(".", 1)[1][:10] not in text
