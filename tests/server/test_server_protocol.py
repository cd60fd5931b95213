"""The client protocol end to end: real TCP sockets on 127.0.0.1 against the real
server core (:class:`ServerApp`) running the example stations on the built-in
switch emulator.  Each request is checked by what a client reads back and by the
relays the emulated switch then holds."""

from __future__ import annotations

import asyncio
import json
import logging
from collections.abc import AsyncIterator, Callable
from pathlib import Path
from typing import Any

import pytest
import pytest_asyncio
from helpers import FakeClock, free_port, until

from moas_gui import __version__
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.client.connection import Backoff, ClientConnection
from moas_gui.config import Config, load_config
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.hw.rotators.base import Timing
from moas_gui.net.log_events import ClientLogHandler
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)

Message = dict[str, Any]


class Peer:
    """One client connection: JSON lines out, every line the server sends kept in order."""

    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.messages: list[Message] = []
        self.eof = False
        self._arrived = asyncio.Event()
        self._next_id = 0
        self._task = asyncio.create_task(self._read())

    @classmethod
    async def connect(cls, address: tuple[str, int]) -> Peer:
        return cls(*await asyncio.open_connection(*address))

    async def _read(self) -> None:
        try:
            while line := await self.reader.readline():
                self.messages.append(json.loads(line))
                self._arrived.set()
        except ConnectionError:
            pass
        finally:
            self.eof = True
            self._arrived.set()

    def mark(self) -> int:
        return len(self.messages)

    def send(self, cmd: str, **args: Any) -> int:
        self._next_id += 1
        self.writer.write(json.dumps({"id": self._next_id, "cmd": cmd, **args}).encode() + b"\n")
        return self._next_id

    def send_raw(self, data: bytes) -> None:
        self.writer.write(data)

    async def wait_for(self, wanted: Callable[[Message], bool], since: int = 0,
                       timeout: float = 5.0, what: str = "a message") -> Message:
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        seen = since
        while True:
            for message in self.messages[seen:]:
                if wanted(message):
                    return message
            seen = len(self.messages)
            if self.eof:
                raise AssertionError(f"the server closed the connection before {what}")
            self._arrived.clear()
            left = end - loop.time()
            if left <= 0:
                raise AssertionError(f"no {what} within {timeout} s; got {self.messages[since:]}")
            try:
                await asyncio.wait_for(self._arrived.wait(), left)
            except TimeoutError:
                pass

    async def event(self, name: str, since: int = 0, timeout: float = 5.0,
                    where: Callable[[Message], bool] = lambda m: True) -> Message:
        return await self.wait_for(lambda m: m.get("event") == name and where(m), since,
                                   timeout, f"{name} event")

    def events(self, name: str, since: int = 0) -> list[Message]:
        return [m for m in self.messages[since:] if m.get("event") == name]

    async def request(self, cmd: str, **args: Any) -> Message:
        ident = self.send(cmd, **args)
        return await self.wait_for(lambda m: "ok" in m and m.get("id") == ident,
                                   what=f"reply to {cmd}")

    async def ok(self, cmd: str, **args: Any) -> Any:
        reply = await self.request(cmd, **args)
        assert reply["ok"] is True, reply
        return reply["result"]

    async def refused(self, cmd: str, **args: Any) -> tuple[str, str]:
        reply = await self.request(cmd, **args)
        assert reply["ok"] is False, reply
        return reply["error"]["code"], reply["error"]["message"]

    async def close(self) -> None:
        self.writer.close()
        await self._task


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    # The big station's serial rotators would look for a MOAS Rotator program: give
    # them a port nobody listens on, so that they stay offline whatever else runs.
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     rotator_program_port=free_port(), switch_timing=FAST))
    yield server
    await server.close()


@pytest_asyncio.fixture
async def peers() -> AsyncIterator[list[Peer]]:
    made: list[Peer] = []
    yield made
    for peer in made:
        await peer.close()


async def run_example(app: ServerApp, name: str) -> Config:
    path = EXAMPLES / name
    assert (await app.open(path)).ok
    await until(lambda: app.status.state is ServerState.NORMAL, what="the switches ready")
    return load_config(path).unwrap()


