"""Antenna Genius codes cannot be guessed in a contest weekend: 6 digits at least,
failures counted per operator from every address together and per address, at every
``auth`` (an open session's too), with a growing back-off that spares a device that
signed in before; wrong codes are one log line a minute however many come.  Real AG
connections from several loopback addresses."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from ag_client import AgClient

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine_backend import AgEngineBackend
from moas_gui.net.antenna_genius.access import SimpleAccess
from moas_gui.net.antenna_genius.server import AgServer
from moas_gui.net.secrets import ADDRESS_FREE, SecretGuard

CODE = "471100"


class Lan(SimpleAccess):
    def needs_token(self, host: str) -> bool:  # as for LAN peers with --require-token
        return True


class Station:
    def __init__(self, ag: AgServer, now: list[float]) -> None:
        self.ag, self.now = ag, now

    async def client(self, source: str) -> AgClient:
        return await AgClient.connect(self.ag.port, local=source)


@pytest_asyncio.fixture
async def station() -> AsyncIterator[Station]:
    now = [1000.0]
    guard = SecretGuard(codes={CODE: "Ann"}, clock=lambda: now[0])
    core = AgEngineBackend(ServerApp(ServerOptions(ag_port=None)))
    ag = AgServer(core, "127.0.0.1", 0, access=Lan(guard=guard))
    await ag.start(None)
    yield Station(ag, now)
    await ag.close()
    guard.close()


@pytest.mark.asyncio
async def test_a_failure_from_one_address_holds_back_every_other_new_one(
        station: Station) -> None:
    guesser = await station.client("127.0.0.2")
    assert (await guesser.ask("auth code=000000")).code == 0xFF
    ann = await station.client("127.0.0.3")  # the right code, from an address never seen
    held = await ann.ask(f"auth code={CODE}")
    assert held.code == 0xFF and "try again in 1 s" in held.message
    station.now[0] += 1.0
    assert (await ann.ask(f"auth code={CODE}")).code == 0
    for n in range(5):  # each failure doubles the wait, whatever the address
        station.now[0] += 120.0
        other = await station.client(f"127.0.0.{10 + n}")
        assert (await other.ask("auth code=000000")).code == 0xFF
        waiting = await other.ask(f"auth code={CODE}")
        assert f"try again in {2 ** (n + 1)} s" in waiting.message
        await other.close()
    # the device that signed in before is not held back by them
    again = await station.client("127.0.0.3")
    assert (await again.ask(f"auth code={CODE}")).code == 0
    for each in (guesser, ann, again):
        await each.close()


@pytest.mark.asyncio
async def test_every_auth_counts_an_open_sessions_too(station: Station) -> None:
    ann = await station.client("127.0.0.3")
    assert (await ann.ask(f"auth code={CODE}")).code == 0
    assert (await ann.ask("info get")).code == 0
    for _ in range(ADDRESS_FREE + 1):  # an authenticated session guessing other codes
        assert (await ann.ask("auth code=000000")).code == 0xFF
    assert await ann.closed()  # its address's budget is spent: the session ends
    late = await station.client("127.0.0.3")
    assert late.greeting == ""  # and the address waits
    await ann.close()
    await late.close()


@pytest.mark.asyncio
async def test_wrong_codes_are_one_log_line_a_minute_however_many(
        station: Station, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui")
    sent = 0
    for n in range(40):  # 40 addresses, 5 wrong codes each, as fast as answered
        client = await station.client(f"127.0.2.{n + 1}")
        for k in range(5):
            answer = await client.ask(f"auth code={n:03d}{k:03d}")
            assert answer.code == 0xFF
            sent += 1
        await client.close()
    lines = [r.getMessage() for r in caplog.records
             if r.levelno >= logging.INFO and r.name.startswith("moas_gui")]
    about_codes = [m for m in lines if "code" in m]
    assert sent == 200
    assert sum("A wrong code" in m for m in about_codes) == 1
    assert sum("too many wrong codes" in m for m in about_codes) == 1
    assert len(about_codes) <= 3, about_codes


@pytest.mark.realtime
def test_add_operator_refuses_a_code_shorter_than_6_digits_saying_why(tmp_path: Path) -> None:
    env = dict(os.environ, XDG_CONFIG_HOME=str(tmp_path), PYTHONUNBUFFERED="1")
    short = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--add-operator",
                            "Ann", "--role", "operate", "--ag-code", "4711"], env=env,
                           capture_output=True, text=True, check=False, timeout=60)
    assert short.returncode == 1
    assert "6 to 9 digits" in short.stderr and "4 digits are too few" in short.stderr
    assert not (tmp_path / "moas-gui" / "operators.json").exists()
