"""The Antenna Genius front of a real server, in process (issue 32): a client from the
public description over real TCP on 127.0.0.1, the switch in the built-in emulator, a
logger's real N1MM packets over UDP."""

from __future__ import annotations

import asyncio
import json
import socket
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from ag_client import AgClient, fields
from helpers import free_port, until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.config.model import RadioRef
from moas_gui.engine_backend import AgEngineBackend
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.net.antenna_genius.server import AgServer, AgTiming
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def options(**more: object) -> ServerOptions:
    settings: dict[str, object] = {"ag_port": 0, **more}
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         **settings)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    server = ServerApp(options())
    assert (await server.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: server.status.state is ServerState.NORMAL)
    yield server
    await server.close()


@pytest_asyncio.fixture
async def client(app: ServerApp) -> AsyncIterator[AgClient]:
    ag = await AgClient.connect(app.ag_ports[0])
    yield ag
    await ag.close()


def two_free_ports() -> int:
    """A TCP port free on 127.0.0.1 whose next one is free too."""
    for _ in range(50):
        base = free_port()
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", base + 1))
            except OSError:
                continue
            return base
    raise AssertionError("no two free ports in a row")


def logger_band(app: ServerApp, khz: float, radio: int = 1) -> None:
    address = app.n1mm_address
    assert address is not None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(radio_info_packet(radio, khz), address)


@pytest.mark.asyncio
async def test_greeting_info_antennas_and_bands(app: ServerApp, client: AgClient) -> None:
    assert client.greeting == "V4.1.0 AG"
    info = await client.ask("info get")
    assert info.code == 0 and info.message.startswith("info v=4.1.0 ")
    said = fields(info.message)
    assert said["ports"] == "2" and said["antennas"] == "4" and said["mode"] == "master"
    assert said["name"] == "MOAS_small-station"
    antennas = await client.ask("antenna list", listing=True)
    assert antennas.code == 0
    assert [line.split()[1] for line in antennas.lines] == ["1", "2", "3", "4"]
    assert fields(antennas.lines[3])["name"] == "All-band_vertical"
    bands = await client.ask("band list", listing=True)
    assert len(bands.lines) == 16 and fields(bands.lines[6])["name"] == "20m"


@pytest.mark.asyncio
@pytest.mark.parametrize("ending", [b"\r", b"\n", b"\r\n"])
async def test_port_get_answers_a_line_and_the_empty_terminator_whatever_the_ending(
        app: ServerApp, client: AgClient, ending: bytes) -> None:
    seq = await client.send("port get 1", ending)
    first = await client.line()
    assert first.startswith(f"R{seq}|0|port 1 auto=1 source=AUTO band=0 ")
    assert await client.line() == f"R{seq}|0|"  # the terminator AetherSDR waits for
    assert (await client.ask("ping", ending=ending)).code == 0


@pytest.mark.asyncio
async def test_logger_band_change_is_pushed_to_subscribers_only(app: ServerApp,
                                                                 client: AgClient) -> None:
    assert (await client.ask("sub port all")).code == 0
    quiet = await AgClient.connect(app.ag_ports[0])
    try:
        logger_band(app, 14025.0)
        line = await client.status("port 1 ")
        said = fields(line)
        assert said["band"] == "6" and said["txant"] == "1" and said["rxant"] == "1"
        assert said["freq"] == "14.025000" and said["tx"] == "0" and said["auto"] == "1"
        got = await client.ask("port get 1", listing=True)
        assert got.lines == [line]
        # a client that did not subscribe hears nothing but its answers
        assert (await quiet.ask("ping")).code == 0
        assert quiet.statuses == []
        assert (await client.ask("unsub port all")).code == 0
        logger_band(app, 7025.0)
        engine = app.engine
        assert engine is not None
        await until(lambda: engine.radio_view(1, 1).khz == 7025.0)
        assert (await client.ask("ping")).code == 0
        assert not any(s.startswith("port 1 ") for s in client.statuses)
    finally:
        await quiet.close()