async def greeted(app: ServerApp, peers: list[Peer], name: str = "test", **args: Any) -> Peer:
    """A client that said hello and got its state event."""
    address = app.client_address
    assert address is not None
    peer = await Peer.connect(address)
    peers.append(peer)
    await peer.ok("hello", client=name, **args)
    await peer.event("state")
    return peer


def wanted_relays(config: Config, held: dict[tuple[int, int], tuple[int, float]]
                  ) -> dict[int, frozenset[int]]:
    """Per switch, the relays the configuration gives each (station, radio) ->
    (antenna, kHz) in ``held`` (relay n is relay n % 100 of switch n // 100 + 1)."""
    out: dict[int, set[int]] = {switch.id: set() for switch in config.switches}
    for (station, radio), (antenna_id, khz) in held.items():
        antenna = config.antenna(antenna_id)
        assert antenna is not None
        entries = [entry for control in antenna.control if control.range.contains(khz)
                   for entry in control.stations if entry.applies_to(station, radio)]
        assert entries, f"antenna {antenna_id} has no relays at {khz} kHz"
        for relay in entries[0].relays:
            out[relay // 100 + 1].add(relay % 100)
    return {switch: frozenset(relays) for switch, relays in out.items()}


def held_relays(app: ServerApp) -> dict[int, frozenset[int]]:
    return {switch: box.view().relays for switch, box in app.emulators().items()}


async def relays_become(app: ServerApp, wanted: dict[int, frozenset[int]]) -> None:
    try:
        await until(lambda: held_relays(app) == wanted, what="the relays")
    except AssertionError:
        raise AssertionError(f"relays {held_relays(app)}, wanted {wanted}") from None


# ---- hello and state -------------------------------------------------------------------


@pytest.mark.asyncio
async def test_hello_is_answered_then_the_big_station_state_follows(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "big-station.moas")
    address = app.client_address
    assert address is not None
    peer = await Peer.connect(address)
    peers.append(peer)
    result = await peer.ok("hello", client="panel", station=1, radio=1)
    assert result == {"server": "moas-gui", "version": __version__, "protocol": 1}
    state = await peer.event("state")
    assert peer.messages.index(state) == peer.messages.index(
        next(m for m in peer.messages if "ok" in m)) + 1, "the state event follows the reply"

    assert state["config"] == "big-station.moas"
    assert [(r["station"], r["radio"]) for r in state["radios"]] == [(1, 1), (2, 1)]
    assert all(r["khz"] is None and r["tx"] is None for r in state["radios"])
    assert [a["id"] for a in state["antennas"]] == [a.id for a in config.antennas]
    antennas = {a["id"]: a for a in state["antennas"]}
    assert antennas[11].items() >= {
        "id": 11, "short": "SE", "long": "160 m 4-square SE", "rotator": 10, "offset": 135,
    }.items()
    assert antennas[42]["offset"] == 45 and antennas[42]["rotator"] is None
    assert antennas[92]["offset"] == 270

    rotators = {r["id"]: r for r in state["rotators"]}
    assert sorted(rotators) == list(range(1, 13))
    assert rotators[3].items() >= {
        "id": 3, "short": "20 5 el", "heading": None, "target": None, "moving": False,
        "online": False, "long": "20 m 5 element yagi", "ccw_limit": 0, "rotation": 450,
        "has_stop": True, "electrical": False,
    }.items()
    four_square = rotators[10]
    assert four_square["electrical"] is True and four_square["online"] is True
    assert (four_square["ccw_limit"], four_square["rotation"], four_square["has_stop"]) == (
        0, 360, False)
    assert rotators[1]["ccw_limit"] == 180 and rotators[1]["has_stop"] is True

    assert state["switches"] == [{"id": 1, "status": "ok"}, {"id": 2, "status": "ok"}]

    snapshot = await peer.ok("state")
    assert snapshot == {k: v for k, v in state.items() if k != "event"}

    # no MOAS Rotator program answers for the serial rotators
    code, message = await peer.refused("rotate", rotator=3, heading=90)
    assert code == "unavailable" and "not connected" in message


@pytest.mark.asyncio
async def test_state_works_without_hello_and_events_wait_for_hello(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    address = app.client_address
    assert address is not None
    quiet = await Peer.connect(address)
    peers.append(quiet)
    snapshot = await quiet.ok("state")
    assert snapshot["config"] == "small-station.moas"
    assert [(r["station"], r["radio"]) for r in snapshot["radios"]] == [(1, 1), (1, 2)]
    tribander = snapshot["rotators"][0]
    assert (tribander["id"], tribander["heading"], tribander["online"]) == (1, 180, True)

    await quiet.ok("frequency", station=1, radio=1, khz=14025)
    watcher = await greeted(app, peers, "watcher")
    since = watcher.mark()
    await quiet.ok("frequency", station=1, radio=2, khz=7025)
    await watcher.event("radio", since, where=lambda m: m["radio"] == 2)
    assert not [m for m in quiet.messages if "event" in m], "no events before hello"


# ---- frequency ----------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_frequency_selects_an_antenna_and_the_switch_closes_its_relays(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    assert held_relays(app) == {1: frozenset()}

    since = peer.mark()
    assert await peer.ok("frequency", station=1, radio=1, khz=14025) == {}
    radio = await peer.event("radio", since)
    assert radio.items() >= {"station": 1, "radio": 1, "khz": 14025.0, "tx_khz": 14025.0,
                             "tx": 0, "rx": 0, "alt": None, "transmitting": False,
                             "inhibited": False, "note": ""}.items()
    await relays_become(app, wanted_relays(config, {(1, 1): (0, 14025)}))

    since = peer.mark()
    await peer.ok("frequency", station=1, radio=2, khz=7025.5)
    radio = await peer.event("radio", since)
    assert (radio["radio"], radio["khz"], radio["tx"]) == (2, 7025.5, 1)
    await relays_become(app, wanted_relays(config, {(1, 1): (0, 14025), (1, 2): (1, 7025.5)}))

    since = peer.mark()
    await peer.ok("frequency", station=1, radio=2, khz=7025.5, tx_khz=7190)
    radio = await peer.event("radio", since)
    assert (radio["khz"], radio["tx_khz"], radio["tx"]) == (7025.5, 7190.0, 1)


# ---- select -----------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_select_toggles_the_stack_and_sets_tx_and_rx_on_the_big_station(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "big-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=14025)
    assert (await peer.ok("state"))["radios"][0]["tx"] == 40  # the whole stack

    async def press(antenna: int, tx: int, rx: int, **args: Any) -> None:
        since = peer.mark()
        assert await peer.ok("select", station=1, radio=1, antenna=antenna, **args) == {
            "tx": tx, "rx": rx}
        event = await peer.event("radio", since)
        assert (event["tx"], event["rx"]) == (tx, rx)
        # receiving: the switch holds the receive antenna's relays
        await relays_become(app, wanted_relays(config, {(1, 1): (rx, 14025)}))

    await press(42, 45, 45)  # additive: the middle yagi leaves the stack (top + bottom)
    await press(43, 41, 41)  # and the bottom one: the top alone
    await press(42, 44, 44)  # the middle one comes back: top + middle
    await press(43, 43, 43, exclusive=True)  # a long press: the bottom yagi alone
    await press(47, 43, 47, target="rx")  # the 5 element yagi to receive only
    await press(40, 40, 47, target="tx")  # transmit on the whole stack
    await press(47, 47, 47, target="both")

    since = peer.mark()
    assert await peer.ok("select", station=1, radio=1, antenna=47) == {"tx": 47, "rx": 47}
    # a change would have been told before the reply
    assert not peer.events("radio", since), "pressing the selected antenna changes nothing"


@pytest.mark.asyncio
async def test_a_select_by_one_client_reaches_the_other_clients(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    picker = await greeted(app, peers, "picker")
    watcher = await greeted(app, peers, "watcher")
    await picker.ok("frequency", station=1, radio=1, khz=21025)
    since = watcher.mark()
    await picker.ok("select", station=1, radio=1, antenna=3)
    event = await watcher.event("radio", since, where=lambda m: m["tx"] == 3)
    assert (event["station"], event["radio"], event["khz"]) == (1, 1, 21025.0)


# ---- functions --------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_antenna_swap_trades_the_radios_antennas_on_the_small_station(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=14025)
    await peer.ok("frequency", station=1, radio=2, khz=7025)

    # Tribander on 20 m and 40 m dipole: the tribander cannot serve radio 2 on 40 m.
    available, reason = app.engine.function_status(1, 1, 0)
    assert not available and reason
    code, message = await peer.refused("function", station=1, radio=1, function=0)
    assert code == "unavailable" and reason in message
    await relays_become(app, wanted_relays(config, {(1, 1): (0, 14025), (1, 2): (1, 7025)}))

    # Tribander on 15 m, the vertical on 20 m: each covers the other's band.
    await peer.ok("frequency", station=1, radio=1, khz=21025)
    await peer.ok("frequency", station=1, radio=2, khz=14025)
    radios = {r["radio"]: r for r in (await peer.ok("state"))["radios"]}
    assert (radios[1]["tx"], radios[2]["tx"]) == (0, 3)
    since = peer.mark()
    assert await peer.ok("function", station=1, radio=1, function=0) == {}
    await peer.event("radio", since, where=lambda m: m["radio"] == 1 and m["tx"] == 3)
    await peer.event("radio", since, where=lambda m: m["radio"] == 2 and m["tx"] == 0)
    await relays_become(app, wanted_relays(config, {(1, 1): (3, 21025), (1, 2): (0, 14025)}))


@pytest.mark.asyncio
async def test_store_and_recall_bring_back_the_stored_antennas_on_the_big_station(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "big-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=14025)
    code, message = await peer.refused("function", station=1, radio=1, function=1)
    reason = app.engine.function_status(1, 1, 1)[1]  # Recall: nothing stored yet
    assert code == "unavailable" and reason and reason in message, message
    await peer.ok("select", station=1, radio=1, antenna=47, target="rx")
    assert await peer.ok("function", station=1, radio=1, function=0) == {}  # Store
    await peer.ok("select", station=1, radio=1, antenna=43, exclusive=True)
    await relays_become(app, wanted_relays(config, {(1, 1): (43, 14025)}))

    since = peer.mark()
    assert await peer.ok("function", station=1, radio=1, function=1) == {}  # Recall
    event = await peer.event("radio", since)
    assert (event["tx"], event["rx"]) == (40, 47)
    await relays_become(app, wanted_relays(config, {(1, 1): (47, 14025)}))

    code, message = await peer.refused("function", station=1, radio=1, function=7)
    assert code == "not_found" and "7" in message


# ---- relative and layout ------------------------------------------------------------------


@pytest.mark.asyncio
async def test_relative_steps_round_the_list_and_picks_by_index(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=21025)  # list: tribander, 40 dipole, vertical

    async def relative(expected: int, **how: int) -> None:
        since = peer.mark()
        assert await peer.ok("relative", station=1, radio=1, **how) == {
            "tx": expected, "rx": expected}
        await peer.event("radio", since, where=lambda m: m["tx"] == expected)

    await relative(1, step=1)
    await relative(3, step=1)
    await relative(0, step=1)  # round to the start
    await relative(3, step=-1)
    await relative(1, index=1)
    await relays_become(app, wanted_relays(config, {(1, 1): (1, 21025)}))

    code, message = await peer.refused("relative", station=1, radio=1, index=7)
    assert code == "not_found" and "7" in message
    await peer.ok("frequency", station=1, radio=2, khz=14025)
    await peer.ok("select", station=1, radio=2, antenna=3)  # radio 2 takes the vertical
    code, message = await peer.refused("relative", station=1, radio=1, index=2)
    assert code == "unavailable" and "vertical" in message.lower()
    await relative(0, step=1)  # the vertical in use is skipped: 40 dipole -> tribander
    await relative(1, step=1)
    for both_or_neither in ({"step": 1, "index": 0}, {}):
        code, message = await peer.refused("relative", station=1, radio=1, **both_or_neither)
        assert code == "bad_request" and "step" in message and "index" in message
    await peer.ok("frequency", station=1, radio=1, khz=10120)  # 30 m: no relative list
    code, _ = await peer.refused("relative", station=1, radio=1, step=1)
    assert code == "unavailable"


@pytest.mark.asyncio
async def test_a_followed_layout_changes_when_another_radio_takes_an_antenna(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    panel = await greeted(app, peers, "radio 1 panel", station=1, radio=1)
    other = await greeted(app, peers, "radio 2 panel", station=1, radio=2)
    await panel.ok("frequency", station=1, radio=1, khz=21025)
    await other.ok("frequency", station=1, radio=2, khz=7025)

    layout = await panel.ok("layout", station=1, radio=1, rows=5, columns=5)
    assert (layout["station"], layout["radio"], layout["rows"], layout["columns"]) == (1, 1, 2, 3)
    buttons = {(b["row"], b["column"]): b for b in layout["buttons"]}
    assert buttons[(0, 0)] == {"row": 0, "column": 0, "type": "Antenna", "id": 0,
                               "label": "Tribander", "state": "selected"}
    assert buttons[(0, 2)]["id"] == 3 and buttons[(0, 2)]["state"] == "available"
    assert buttons[(1, 0)]["type"] == "Function" and buttons[(1, 0)]["label"] == "Swap"
    assert {b["state"] for b in layout["buttons"]} <= {"selected", "available", "unavailable"}

    # radio 2 takes the vertical: radio 1's vertical button becomes unavailable
    since = panel.mark()
    await other.ok("select", station=1, radio=2, antenna=3)
    changed = await panel.event("layout", since)
    states = {b["id"]: b["state"] for b in changed["buttons"] if b["type"] == "Antenna"}
    assert states == {0: "selected", 1: "available", 3: "unavailable"}
    assert (changed["station"], changed["radio"], changed["rows"], changed["columns"]) == (
        1, 1, 2, 3)
    code, message = await panel.refused("select", station=1, radio=1, antenna=3)
    assert code == "unavailable" and "station 1 radio 2" in message
    await other.ok("state")  # comes after anything already sent to it
    assert not other.events("layout"), "layout events go only to who asked"

    # radio 1 changes band: the layout shows that band's buttons
    since = panel.mark()
    await panel.ok("frequency", station=1, radio=1, khz=3525)
    changed = await panel.event("layout", since)
    assert {b["id"] for b in changed["buttons"] if b["type"] == "Antenna"} == {2, 3}


# ---- rotators ----------------------------------------------------------------------------


@pytest_asyncio.fixture
async def clocked() -> AsyncIterator[tuple[ServerApp, FakeClock]]:
    """A server whose rotators run on a fake clock (its switches on the real one)."""
    clock = FakeClock()
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     rotator_program_port=free_port(), switch_timing=FAST,
                                     rotator_timing=Timing(clock=clock)))
    yield server, clock
    await server.close()


async def ticking(clock: FakeClock, peer: Peer, wanted: Callable[[Message], bool],
                  since: int, limit: float, what: str) -> Message:
    """The first message from ``since`` on that passes ``wanted``, moving ``clock`` on a
    twentieth of a second at a time (at most ``limit`` seconds) until it comes."""
    end = clock.now() + limit
    while True:
        for message in peer.messages[since:]:
            if wanted(message):
                return message
        since = len(peer.messages)
        if clock.now() >= end:
            raise AssertionError(f"no {what} within {limit} s on the clock")
        await clock.advance(0.05)


@pytest.mark.asyncio
async def test_a_test_rotator_turns_at_ten_degrees_a_second_and_stops(
        clocked: tuple[ServerApp, FakeClock], peers: list[Peer]) -> None:
    """The whole server, with its rotators' clock moved on by the test."""
    app, clock = clocked
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    start = (await peer.ok("state"))["rotators"][0]
    assert (start["heading"], start["moving"], start["online"]) == (180, False, True)

    since = peer.mark()
    began = clock.now()
    assert await peer.ok("rotate", rotator=1, heading=200) == {}
    seen: list[tuple[float, int]] = []

    def note(m: Message) -> bool:
        if m.get("event") == "rotator" and m["id"] == 1:
            seen.append((clock.now(), m["heading"]))
            return not m["moving"]
        return False

    moving = await peer.event("rotator", since, where=lambda m: m["moving"])
    assert moving["target"] == 200
    arrived = await ticking(clock, peer, note, since, 6, "arrival")
    took = clock.now() - began
    assert (arrived["heading"], arrived["target"], arrived["online"]) == (200, None, True)
    headings = [h for _, h in seen]
    assert headings == sorted(headings) and len(set(headings)) >= 4, headings
    assert 1.5 <= took <= 3.5, f"20 degrees took {took:.2f} s"

    since = peer.mark()
    await peer.ok("rotate", rotator=1, heading=170)  # clockwise all the way round: 33 s
    await ticking(clock, peer, lambda m: m.get("event") == "rotator" and m["moving"]
                  and m["heading"] >= 203, since, 5, "the turn under way past 203")
    since = peer.mark()
    assert await peer.ok("stop", rotator=1) == {}
    stopped = await peer.event("rotator", since, where=lambda m: not m["moving"])
    assert stopped["target"] is None and 203 <= stopped["heading"] < 230
    await clock.advance(1.0)  # five ticks of a rotator that would still be turning
    assert all(m["heading"] == stopped["heading"] for m in peer.events("rotator", since))


@pytest.mark.asyncio
async def test_turning_the_4_square_selects_the_antenna_nearest_the_heading(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "big-station.moas")
    peer = await greeted(app, peers)

    since = peer.mark()
    await peer.ok("frequency", station=1, radio=1, khz=1825)
    radio = await peer.event("radio", since)
    assert radio["tx"] == 10  # the north-east direction

    since = peer.mark()
    assert await peer.ok("rotate", rotator=10, heading=200) == {}
    radio = await peer.event("radio", since)
    assert (radio["tx"], radio["rx"]) == (12, 12)  # south-west, 225 degrees
    rotator = await peer.event("rotator", since, where=lambda m: m["id"] == 10)
    assert (rotator["heading"], rotator["moving"], rotator["electrical"]) == (225, False, True)
    await relays_become(app, wanted_relays(config, {(1, 1): (12, 1825)}))

    since = peer.mark()
    await peer.ok("rotate", rotator=10, heading=300)
    assert (await peer.event("radio", since))["tx"] == 13
    await relays_become(app, wanted_relays(config, {(1, 1): (13, 1825)}))
    assert await peer.ok("stop", rotator=10) == {}

    code, message = await peer.refused("rotate", rotator=11, heading=90)  # 80 m: unused
    assert code == "unavailable" and "rotator 11" in message.lower()


@pytest.mark.asyncio
async def test_a_button_on_the_4_square_turns_its_compass_needle(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "big-station.moas")
    peer = await greeted(app, peers)
    since = peer.mark()
    await peer.ok("frequency", station=1, radio=1, khz=1825)
    needle = await peer.event("rotator", since, where=lambda m: m["id"] == 10)
    assert needle["heading"] == 45
    since = peer.mark()
    await peer.ok("select", station=1, radio=1, antenna=11)  # the SE button
    needle = await peer.event("rotator", since, where=lambda m: m["id"] == 10)
    assert needle["heading"] == 135
    state = await peer.ok("state")
    assert next(r for r in state["rotators"] if r["id"] == 10)["heading"] == 135


# ---- refusals ----------------------------------------------------------------------------


@pytest.mark.asyncio
async def test_every_bad_request_is_refused_with_its_code_and_changes_nothing(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    bystander = await greeted(app, peers, "bystander")
    await peer.ok("frequency", station=1, radio=1, khz=21025)  # tribander
    await peer.ok("frequency", station=1, radio=2, khz=14025)
    await peer.ok("select", station=1, radio=2, antenna=3)  # vertical
    before, relays = await peer.ok("state"), held_relays(app)
    await bystander.ok("state")  # its reply comes after the events so far
    quiet_from = bystander.mark()

    refusals: list[tuple[str, dict[str, Any], str, str]] = [
        ("select", {"station": 9, "radio": 1, "antenna": 0}, "not_found", "station 9"),
        ("frequency", {"station": 1, "radio": 5, "khz": 7000}, "not_found", "radio 5"),
        ("select", {"station": 1, "radio": 1, "antenna": 999}, "not_found", "999"),
        ("function", {"station": 1, "radio": 1, "function": 42}, "not_found", "42"),
        ("layout", {"station": 3, "radio": 1, "rows": 2, "columns": 3}, "not_found", "station 3"),
        ("rotate", {"rotator": 99, "heading": 90}, "not_found", "rotator 99"),
        ("stop", {"rotator": 99}, "not_found", "rotator 99"),
        ("select", {"station": 1, "radio": 2, "antenna": 0}, "unavailable", "station 1 radio 1"),
        ("select", {"station": 1, "radio": 1, "antenna": 2}, "unavailable", "21025"),
        ("select", {"station": 1, "radio": 1}, "bad_request", '"antenna"'),
        ("select", {"station": 1, "radio": 1, "antenna": 1, "target": "up"}, "bad_request",
         "target"),
        ("select", {"station": "1", "radio": 1, "antenna": 1}, "bad_request", "station"),
        ("select", {"station": 1, "radio": 1, "antenna": 1, "exclusive": 1}, "bad_request",
         "exclusive"),
        ("frequency", {"station": 1, "radio": 1, "khz": -5}, "bad_request", "khz"),
        ("rotate", {"rotator": 1, "heading": 1000}, "bad_request", "heading"),
        ("rotate", {"rotator": 1, "heading": "north"}, "bad_request", "heading"),
        ("layout", {"station": 1, "radio": 1, "rows": 0, "columns": 3}, "bad_request", "rows"),
        ("hello", {}, "bad_request", "client"),
        ("selct", {"station": 1, "radio": 1, "antenna": 1}, "unknown_cmd", "select"),
    ]
    for cmd, args, code, words in refusals:
        got_code, message = await peer.refused(cmd, **args)
        assert (got_code, words in message) == (code, True), (cmd, args, got_code, message)

    assert await peer.ok("state") == before
    assert held_relays(app) == relays
    assert not bystander.events("radio", quiet_from)
    assert not bystander.events("rotator", quiet_from)


@pytest.mark.asyncio
async def test_lines_that_are_not_requests_get_id_null_and_three_in_a_row_close(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    bystander = await greeted(app, peers, "bystander")
    since = peer.mark()
    peer.send_raw(b"this is not JSON\n")
    bad = await peer.wait_for(lambda m: "ok" in m, since, what="the bad line's reply")
    assert bad["id"] is None and bad["error"]["code"] == "bad_request"
    peer.send_raw(b'["a list"]\n')
    await peer.ok("state")  # a request in between: the count starts again
    peer.send_raw(b"\xff\xfe\n[1]\n42\n")
    await until(lambda: peer.eof, what="the server closing the connection")
    nulls = [m for m in peer.messages[since:] if "ok" in m and m["id"] is None]
    assert len(nulls) == 5
    assert (await bystander.ok("state"))["config"] == "small-station.moas"


@pytest.mark.asyncio
async def test_stopped_switches_refuse_selection_with_not_running_until_started(
        app: ServerApp, peers: list[Peer]) -> None:
    config = await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=21025)
    since = peer.mark()
    app.stop_switches()
    await peer.event("switch", since, where=lambda m: m == {
        "event": "switch", "id": 1, "status": "stopped"})
    await until(lambda: held_relays(app) == {1: frozenset()}, what="all relays off")
    for cmd, args in (("select", {"antenna": 3}), ("function", {"function": 1}),
                      ("relative", {"step": 1})):
        code, message = await peer.refused(cmd, station=1, radio=1, **args)
        assert code == "not_running" and "stopped" in message, (cmd, message)
    since = peer.mark()
    app.start_switches()
    await peer.event("switch", since, where=lambda m: m["status"] == "ok")
    assert await peer.ok("select", station=1, radio=1, antenna=3) == {"tx": 3, "rx": 3}
    await relays_become(app, wanted_relays(config, {(1, 1): (3, 21025)}))


@pytest.mark.asyncio
async def test_closing_the_configuration_disconnects_clients_and_stops_listening(
        app: ServerApp, peers: list[Peer]) -> None:
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    address = app.client_address
    assert address is not None
    await app.close()
    await until(lambda: peer.eof, what="the connection closed")
    assert app.client_address is None
    with pytest.raises(ConnectionRefusedError):
        await asyncio.open_connection(*address)


# ---- log events and restarts ---------------------------------------------------------------


@pytest.mark.asyncio
async def test_log_events_go_only_to_clients_that_asked(
        app: ServerApp, peers: list[Peer], caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui")  # as moas-server sets its log up
    await run_example(app, "big-station.moas")
    listener = await greeted(app, peers, "log window", log=True)
    quiet = await greeted(app, peers, "panel")
    since = listener.mark()
    await greeted(app, peers, "newcomer")
    line = await listener.event("log", since, where=lambda m: '"newcomer"' in m["message"])
    assert line["level"] == "info" and "127.0.0.1" in line["message"]

    await quiet.ok("frequency", station=1, radio=1, khz=1825)
    await quiet.ok("rotate", rotator=10, heading=200)  # the engine says which antenna
    await listener.event("log", since, where=lambda m: "Rotator 10" in m["message"])
    assert not quiet.events("log")


def log_handlers() -> int:
    return sum(isinstance(h, ClientLogHandler) for h in logging.getLogger("moas_gui").handlers)


@pytest.mark.asyncio
async def test_restart_disconnects_clients_and_the_built_in_client_reconnects_to_the_new_run(
        tmp_path: Path, peers: list[Peer]) -> None:
    port = free_port()
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=port, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False,
                                  switch_timing=FAST))
    connection = ClientConnection("127.0.0.1", port, name="built-in client",
                                  backoff=Backoff(first=0.05, most=0.2))
    try:
        await run_example(app, "small-station.moas")
        raw = await greeted(app, peers, "script")
        connection.start()
        await connection.wait_connected(5)
        await raw.ok("frequency", station=1, radio=1, khz=21025)
        await until(lambda: connection.snapshot is not None and connection.snapshot.radio(
            1, 1).khz == 21025.0, what="the built-in client seeing 15 m")  # type: ignore[union-attr]

        await app.restart()
        assert app.client_address == ("127.0.0.1", port)
        assert log_handlers() == 1, "the old configuration's log handler is gone"
        await until(lambda: raw.eof, what="the script's connection closed")
        await until(lambda: connection.connects == 2, what="the built-in client reconnecting")
        # a snapshot of the new run, which restored the saved state (docs/server.md)
        await until(lambda: connection.snapshot is not None and connection.snapshot.radio(
            1, 1).khz == 21025.0, what="the restored state")  # type: ignore[union-attr]
        await connection.request("frequency", {"station": 1, "radio": 1, "khz": 14025})
        assert (await connection.select(1, 1, 3)).tx == 3
        await relays_become(app, wanted_relays(load_config(EXAMPLES / "small-station.moas")
                                               .unwrap(), {(1, 1): (3, 14025)}))
    finally:
        await connection.aclose()
        await app.close()
    assert log_handlers() == 0


@pytest.mark.asyncio
async def test_stop_and_reset_switches_while_a_radio_transmits_need_force(
        app: ServerApp, peers: list[Peer]) -> None:
    """The admin commands ask first, as the window does: while a switch says a radio is
    keyed, stop_switches and reset_switches are refused naming it (nothing happens) and
    go only with "force": true; start_switches never waits."""
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)  # this computer: every right
    await peer.ok("frequency", station=1, radio=1, khz=21025)
    box = app.emulators()[1]
    await until(lambda: bool(box.view().relays))
    held = box.view().relays
    box.set_tr(1, True)
    await until(lambda: app.keyed_radios() == ["station 1 radio 1 (switch 1 port 1)"])
    resets = box.record.written
    for cmd in ("stop_switches", "reset_switches"):
        code, message = await peer.refused(cmd)
        assert code == "unavailable", (cmd, message)
        assert "station 1 radio 1 (switch 1 port 1) transmits now" in message
        assert '"force": true' in message
    assert not app.switches_stopped and box.view().relays == held
    assert not any(e.event.value == "reset" for e in box.record.after(resets))
    assert await peer.ok("stop_switches", force=True) == {}
    assert app.switches_stopped
    await until(lambda: box.view().relays == frozenset())
    assert await peer.ok("start_switches") == {}
    box.set_tr(1, False)
    await until(lambda: app.keyed_radios() == [])
    assert await peer.ok("reset_switches") == {}  # nobody keyed: no force needed
