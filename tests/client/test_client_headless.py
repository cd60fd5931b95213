"""``moas-client --headless``: a real process reading the real rigctld (Hamlib's dummy rig)
and a logger's OTRSP on a real pseudo-terminal, telling a server over TCP on 127.0.0.1.

The server here is the protocol server over the fake backend, so the test can
read exactly which requests arrived; the journey through the real server core
is the same client protocol.
"""

from __future__ import annotations

import asyncio
import os
import shutil
import signal
import sys
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest
import pytest_asyncio
from helpers import free_port, until
from rig_support import Pty, rigctl, start_rigctld

from moas_gui.cli.client import main
from moas_gui.net.server import ClientServer
from moas_gui.sources.spec import SourceSpec, parse_spec
from moas_gui.testing.fake_backend import FakeBackend

needs_hamlib = pytest.mark.skipif(shutil.which("rigctld") is None, reason="Hamlib's rigctld")
posix_only = pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals, signals")


# -- KIND[:OPTIONS] ---------------------------------------------------------------------

@pytest.mark.parametrize(("text", "spec"), [
    ("rigctld", SourceSpec("rigctld")),
    ("rigctld:4534,radio=2", SourceSpec("rigctld", "4534", {"radio": "2"})),
    ("flrig:shack-pc:12345,rate=5", SourceSpec("flrig", "shack-pc:12345", {"rate": "5"})),
    ("otrsp:/dev/ttyUSB1,ant1.3=5,ant2.3=6",
     SourceSpec("otrsp", "/dev/ttyUSB1", {}, {(1, 3): 5, (2, 3): 6})),
    ("wintest:name=STN1", SourceSpec("wintest", "", {"name": "STN1"})),
    ("N1MM:12061", SourceSpec("n1mm", "12061")),
])
def test_source_options_are_read(text: str, spec: SourceSpec) -> None:
    assert parse_spec(text) == spec
    assert parse_spec(spec.text()) == spec


@pytest.mark.parametrize(("text", "words"), [
    ("omnirig", "is not a source; the sources are rigctld"),
    ("rigctld:port=4532", "'port' is not one of its options (radio, rate, retry, station)"),
    ("rigctld:99999", "is not between 1 and 65535"),
    ("rigctld:4532,rate=0", "between 0.1 and 100"),
    ("otrsp", "otrsp needs the serial port"),
    ("otrsp:COM5,ant3.1=2", "should be ant1.N=ID or ant2.N=ID"),
    ("otrsp:COM5,ant1.300=2", "is not between 0 and 255"),
    ("wintest", "needs the Win-Test station name"),
    ("flrig:a:1,b:2", "two addresses"),
])
def test_bad_source_options_are_explained(text: str, words: str) -> None:
    with pytest.raises(ValueError, match=None) as refused:
        parse_spec(text)
    assert words in str(refused.value)