@pytest.mark.asyncio
async def test_port_set_is_a_press_moves_the_relays_and_tells_every_subscriber(
        app: ServerApp, client: AgClient) -> None:
    other = await AgClient.connect(app.ag_ports[0])
    try:
        for c in (client, other):
            assert (await c.ask("sub port all")).code == 0
        logger_band(app, 14025.0)
        await client.status("port 1 ")
        await other.status("port 1 ")
        emulator = app.emulators()[1]
        before = emulator.view().relays
        answer = await client.ask("port set 1 rxant=4 txant=4")
        assert answer.code == 0, answer
        for c in (client, other):
            said = fields(await c.status("port 1 "))
            assert said["rxant"] == "4" and said["txant"] == "4" and said["band"] == "6"
        engine = app.engine
        assert engine is not None
        assert engine.radio_view(1, 1).tx == 3  # the vertical's ID
        await until(lambda: emulator.view().relays != before)
    finally:
        await other.close()


@pytest.mark.asyncio
async def test_what_the_engine_refuses_gets_its_reason_and_changes_nothing(
        app: ServerApp, client: AgClient) -> None:
    engine = app.engine
    assert engine is not None
    logger_band(app, 14025.0, radio=1)
    await until(lambda: engine.radio_view(1, 1).khz == 14025.0)
    logger_band(app, 21225.0, radio=2)
    await until(lambda: engine.radio_view(1, 2).khz == 21225.0)
    before = (engine.radio_view(1, 1), engine.radio_view(1, 2))
    assert (before[0].tx, before[1].tx) == (0, 1)  # tribander, 40 m dipole (15 m)
    emulator = app.emulators()[1]
    relays = emulator.view().relays
    # radio 1 holds the tribander: radio 2's press for it is refused, with the reason
    answer = await client.ask("port set 2 rxant=1 txant=1")
    assert answer.code == 0x20
    # in the AG's words: its antenna number and name, the port of the radio
    assert answer.message == ("AG antenna 1 (Triband_Yagi_20-15-10) is in use by station 1 "
                              "radio 1 (port 1)")
    # the 80 m dipole (AG antenna 3) cannot work on 20 m
    answer = await client.ask("port set 1 rxant=3 txant=3")
    assert answer.code == 0x20
    assert answer.message == ("AG antenna 3 (80_m_dipole) does not cover 14025 kHz for "
                              "station 1 radio 1 (port 1)")
    # a band with a press the engine refuses: neither is done
    answer = await client.ask("port set 1 band=2 rxant=1")
    assert answer.code == 0x20
    assert (engine.radio_view(1, 1), engine.radio_view(1, 2)) == before
    assert emulator.view().relays == relays
    for bad, words in (("port set 3 rxant=1", "no port 3"), ("port set 1 rxant=9", "rxant=9"),
                       ("port set 1 band=13", "band=13"), ("port set 1 speed=3", "speed"),
                       ("port get x", "no port x")):
        got = await client.ask(bad, listing=bad.startswith("port get"))
        assert got.code == 0x12 and words in got.message, (bad, got)
    for unsupported in ("stack list", "group list", "output list", "flex list",
                        "antenna set 1 name=x", "sub group"):
        got = await client.ask(unsupported)
        assert got.code == 0x11, (unsupported, got)
    assert (await client.ask("frobnicate")).code == 0x10


@pytest.mark.asyncio
async def test_auto_0_holds_against_the_logger_and_auto_1_releases(app: ServerApp,
                                                                   client: AgClient) -> None:
    assert (await client.ask("sub port all")).code == 0
    logger_band(app, 14025.0)
    await client.status("port 1 ")
    assert (await client.ask("port set 1 auto=0 rxant=4 txant=4")).code == 0
    said = fields(await client.status("port 1 "))
    # the press and the hold of one command: one line
    assert said["auto"] == "0" and said["source"] == "MANUAL" and said["txant"] == "4"
    engine = app.engine
    assert engine is not None
    assert engine.radio_view(1, 1).held_by == "an Antenna Genius client at 127.0.0.1"
    assert app.radio_entry(1, 1)["held_by"] == "an Antenna Genius client at 127.0.0.1"
    logger_band(app, 21025.0)  # the vertical works on 15 m too: held, it stays
    said = fields(await client.status("port 1 "))
    assert said["band"] == "8" and said["txant"] == "4" and said["auto"] == "0"
    assert (await client.ask("port set 1 auto=1")).code == 0
    said = fields(await client.status("port 1 "))
    assert said["auto"] == "1" and said["txant"] == "1"  # the tribander, by frequency
    assert engine.radio_view(1, 1).held_by is None


