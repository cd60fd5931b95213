"""The Antenna Genius front inside the server's policy (issue 38): a hold and its release
are actions with a role, logged with the operator's name; an operator's connection takes
the operators' own capacity; a client that stops reading is cut; lines that are no
commands write one log line a minute.  Real TCP on loopback addresses (127.0.0.2 and on
play the LAN), the real server in process with its switch in the built-in emulator."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import random
import socket
import threading
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import pytest_asyncio
from ag_client import AgClient, fields
from helpers import EXAMPLES, until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.edge.admission import Standing
from moas_gui.engine.operations import SetFrequency
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.log_limit import LogLimiter
from moas_gui.net.antenna_genius.server import AgServer
from moas_gui.operators import OperatorBook, Role
from moas_gui.status import ServerState

FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)
CODES = {"Ann": "471101", "Vic": "471102", "Ada": "471103"}
"""Ann operates radio 1/1, Vic has the view role, Ada is an admin."""


def options(**more: object) -> ServerOptions:
    settings: dict[str, object] = {"ag_port": 0, **more}
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         **settings)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def station(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> AsyncIterator[ServerApp]:
    """A server with ``--require-token`` and three operators with AG codes."""
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    book = OperatorBook()
    book.add("Ann", Role.OPERATE, frozenset({(1, 1)}), ag_code=CODES["Ann"])
    book.add("Vic", Role.VIEW, ag_code=CODES["Vic"])
    book.add("Ada", Role.ADMIN, ag_code=CODES["Ada"])
    server = ServerApp(options(require_token=True))
    assert (await server.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: server.status.state is ServerState.NORMAL)
    yield server
    await server.close()


def ag_of(app: ServerApp) -> AgServer:
    server = app._ag.server
    assert server is not None
    return server


async def signed_in(app: ServerApp, name: str, source: str) -> AgClient:
    client = await AgClient.connect(app.ag_ports[0], local=source)
    assert client.greeting == "V4.1.0 AG AUTH"
    answer = await client.ask(f"auth code={CODES[name]}")
    assert answer.code == 0, answer
    return client


def said(caplog: pytest.LogCaptureFixture, text: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if text in r.getMessage()]


# -- a hold and its release: actions with a role -------------------------------------------

@pytest.mark.asyncio
async def test_a_view_operator_can_neither_hold_nor_release_and_each_hold_is_logged_by_name(
        station: ServerApp, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    engine = station.engine
    assert engine is not None
    ada = await signed_in(station, "Ada", "127.0.0.3")
    vic = await signed_in(station, "Vic", "127.0.0.4")
    ann = await signed_in(station, "Ann", "127.0.0.2")
    try:
        # the view role may hold nothing: refused with the reason, nothing held
        answer = await vic.ask("port set 2 auto=0")
        assert answer.code == 0x20 and 'operator "Vic" has the view role' in answer.message
        assert engine.radio_view(1, 2).held_by is None
        # an admin holds radio 1/1; the log names her
        assert (await ada.ask("port set 1 auto=0")).code == 0
        assert engine.radio_view(1, 1).held_by == "Ada at 127.0.0.3"
        assert said(caplog, "Ada at 127.0.0.3:") and \
            said(caplog, "Ada at 127.0.0.3:")[-1].endswith(": holding radio 1/1")
        # the view role cannot release the admin's hold, alone or with a press
        for command in ("port set 1 auto=1", "port set 1 auto=1 txant=4 rxant=4"):
            answer = await vic.ask(command)
            assert answer.code == 0x20 and "view role" in answer.message, (command, answer)
            assert engine.radio_view(1, 1).held_by == "Ada at 127.0.0.3"
        # an operator may hold and release only its own radios
        answer = await ann.ask("port set 2 auto=0")
        assert answer.code == 0x20 and "not one of operator \"Ann\"'s" in answer.message
        assert engine.radio_view(1, 2).held_by is None
        assert (await ann.ask("port set 1 auto=1")).code == 0
        assert engine.radio_view(1, 1).held_by is None
        released = said(caplog, "Ann at 127.0.0.2:")
        assert released and released[-1].endswith(": releasing the hold of radio 1/1")
        assert not said(caplog, "Vic at 127.0.0.4:"), "a refusal is no action done"
    finally:
        for client in (ada, vic, ann):
            await client.close()


@pytest.mark.asyncio
async def test_a_refused_release_leaves_the_press_of_the_same_command_undone(
        station: ServerApp) -> None:
    """``port set 2 auto=1 band=6``: Ann may not release radio 1/2's hold, so the band
    of the same command is not tuned either (all of one command or nothing)."""
    engine = station.engine
    assert engine is not None
    ada = await signed_in(station, "Ada", "127.0.0.3")
    ann = await signed_in(station, "Ann", "127.0.0.2")
    try:
        assert (await ada.ask("port set 2 auto=0")).code == 0
        before = engine.radio_view(1, 2)
        answer = await ann.ask("port set 2 band=6 auto=1")
        assert answer.code == 0x20 and "Ann" in answer.message
        assert engine.radio_view(1, 2) == before
    finally:
        await ada.close()
        await ann.close()


# -- the operators' own capacity -----------------------------------------------------------

@dataclass
class Crowd:
    opened: int = 0
    stop: bool = False


async def crowd_member(port: int, source: str, crowd: Crowd) -> None:
    """A connection from ``source`` that says one line and stays; opened again soon
    after the server closes it."""
    while not crowd.stop:
        try:
            reader, writer = await asyncio.open_connection("127.0.0.1", port,
                                                           local_addr=(source, 0))
        except OSError:
            await asyncio.sleep(0.05)
            continue
        crowd.opened += 1
        try:
            writer.write(b"C1|ping\r")
            while not crowd.stop and await reader.read(4096):
                pass
        except (ConnectionError, OSError):
            pass
        finally:
            writer.close()
        await asyncio.sleep(0.02)


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_a_crowd_of_200_addresses_does_not_stop_new_operator_connections(
        station: ServerApp) -> None:
    ag = ag_of(station)
    pool = ag.access.admission
    port = station.ag_ports[0]
    crowd = Crowd()
    members = [asyncio.create_task(crowd_member(port, f"127.0.3.{n}", crowd))
               for n in range(1, 201)]
    operators: list[AgClient] = []
    try:
        await until(lambda: crowd.opened >= 200 and pool.count - pool.operator_count
                    >= pool.total, timeout=60, what="the crowd filling the pool")
        def full() -> bool:
            return pool.count - pool.operator_count >= pool.total

        for _ in range(20):  # more than one address may hold besides operators (16)
            # each operator comes while the crowd fills every place it may take
            await until(full, timeout=60, what="the crowd filling the pool again")
            operators.append(await signed_in(station, "Ann", "127.0.0.2"))
        assert pool.operator_count == 20
        opened = crowd.opened
        await until(lambda: crowd.opened > opened + 200, timeout=60,
                    what="the crowd coming back 200 times more")
        for client in operators:  # every operator's connection is still served
            assert (await client.ask("ping")).code == 0
    finally:
        crowd.stop = True
        for client in operators:
            await client.close()
        for task in members:
            task.cancel()
        await asyncio.gather(*members, return_exceptions=True)


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_an_auth_waiting_for_its_check_keeps_its_place_under_a_crowd(
        station: ServerApp) -> None:
    """The code is checked on the secret worker (held busy here): while the ``auth``
    waits for the answer, a crowd of addresses filling the pool (each sending a line,
    so that the waiting connection is the idlest) cannot take its place, and the answer
    moves it to the operators' capacity."""
    ag = ag_of(station)
    pool = ag.access.admission
    worker = station.secrets.worker
    release = threading.Event()
    crowd: list[asyncio.StreamWriter] = []
    holding = asyncio.ensure_future(worker.run(lambda: release.wait(30), known=True))
    ann = await AgClient.connect(station.ag_ports[0], local="127.0.0.2")
    try:
        seq = await ann.send(f"auth code={CODES['Ann']}")
        await until(lambda: worker.waiting == 2, what="the auth's check queued")
        (waiting,) = [t for t in pool.tickets() if t.address.startswith("127.0.0.2:")]
        for n in range(1, pool.total + 20):
            _reader, writer = await asyncio.open_connection(
                "127.0.0.1", station.ag_ports[0], local_addr=(f"127.0.5.{n}", 0))
            writer.write(b"C1|ping\r")
            crowd.append(writer)
            await until(lambda n=n: pool.open_from(f"127.0.5.{n}") == 1,
                        what=f"127.0.5.{n} admitted")
        assert pool.count - pool.operator_count == pool.total  # full, and made room
        assert not waiting.released and waiting.checks == 1
        release.set()
        await holding
        assert (await ann.reply(seq)).code == 0
        assert pool.operator_count == 1 and waiting.standing is Standing.OPERATOR
        assert (await ann.ask("ping")).code == 0
    finally:
        release.set()
        for writer in crowd:
            writer.close()
        await ann.close()


