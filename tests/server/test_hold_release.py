"""A hold outlives the program that set it; who set it and since when are shown, and an
operator whose role covers the radio releases it over the client protocol (issue 40):
the real server in process, an Antenna Genius program and client-protocol clients over
real TCP on loopback addresses (127.0.0.2 and on play the LAN)."""

from __future__ import annotations

import asyncio
import json
import logging
import time
from collections.abc import AsyncIterator
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pytest
import pytest_asyncio
from ag_client import AgClient
from helpers import EXAMPLES, until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine.operations import Hold, SetFrequency
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.operators import OperatorBook, Role
from moas_gui.status import ServerState

FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


class Client:
    """A client-protocol connection that keeps the events it meets."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.events: list[dict[str, Any]] = []
        self.next_id = 0

    @classmethod
    async def open(cls, address: tuple[str, int], source: str) -> Client:
        reader, writer = await asyncio.open_connection(*address, local_addr=(source, 0))
        return cls(reader, writer)

    async def ask(self, cmd: str, **args: Any) -> dict[str, Any]:
        self.next_id += 1
        self.writer.write(json.dumps({"id": self.next_id, "cmd": cmd, **args}).encode() + b"\n")
        while True:
            message = json.loads(await asyncio.wait_for(self.reader.readline(), 10))
            if "event" in message:
                self.events.append(message)
            elif message.get("id") == self.next_id:
                return message

    async def radio_event(self, station: int, radio: int,
                          check: Any = lambda entry: True) -> dict[str, Any]:
        while True:
            for i, message in enumerate(self.events):
                if message["event"] == "radio" and (message.get("station"),
                                                    message.get("radio")) == (station, radio) \
                        and check(message):
                    del self.events[:i + 1]
                    return dict(message)
            self.events.clear()
            self.events.append(json.loads(await asyncio.wait_for(self.reader.readline(), 10)))

    def close(self) -> None:
        self.writer.close()


@pytest_asyncio.fixture
async def station(tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                  ) -> AsyncIterator[tuple[ServerApp, dict[str, str]]]:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    book = OperatorBook()
    tokens = {
        "Vic": book.add("Vic", Role.VIEW)[1],
        "Bob": book.add("Bob", Role.OPERATE, frozenset({(1, 2)}))[1],
        "Ann": book.add("Ann", Role.OPERATE, frozenset({(1, 1)}))[1],
    }
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False,
                                  switch_timing=FAST, ag_port=0))
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: app.status.state is ServerState.NORMAL)
    yield app, tokens
    await app.close()


async def operator(app: ServerApp, tokens: dict[str, str], name: str, source: str) -> Client:
    address = app.client_address
    assert address is not None
    client = await Client.open(address, source)
    said = await client.ask("hello", client="test", token=tokens[name])
    assert said["ok"], said
    return client


@pytest.mark.asyncio
async def test_a_hold_outlives_its_program_and_an_operator_whose_role_covers_it_releases_it(
        station: tuple[ServerApp, dict[str, str]], caplog: pytest.LogCaptureFixture) -> None:
    app, tokens = station
    caplog.set_level(logging.INFO)
    engine = app.engine
    assert engine is not None
    app.act(SetFrequency(1, 1, 14025.0))
    program = await AgClient.connect(app.ag_ports[0])
    before = time.time()
    assert (await program.ask("port set 1 auto=0 rxant=4 txant=4")).code == 0
    await program.close()  # the program goes away: the hold stays
    await until(lambda: not app._ag.server or not app._ag.server.devices[0].sessions)
    entry = app.radio_entry(1, 1)
    assert entry["held_by"] == "an Antenna Genius client at 127.0.0.1"
    since = datetime.strptime(str(entry["held_since"]), "%Y-%m-%dT%H:%M:%SZ") \
        .replace(tzinfo=UTC).timestamp()
    assert before - 1 <= since <= time.time()

    ann = await operator(app, tokens, "Ann", "127.0.0.2")
    vic = await operator(app, tokens, "Vic", "127.0.0.3")
    bob = await operator(app, tokens, "Bob", "127.0.0.4")
    try:
        # the hello tells a client who it acts as, so it offers only what it may
        said = await Client.open(app.client_address or ("", 0), "127.0.0.5")
        hello = await said.ask("hello", client="t", token=tokens["Ann"])
        assert hello["result"]["operator"] == {"name": "Ann", "role": "operate",
                                               "radios": [[1, 1]]}
        said.close()
        for who, words in ((vic, 'has the view role'), (bob, "not one of operator \"Bob\"'s")):
            refused = await who.ask("release", station=1, radio=1)
            assert refused["ok"] is False and refused["error"]["code"] == "forbidden"
            assert words in refused["error"]["message"]
            assert engine.radio_view(1, 1).held_by is not None
        assert (await ann.ask("release", station=1, radio=1)) == {"id": ann.next_id, "ok": True,
                                                                 "result": {}}
        released = await bob.radio_event(1, 1, lambda e: e.get("held_by") is None)
        assert released["held_since"] is None and engine.radio_view(1, 1).held_by is None
        lines = [r.getMessage() for r in caplog.records]
        assert any(line.startswith("Ann at 127.0.0.2:") and
                   line.endswith(": releasing the hold of radio 1/1") for line in lines)
        # nothing held: nothing to do
        assert (await ann.ask("release", station=1, radio=1))["ok"] is True
        assert (await ann.ask("release", station=9, radio=1))["error"]["code"] == "not_found"
    finally:
        for client in (ann, vic, bob):
            client.close()


@pytest.mark.asyncio
async def test_an_anonymous_release_from_this_computer_is_logged_with_whom_it_freed(
        station: tuple[ServerApp, dict[str, str]], caplog: pytest.LogCaptureFixture) -> None:
    app, _tokens = station
    caplog.set_level(logging.INFO)
    app.act(Hold(1, 2, "Log4YM at 192.168.1.20", since=time.time()))
    address = app.client_address
    assert address is not None
    local = await Client.open(address, "127.0.0.1")
    try:
        assert (await local.ask("hello", client="desk"))["ok"]
        assert "operator" not in (await local.ask("hello", client="desk"))["result"]
        assert (await local.ask("release", station=1, radio=2))["ok"] is True
        assert app.radio_entry(1, 2)["held_by"] is None
        assert any("released the hold of radio 1/2 (held by Log4YM at 192.168.1.20)"
                   in r.getMessage() for r in caplog.records)
    finally:
        local.close()