@pytest.mark.asyncio
async def test_band_from_a_client_is_that_bands_middle(app: ServerApp, client: AgClient) -> None:
    assert (await client.ask("port set 2 band=4")).code == 0
    engine = app.engine
    assert engine is not None
    assert engine.radio_view(1, 2).khz == 7150.0
    got = fields((await client.ask("port get 2", listing=True)).message)
    assert got["band"] == "4" and got["txant"] == "2"


@pytest.mark.asyncio
async def test_a_new_configuration_sends_antenna_reload(app: ServerApp,
                                                        client: AgClient) -> None:
    assert (await client.ask("sub port all")).code == 0
    assert (await app.open(EXAMPLES / "small-station.moas")).ok
    assert await client.status("antenna reload") == "antenna reload"
    assert (await client.ask("antenna list", listing=True)).code == 0


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_keepalive_drops_a_silent_client_and_a_pinging_one_stays() -> None:
    core = AgEngineBackend(ServerApp(options(ag_port=None)))
    ag = AgServer(core, "127.0.0.1", 0, timing=AgTiming(first_command=0.5, keepalive=0.4,
                                                          idle=60))
    await ag.start(None)
    try:
        silent = await AgClient.connect(ag.port)
        assert await silent.closed(), "no first command: closed"
        lively = await AgClient.connect(ag.port)
        assert (await lively.ask("keepalive enable")).code == 0
        for _ in range(5):
            await asyncio.sleep(0.2)
            assert (await lively.ask("ping")).code == 0
        assert await lively.closed(), "silent past the keepalive: closed"
        await lively.close()
        await silent.close()
    finally:
        await ag.close()


@pytest.mark.asyncio
async def test_auth_needed_wrong_code_gets_ff_and_too_many_lock_the_address_out() -> None:
    from moas_gui.net.antenna_genius.access import SimpleAccess
    from moas_gui.net.secrets import ADDRESS_FREE, SecretGuard

    class Lan(SimpleAccess):
        def needs_token(self, host: str) -> bool:  # as for a LAN peer with --require-token
            return True

    now = [0.0]
    guard = SecretGuard(codes={"471100": "Ann"}, clock=lambda: now[0])
    core = AgEngineBackend(ServerApp(options(ag_port=None)))
    ag = AgServer(core, "127.0.0.1", 0, access=Lan(guard=guard))
    await ag.start(None)
    try:
        c = await AgClient.connect(ag.port)
        assert c.greeting == "V4.1.0 AG AUTH"
        assert (await c.ask("info get")).code == 0xFF
        assert (await c.ask("auth code=1234")).code == 0xFF
        assert (await c.ask("port get 1", listing=False)).code == 0xFF
        throttled = await c.ask("auth code=471100")  # every code waits 1 s after a failure
        assert throttled.code == 0xFF and "try again in 1 s" in throttled.message
        now[0] += 1.0
        assert (await c.ask("auth code=471100")).code == 0
        assert (await c.ask("info get")).code == 0
        await c.close()
        # this address has signed in: other addresses' failures do not hold it back, but
        # its own budget still counts: past it, its sessions end and it is refused
        d = await AgClient.connect(ag.port)
        for _ in range(ADDRESS_FREE):  # with the one above, one more than its budget
            assert (await d.ask("auth code=0")).code == 0xFF
        assert await d.closed()
        e = await AgClient.connect(ag.port)  # the address must wait: closed at once
        assert e.greeting == ""
        await d.close()
        await e.close()
    finally:
        await ag.close()


