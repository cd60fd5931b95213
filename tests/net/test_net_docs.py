"""docs/client-protocol.md stays true: its example session is replayed against
the server, and every command, argument, error code and event is documented."""

from __future__ import annotations

import asyncio
import json
import re
from pathlib import Path
from typing import Any

import pytest

from moas_gui import __version__
from moas_gui.net.backend import ErrorCode
from moas_gui.net.messages import EVENTS
from moas_gui.net.requests import COMMANDS
from moas_gui.net.server import ClientServer
from moas_gui.testing.fake_backend import FakeBackend

DOC = Path(__file__).resolve().parents[2] / "docs" / "client-protocol.md"
TEXT = DOC.read_text(encoding="utf-8")


def session() -> list[tuple[str, list[str]]]:
    block = TEXT.split("<!-- session -->", 1)[1].split("<!-- /session -->", 1)[0]
    steps: list[tuple[str, list[str]]] = []
    for line in block.splitlines():
        if line.startswith("> "):
            steps.append((line[2:], []))
        elif line.startswith("< "):
            steps[-1][1].append(line[2:])
    return steps


def normalised(message: Any) -> Any:
    if isinstance(message, dict) and isinstance(message.get("result"), dict) \
            and message["result"].get("server") == "moas-gui":
        message["result"]["version"] = __version__
    return message


@pytest.mark.asyncio
async def test_the_example_session_is_what_the_server_says() -> None:
    steps = session()
    assert len(steps) >= 10
    backend = FakeBackend()
    server = ClientServer(backend, host="127.0.0.1", port=0)
    backend.attach(server)
    await server.start()
    reader, writer = await asyncio.open_connection("127.0.0.1", server.port)
    try:
        for sent, expected in steps:
            writer.write(sent.encode() + b"\n")
            for line in expected:
                got = await asyncio.wait_for(reader.readline(), 5)
                assert json.loads(got) == normalised(json.loads(line)), f"after {sent}"
    finally:
        writer.close()
        await asyncio.gather(writer.wait_closed(), return_exceptions=True)
        await server.close()


def section(cmd: str) -> str:
    match = re.search(rf"^### {cmd}\n(.*?)(?=^##)", TEXT, re.DOTALL | re.MULTILINE)
    assert match, f"no section for {cmd}"
    return match.group(1)


@pytest.mark.parametrize("cmd", sorted(COMMANDS))
def test_every_command_and_argument_is_documented(cmd: str) -> None:
    text = section(cmd)
    for arg in COMMANDS[cmd].args:
        assert f"| `{arg.name}` |" in text, f"{cmd} does not document {arg.name}"
    assert f"| [`{cmd}`](#{cmd}) |" in TEXT


def test_every_error_code_and_event_is_documented() -> None:
    for code in ErrorCode:
        assert f"| `{code.value}` |" in TEXT
    for name in EVENTS:
        assert f"| `{name}` |" in TEXT