@pytest.mark.parametrize(("args", "words"), [
    (["--headless", "--station", "1"], "--headless needs at least one --source"),
    (["--headless", "--source", "rigctld"], "--headless needs --station"),
    (["--source", "bogus"], "--source bogus: 'bogus' is not a source"),
])
def test_bad_headless_command_lines_are_explained(args: list[str], words: str,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    # the command line is read before anything starts: moas-client's main in this process
    # (as tests/client/test_client_cli.py reads its other usage errors)
    with pytest.raises(SystemExit) as stopped:
        main(args)
    assert stopped.value.code == 2 and words in capsys.readouterr().err


# -- the journey --------------------------------------------------------------------------

class Server:
    def __init__(self, port: int) -> None:
        self.port = port
        self.backend = FakeBackend()
        self.server = ClientServer(self.backend, host="127.0.0.1", port=port)
        self.backend.attach(self.server)

    def calls(self, name: str) -> list[tuple[Any, ...]]:
        return [args for call, args in self.backend.calls if call == name]


@pytest_asyncio.fixture
async def servers() -> AsyncIterator[list[Server]]:
    made: list[Server] = []
    yield made
    for s in made:
        await s.server.close()


@pytest.mark.realtime
@needs_hamlib
@posix_only
@pytest.mark.asyncio
async def test_headless_client_tells_the_server_what_rigctld_and_otrsp_say(
        servers: list[Server], tmp_path: Path) -> None:
    server = Server(free_port())
    servers.append(server)
    await server.server.start()
    rig_port = free_port()
    rigctld = await asyncio.to_thread(start_rigctld, rig_port)
    pty = Pty(tmp_path / "otrsp")
    client = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.client", "--headless", "--station", "1",
        "--source", f"rigctld:{rig_port},rate=20",
        "--source", f"otrsp:{pty.link},radio2=9,ant1.3=2",
        f"127.0.0.1:{server.port}",
        stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
    try:
        await until(lambda: (1, 1, 145000.0, None) in server.calls("frequency"), 30,
                    what="the dummy rig's frequency at the server")
        await rigctl(rig_port, "F", "14025000")
        await until(lambda: (1, 1, 14025.0, None) in server.calls("frequency"),
                    what="rigctl's change at the server")
        await until(lambda: os.path.exists(pty.link))
        pty.write(b"TX1\rRX1S\rAUX13\r")
        await until(lambda: (1, 1, "active") in server.calls("set_focus"),
                    what="the transmit focus at the server")
        await until(lambda: (1, 1, "focus") in server.calls("set_focus"))
        await until(lambda: any(a[:3] == (1, 1, 2) and a[-1] is True
                                for a in server.calls("select")),
                    what="the AUX antenna selected alone")
        pty.write(b"TX2\r")  # radio 9 of station 1 does not exist: refused, logged, harmless
        # the server restarts: what the client knows arrives again without any change
        await server.server.close()
        again = Server(server.port)
        servers.append(again)
        await again.server.start()
        await until(lambda: (1, 1, 14025.0, None) in again.calls("frequency"), 30,
                    what="the frequency told again after the server came back")
        await until(lambda: (1, 1, "active") in again.calls("set_focus")
                    or (1, 9, "active") in again.calls("set_focus"))
        client.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(client.wait(), 20) == 0
        assert client.stderr is not None
        log = (await client.stderr.read()).decode()
        assert "Reading rigctld" in log and "Reading otrsp" in log
        assert "Traceback" not in log
        assert log.count("The server refused active") == 1
    finally:
        if client.returncode is None:
            client.kill()
            await client.wait()
        rigctld.terminate()
        rigctld.wait(5)
        if pty.master >= 0:
            os.close(pty.master)


ABSURD = (b"get_freq:\nFrequency: 1e99\nRPRT 0\nget_split_vfo:\nSplit: 0\nTX VFO: VFOA\n"
          b"RPRT 0\nget_split_freq:\nTX Frequency: 0\nRPRT 0\nget_ptt:\nPTT: 0\nRPRT 0\n")


@pytest.mark.realtime
@posix_only
@pytest.mark.asyncio
async def test_a_rig_daemon_answering_garbage_sends_nothing_to_the_server(
        servers: list[Server]) -> None:
    server = Server(free_port())
    servers.append(server)
    await server.server.start()
    polls = 0

    async def garbage(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        nonlocal polls
        try:
            while await reader.readuntil(b"+t\n"):
                polls += 1
                writer.write(ABSURD if polls % 2 else b"\xff\xfe<xml>&entity;\n" * 3)
        except (asyncio.IncompleteReadError, ConnectionError):
            pass
        finally:
            writer.close()

    rig = await asyncio.start_server(garbage, "127.0.0.1", 0)
    rig_port = rig.sockets[0].getsockname()[1]
    client = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.client", "--headless", "--station", "1",
        # retry=0.01: the pauses between the garbage answers are short (each answer that
        # makes no sense ends the connection; the next one comes after a growing pause)
        "--source", f"rigctld:{rig_port},rate=50,retry=0.01", f"127.0.0.1:{server.port}",
        stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.PIPE)
    try:
        await until(lambda: polls >= 4, 30, what="the client polling the garbage daemon")
        await until(lambda: server.server.client_count == 1, what="the client at the server")
        client.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(client.wait(), 20) == 0
        assert client.stderr is not None
        log = (await client.stderr.read()).decode()
    finally:
        if client.returncode is None:
            client.kill()
            await client.wait()
        rig.close()
    assert server.calls("frequency") == [] and server.calls("select") == []
    assert "Traceback" not in log
    assert "WARNING" not in log, log  # bad answers are Debug lines, not warnings