@pytest.mark.asyncio
async def test_more_radios_are_a_second_device_on_the_next_port(tmp_path: Path) -> None:
    base = two_free_ports()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as listener:
        listener.bind(("127.0.0.1", 0))
        listener.setblocking(False)
        # two devices: the same radio may be on two ports; each has its own serial
        server = ServerApp(options(ag_port=base, ag_discovery=listener.getsockname(),
                                   ag_radios=(RadioRef(1, 2), RadioRef(1, 1), RadioRef(1, 2))))
        assert (await server.open(EXAMPLES / "small-station.moas")).ok
        try:
            assert server.ag_ports == [base, base + 1]
            first = await AgClient.connect(base)
            second = await AgClient.connect(base + 1)
            one = fields((await first.ask("info get")).message)
            two = fields((await second.ask("info get")).message)
            assert one["serial"] != two["serial"] and two["name"] == "MOAS_small-station_2"
            assert (await second.ask("port set 2 band=6")).code == 0x21  # no radio on B
            assert (await second.ask("port set 1 band=6")).code == 0
            engine = server.engine
            assert engine is not None and engine.radio_view(1, 2).khz == 14175.0
            # a discovery line per device, each with its port and serial
            loop = asyncio.get_running_loop()
            heard: dict[str, str] = {}
            while len(heard) < 2:
                data = await asyncio.wait_for(loop.sock_recv(listener, 1024), 10)
                said = fields(data.decode())
                heard[said["port"]] = said["serial"]
            assert heard == {str(base): one["serial"], str(base + 1): two["serial"]}
            await first.close()
            await second.close()
        finally:
            await server.close()


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_discovery_is_sent_to_the_chosen_loopback_address() -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as listener:
        listener.bind(("127.0.0.1", 0))
        listener.setblocking(False)
        target = listener.getsockname()
        server = ServerApp(options(ag_discovery=target))
        assert (await server.open(EXAMPLES / "small-station.moas")).ok
        try:
            loop = asyncio.get_running_loop()
            data = await asyncio.wait_for(loop.sock_recv(listener, 1024), 10)
            said = data.decode().split()
            assert said[0] == "AG"
            words = dict(w.split("=", 1) for w in said[1:])
            assert words["ip"] == "127.0.0.1" and words["port"] == str(server.ag_ports[0])
            assert words["ports"] == "2" and words["antennas"] == "4"
            assert words["mode"] == "master" and words["v"] == "4.1.0"
            second = await asyncio.wait_for(loop.sock_recv(listener, 1024), 10)
            assert second.decode().startswith("AG ip=127.0.0.1 ")
        finally:
            await server.close()


def test_ag_port_in_the_file_is_read_as_web_port_is(tmp_path: Path) -> None:
    from moas_gui.config import load_config

    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["AGPort"] = 9007
    path = tmp_path / "s.moas"
    path.write_text(json.dumps(data))
    assert load_config(path).unwrap().ag_port == 9007
    data["AGPort"] = 70000
    path.write_text(json.dumps(data))
    result = load_config(path)
    assert result.config is None and any("AGPort" in str(e) for e in result.errors)


@pytest.mark.asyncio
async def test_transmit_and_inhibit_are_pushed(app: ServerApp, client: AgClient) -> None:
    engine = app.engine
    assert engine is not None
    logger_band(app, 14025.0, radio=1)
    await until(lambda: engine.radio_view(1, 1).khz == 14025.0)
    logger_band(app, 7025.0, radio=2)
    await until(lambda: engine.radio_view(1, 2).khz == 7025.0)
    assert (await client.ask("sub port all")).code == 0
    box = app.emulators()[1]
    box.set_tr(1, True)  # station 1 radio 1's port keys
    said = fields(await client.status("port 1 "))
    assert said["tx"] == "1" and said["inhibit"] == "0"
    await until(lambda: engine.radio_view(1, 2).inhibited)
    said = fields(await client.status("port 2 "))
    assert said["inhibit"] == "1" and said["tx"] == "0"
    box.set_tr(1, False)
    assert fields(await client.status("port 1 "))["tx"] == "0"
    assert fields(await client.status("port 2 "))["inhibit"] == "0"