# -- a client that stops reading -------------------------------------------------------------

def never_reading(port: int, source: str) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.bind((source, 0))
    sock.connect(("127.0.0.1", port))
    sock.setblocking(False)
    return sock


def resident_kb() -> int:
    with open(f"/proc/{os.getpid()}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS")


@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_subscribers_that_never_read_are_cut_at_1_mib_and_the_others_get_every_line(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    app = ServerApp(options())
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    ag = ag_of(app)
    device = ag.devices[0]
    stuck = [never_reading(app.ag_ports[0], f"127.0.4.{n}") for n in range(1, 17)]
    healthy = await AgClient.connect(app.ag_ports[0])
    try:
        for sock in stuck:
            sock.send(b"C1|sub port all\r")
        assert (await healthy.ask("sub port all")).code == 0
        await until(lambda: sum(s.ports for s in device.sessions) == 17,
                    what="17 subscribers")
        for session in device.sessions:
            if session.host != "127.0.0.1":
                # the kernel's share of each stuck connection kept small (it grows to
                # 4 MiB on its own): what piles up waits in the server, where the 1 MiB
                # bound is, after about 11,000 pushes rather than 38,000
                sock = session.writer.get_extra_info("socket")
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
        engine = app.engine
        assert engine is not None
        heard: list[str] = []

        async def read_every_line() -> None:
            with contextlib.suppress(ConnectionError):
                while raw := await healthy.reader.readline():
                    heard.append(raw.decode().rstrip("\r\n"))

        reading = asyncio.create_task(read_every_line())
        before = resident_kb()
        peak = pushed = 0
        while any(s.ports for s in device.sessions if s.host != "127.0.0.1") \
                and pushed < 200_000:
            # a new frequency on radio 1 each time: a new line for every subscriber
            app.act(SetFrequency(1, 1, 14000.0 + (pushed % 300) + 0.001 * (pushed // 300)))
            pushed += 1
            peak = max(peak, sum(s.writer.transport.get_write_buffer_size()
                                 for s in device.sessions if s.host != "127.0.0.1"))
            if pushed % 16 == 0:
                await asyncio.sleep(0)
        assert pushed < 200_000, "the stuck subscribers were never cut"
        assert peak <= 16 * ((1 << 20) + 512), f"{peak:,} bytes waited at once"
        grown = resident_kb() - before
        print(f"{pushed} pushes; 16 cut; at most {peak:,} bytes waited; RSS +{grown} kB")
        assert grown < 64 * 1024, f"memory grew {grown} kB"
        await until(lambda: [s.host for s in device.sessions] == ["127.0.0.1"],
                    what="the stuck ones gone")
        cut = said(caplog, "it stopped reading")
        assert len(cut) == 1, cut  # one line a minute for the kind, whoever is cut
        # the reading subscriber got every line, in order, and is served on
        await until(lambda: len(heard) >= pushed, timeout=60, what="every line heard")
        assert len(heard) == pushed
        last = fields(heard[-1])
        assert heard[-1].startswith("S0|port 1 ")
        assert last["freq"] == f"{engine.radio_view(1, 1).khz / 1000:.6f}"
        seq = await healthy.send("ping")
        await until(lambda: heard[-1] == f"R{seq}|0|", what="the answer to a ping")
        reading.cancel()
    finally:
        for sock in stuck:
            sock.close()
        await healthy.close()
        await app.close()


# -- lines that are no commands: one log line a minute ---------------------------------------

@pytest.mark.asyncio
@pytest.mark.timeout(120)
async def test_a_mib_of_binary_writes_one_log_line_and_the_next_one_counts_the_rest(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG)
    app = ServerApp(options())
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    ag = ag_of(app)
    now = [0.0]
    ag.trouble = LogLimiter(clock=lambda: now[0])
    flooder = await AgClient.connect(app.ag_ports[0])
    other = await AgClient.connect(app.ag_ports[0])
    try:
        data = random.Random(38).randbytes(1 << 20)
        flooder.writer.write(data + b"\r")
        # a ping after the flood: its answer comes after every answer to the flood
        last = "R999999|0|"
        flooder.writer.write(b"C999999|ping\r")
        answers = 0

        async def drain_answers() -> None:
            nonlocal answers
            with contextlib.suppress(ConnectionError):
                while raw := await asyncio.wait_for(flooder.reader.readline(), 60):
                    if raw.decode(errors="replace").rstrip("\r\n") == last:
                        return
                    answers += 1
            raise AssertionError("the flooder's connection ended before the ping's answer")

        reading = asyncio.create_task(drain_answers())
        await flooder.writer.drain()
        await reading
        lines = said(caplog, "Antenna Genius: 127.0.0.1:")
        print(f"1 MiB of binary: {answers} answers, {len(lines)} log lines")
        assert answers > 1000, "the flood was not read as many lines"
        assert len(lines) == 1, lines
        assert (await other.ask("ping")).code == 0  # others are served meanwhile
        now[0] += 61.0  # a minute on: the next such line says how many were left out
        other.writer.write(b"not a command\r")
        assert (await other.line()).startswith("R0|10|not a command line")
        lines = said(caplog, "Antenna Genius: 127.0.0.1:")
        assert len(lines) == 2 and f"({answers - 1:,} more like it since the last" in lines[1]
    finally:
        await flooder.close()
        await other.close()
        await app.close()