@pytest.mark.asyncio
async def test_the_other_commands_and_lines_that_are_not_commands(app: ServerApp,
                                                                   client: AgClient) -> None:
    for command in ("sub relay", "sub antenna", "sub port 1", "unsub relay", "unsub",
                    "keepalive enable", "keepalive disable", "ping", "auth code=1"):
        assert (await client.ask(command)).code == 0, command
    assert (await client.ask("keepalive sometimes")).code == 0x12
    assert (await client.ask("info")).code == 0x10
    client.writer.write(b"hello there\r\n")
    assert (await client.line()).startswith("R0|10|not a command line")
    client.writer.write(b"C77|" + b"x" * 600 + b"\n")
    assert (await client.line()).startswith("R77|10|a line of over 512 bytes")
    assert (await client.ask("ping")).code == 0  # the connection carries on


@pytest.mark.asyncio
async def test_stopped_switches_answer_port_set_with_not_running(app: ServerApp,
                                                                 client: AgClient) -> None:
    app.stop_switches()
    answer = await client.ask("port set 1 rxant=4 txant=4")
    assert answer.code == 0x21 and "stopped" in answer.message
    app.start_switches()
    assert (await client.ask("port set 1 band=6")).code == 0


@pytest.mark.asyncio
async def test_a_quiet_client_without_keepalive_is_closed_after_the_idle_time() -> None:
    core = AgEngineBackend(ServerApp(options(ag_port=None)))
    ag = AgServer(core, "127.0.0.1", 0, timing=AgTiming(first_command=30, idle=0.5))
    await ag.start(None)
    try:
        c = await AgClient.connect(ag.port)
        assert (await c.ask("ping")).code == 0
        assert await c.closed(), "idle past the limit: closed"
        await c.close()
    finally:
        await ag.close()


@pytest.mark.asyncio
async def test_admission_is_one_call_at_accept_outside_client_allow_or_over_a_limit() -> None:
    from moas_gui.net.antenna_genius.access import SimpleAccess

    allow: list[str] = ["10.0.0.0/8"]
    core = AgEngineBackend(ServerApp(options(ag_port=None)))
    ag = AgServer(core, "127.0.0.1", 0, access=SimpleAccess(lambda: allow, per_address=1))
    await ag.start(None)
    try:
        outside = await AgClient.connect(ag.port)
        assert outside.greeting == "" and await outside.closed()
        allow[:] = ["127.0.0.0/8"]
        first = await AgClient.connect(ag.port)
        assert first.greeting == "V4.1.0 AG"
        second = await AgClient.connect(ag.port)  # one address may hold one here
        assert second.greeting == "" and await second.closed()
        await first.close()
        await until(lambda: not ag.devices[0].sessions)
        third = await AgClient.connect(ag.port)
        assert third.greeting == "V4.1.0 AG"
        for c in (outside, second, third):
            await c.close()
    finally:
        await ag.close()


@pytest.mark.asyncio
async def test_a_moas_clients_press_is_pushed_to_antenna_genius_subscribers(
        app: ServerApp, client: AgClient) -> None:
    engine = app.engine
    address = app.client_address
    assert engine is not None and address is not None
    logger_band(app, 14025.0)
    await until(lambda: engine.radio_view(1, 1).khz == 14025.0)
    assert (await client.ask("sub port all")).code == 0
    _reader, writer = await asyncio.open_connection(*address)
    try:
        writer.write(b'{"id": 1, "cmd": "hello", "client": "test"}\n'
                     b'{"id": 2, "cmd": "select", "station": 1, "radio": 1, "antenna": 3, '
                     b'"exclusive": true}\n')
        said = fields(await client.status("port 1 "))
        assert said["txant"] == "4" and said["rxant"] == "4"
    finally:
        writer.close()


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_with_require_token_a_lan_client_needs_an_operators_ag_code_and_keeps_to_its_role(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The server's own access policy on the AG front: ``--require-token`` makes a LAN
    peer (127.0.0.2) authenticate with the numeric code of ``--add-operator --ag-code``;
    the operator then acts on its own radios only; this computer needs no code."""
    from moas_gui.operators import OperatorBook, Role

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    book = OperatorBook()
    book.add("Ann", Role.OPERATE, frozenset({(1, 1)}), ag_code="471100")
    server = ServerApp(options(require_token=True))
    assert (await server.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: server.status.state is ServerState.NORMAL)
    try:
        local = await AgClient.connect(server.ag_ports[0])
        assert local.greeting == "V4.1.0 AG"  # a program on this computer
        await local.close()
        lan = await AgClient.connect(server.ag_ports[0], local="127.0.0.2")
        assert lan.greeting == "V4.1.0 AG AUTH"
        assert (await lan.ask("port set 1 rxant=4 txant=4")).code == 0xFF
        assert (await lan.ask("auth code=1234")).code == 0xFF
        while "try again" in (answer := await lan.ask("auth code=471100")).message:
            await asyncio.sleep(0.1)  # the back-off after a wrong code: 1 s
        assert answer.code == 0, answer
        logger_band(server, 14025.0, radio=1)
        engine = server.engine
        assert engine is not None
        await until(lambda: engine.radio_view(1, 1).khz == 14025.0)
        answer = await lan.ask("port set 1 rxant=4 txant=4")  # its own radio
        assert answer.code == 0, answer
        assert engine.radio_view(1, 1).tx == 3
        logger_band(server, 3525.0, radio=2)
        await until(lambda: engine.radio_view(1, 2).khz == 3525.0)
        before = engine.radio_view(1, 2)
        answer = await lan.ask("port set 2 rxant=3 txant=3")  # not its radio
        assert answer.code != 0 and "Ann" in answer.message, answer
        assert engine.radio_view(1, 2) == before
        await lan.close()
    finally:
        await server.close()


def test_an_ag_code_is_kept_as_a_hash_and_must_be_digits(tmp_path: Path) -> None:
    from moas_gui.operators import OperatorBook, OperatorError, Role

    book = OperatorBook(tmp_path / "operators.json")
    book.add("Ann", Role.ADMIN, ag_code="471100")
    assert "471100" not in (tmp_path / "operators.json").read_text()
    found = book.check_ag_code("471100")
    assert found is not None and found.name == "Ann"
    assert book.check_ag_code("471101") is None
    with pytest.raises(OperatorError, match="6 to 9 digits.*digits only"):
        book.add("Bob", Role.VIEW, ag_code="12a456")
    with pytest.raises(OperatorError, match="6 to 9 digits.*4 digits are too few"):
        book.add("Bob", Role.VIEW, ag_code="4711")
    with pytest.raises(OperatorError, match="another operator has that"):
        book.add("Bob", Role.VIEW, ag_code="471100")


@pytest.mark.asyncio
async def test_zero_is_the_ags_none_no_band_no_antenna_and_the_release_pattern_releases(
        app: ServerApp, client: AgClient) -> None:
    """The public API: ``<antenna> = 0-xx (0 = none)``, ``band 0-15`` (0 = None).  A
    program that lets go of its port sends ``auto=1 source=AUTO band=0 rxant=0 txant=0``:
    the hold goes, the frequency stays, the engine chooses; a MOAS radio is never left
    without an antenna."""
    engine = app.engine
    assert engine is not None
    logger_band(app, 14025.0)
    await until(lambda: engine.radio_view(1, 1).khz == 14025.0)
    assert (await client.ask("sub port all")).code == 0
    assert (await client.ask("port set 1 auto=0 rxant=4 txant=4")).code == 0
    await client.status("port 1 ")
    held = engine.radio_view(1, 1)
    assert held.held_by is not None and held.tx == 3
    # none for one side, or for both: nothing is pressed, nothing changes
    for command in ("port set 1 txant=0", "port set 1 rxant=0 txant=0", "port set 1 band=0"):
        assert (await client.ask(command)).code == 0, command
        assert engine.radio_view(1, 1) == held, command
    answer = await client.ask("port set 1 auto=1 source=AUTO band=0 rxant=0 txant=0")
    assert answer.code == 0, answer
    said = fields(await client.status("port 1 "))
    released = engine.radio_view(1, 1)
    assert said["auto"] == "1" and released.held_by is None and released.khz == 14025.0
    assert released.tx is not None and released.rx is not None
    # a press with the other side none: only the side asked for is pressed
    assert (await client.ask("port set 1 txant=1 rxant=0")).code == 0
    assert engine.radio_view(1, 1).tx == 0
