"""N1MM's rotor window over real UDP on 127.0.0.1: commands in, headings out.

Recorded commands: the turn and stop documents published in
sconklin/netrotor README.md and the one-line capture with ``*`` as the rotor
name quoted in n1kdo/rotator-controller-controller (both reproduced in
shared/specs/logger-network.md 1.9); the heading report ``TH6 @ 1460`` is from
the same sources.
"""

from __future__ import annotations

import asyncio
import logging
import socket
from collections.abc import AsyncIterator
from dataclasses import dataclass, field

import pytest
import pytest_asyncio

from moas_gui.sources.n1mm_rotor import N1MMRotorServer, parse_destination
from moas_gui.sources.n1mm_rotor_packet import (
    N1MMRotorError,
    RotorStop,
    RotorTurn,
    heading_report,
    parse_rotor_command,
    stop_command,
    turn_command,
)

TURN_DOC = b"""<N1MMRotor>
  <rotor>TH6</rotor>
  <goazi>55.0</goazi>
  <offset>0.0</offset>
  <bidirectional>0</bidirectional>
  <freqband>14.0</freqband>
</N1MMRotor>"""
STOP_DOC = b"""<N1MMRotor>
  <stop>
    <rotor>YaesuCom9</rotor>
    <freqband>21.0</freqband>
  </stop>
</N1MMRotor>"""
STAR_CAPTURE = (b"<N1MMRotor><rotor>*</rotor><goazi>66.0</goazi><offset>0.0</offset>"
                b"<bidirectional>0</bidirectional><freqband>14.0</freqband></N1MMRotor>")


def test_the_published_turn_and_stop_commands_read() -> None:
    assert parse_rotor_command(TURN_DOC) == RotorTurn("TH6", 55.0, 0.0, False, 14.0)
    assert parse_rotor_command(STOP_DOC) == RotorStop("YaesuCom9", 21.0)
    assert parse_rotor_command(STAR_CAPTURE) == RotorTurn("*", 66.0, 0.0, False, 14.0)


def test_heading_reports_are_in_tenths_of_a_degree() -> None:
    assert heading_report("TH6", 146.0) == b"TH6 @ 1460"
    assert heading_report("40m 4-sq", 359.96) == b"40m 4-sq @ 0"
    assert heading_report("A", 0.04) == b"A @ 0"


@pytest.mark.parametrize(("data", "reason"), [
    (b"junk", "not_xml"),
    (TURN_DOC[:40], "not_xml"),
    (b"<RadioInfo><Freq>1</Freq></RadioInfo>", "not_rotor"),
    (b"<N1MMRotor>" + b" " * 5000 + b"</N1MMRotor>", "too_large"),
    (b'<!DOCTYPE r [<!ENTITY a "x">]><N1MMRotor><rotor>&a;</rotor></N1MMRotor>', "doctype"),
    (b"<N1MMRotor><goazi>10</goazi></N1MMRotor>", "missing_field"),
    (b"<N1MMRotor><rotor>TH6</rotor></N1MMRotor>", "missing_field"),
    (b"<N1MMRotor><rotor>TH6</rotor><goazi>1e9</goazi></N1MMRotor>", "bad_value"),
    (b"<N1MMRotor><rotor>TH6</rotor><goazi>99999.0</goazi></N1MMRotor>", "bad_value"),
    (b"<N1MMRotor><rotor>TH6</rotor><goazi>nan</goazi></N1MMRotor>", "bad_value"),
    ("<N1MMRotor><rotor>TH6</rotor><goazi>\u0661\u0662</goazi></N1MMRotor>".encode(),
     "bad_value"),
    (b"<N1MMRotor><rotor>" + b"x" * 100 + b"</rotor><goazi>1</goazi></N1MMRotor>", "bad_value"),
])
def test_bad_commands_are_refused_with_a_reason(data: bytes, reason: str) -> None:
    with pytest.raises(N1MMRotorError) as caught:
        parse_rotor_command(data)
    assert caught.value.reason == reason and str(caught.value)


def test_destinations_read_as_host_and_port() -> None:
    assert parse_destination("192.168.1.20:13010") == ("192.168.1.20", 13010)
    assert parse_destination("n1mm-pc") == ("n1mm-pc", 13010)
    for bad in ("", ":13010", "host:99999", "host:x"):
        with pytest.raises(ValueError, match="host:port"):
            parse_destination(bad)


@dataclass
class Rotators:
    """What the rotator manager would be asked, and the headings it reports."""

    turns: list[tuple[int, float]] = field(default_factory=list)
    stops: list[int] = field(default_factory=list)
    heading: dict[int, float | None] = field(default_factory=lambda: {1: 146.0, 2: None})
    refuse: bool = False

    def turn(self, rotator_id: int, heading: float) -> None:
        if self.refuse:
            raise RuntimeError("rotator 1 is offline")
        self.turns.append((rotator_id, heading))

    def stop(self, rotator_id: int) -> None:
        self.stops.append(rotator_id)


@dataclass
class Setup:
    server: N1MMRotorServer
    rotators: Rotators
    n1mm: socket.socket
    """Plays N1MM: sends commands from it, and its port receives the headings."""

    async def send(self, *packets: bytes) -> None:
        target = self.server.received + len(packets)
        for packet in packets:
            self.n1mm.sendto(packet, ("127.0.0.1", self.server.port or 0))
        async with asyncio.timeout(5):
            while self.server.received < target:
                await asyncio.sleep(0.005)

    async def headings(self, count: int) -> list[bytes]:
        loop = asyncio.get_running_loop()
        got = []
        async with asyncio.timeout(5):
            for _ in range(count):
                got.append(await loop.sock_recv(self.n1mm, 512))
        return got


@pytest_asyncio.fixture
async def setup() -> AsyncIterator[Setup]:
    n1mm = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    n1mm.bind(("127.0.0.1", 0))
    n1mm.setblocking(False)
    rotators = Rotators()
    server = N1MMRotorServer(
        {1: ("TH6", "Tribander"), 2: ("40m",)}, turn=rotators.turn, stop=rotators.stop,
        headings=lambda: list(rotators.heading.items()),
        destinations=[n1mm.getsockname()], port=0, host="127.0.0.1", interval=60.0)
    await server.start()
    yield Setup(server, rotators, n1mm)
    n1mm.close()
    await server.close()


@pytest.mark.asyncio
async def test_turn_and_stop_reach_the_named_rotator(setup: Setup) -> None:
    await setup.send(TURN_DOC, turn_command("tribander", 270.0), turn_command("40m", 45.5),
                     stop_command("TH6"))
    assert setup.rotators.turns == [(1, 55.0), (1, 270.0), (2, 45.5)]
    assert setup.rotators.stops == [1]


@pytest.mark.asyncio
async def test_headings_go_out_at_start_and_when_they_change(setup: Setup) -> None:
    assert await setup.headings(1) == [b"TH6 @ 1460"], "the round at start (rotator 2 unknown)"
    setup.server.heading_changed(1, 146.0)  # unchanged: nothing
    setup.server.heading_changed(2, 200.0)
    setup.server.heading_changed(1, 150.2)
    assert await setup.headings(2) == [b"40m @ 2000", b"TH6 @ 1502"]


@pytest.mark.asyncio
async def test_bad_and_unknown_commands_turn_nothing_and_log_once_each(
    setup: Setup, caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.n1mm_rotor")
    bad = [b"junk", b"<RadioInfo/>", turn_command("Nobody", 10.0), STAR_CAPTURE,
           b"<N1MMRotor><rotor>TH6</rotor><goazi>1e9</goazi></N1MMRotor>"]
    await setup.send(*(bad * 4))
    assert setup.rotators.turns == [] and setup.rotators.stops == []
    debug = [r.getMessage() for r in caplog.records if r.levelno == logging.DEBUG]
    assert len(debug) == 4, debug
    assert any("no rotator is named 'Nobody' (rotators: 40m, TH6)" in line for line in debug)
    assert any("'*'" in line for line in debug), "* is ambiguous with two rotators"
    assert setup.server.ignored == 4


@pytest.mark.asyncio
async def test_star_names_the_only_rotator() -> None:
    rotators = Rotators()
    server = N1MMRotorServer({7: ("Beam",)}, turn=rotators.turn, stop=rotators.stop,
                             headings=list, port=0, host="127.0.0.1")
    await server.start()
    try:
        server.handle(STAR_CAPTURE, "127.0.0.1")
    finally:
        await server.close()
    assert rotators.turns == [(7, 66.0)]


@pytest.mark.asyncio
async def test_a_refused_turn_is_logged_once_and_the_server_goes_on(
    setup: Setup, caplog: pytest.LogCaptureFixture,
) -> None:
    setup.rotators.refuse = True
    await setup.send(*[turn_command("TH6", 90.0)] * 3)
    setup.rotators.refuse = False
    await setup.send(turn_command("TH6", 91.0))
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == ["N1MM rotor window: turn of TH6 refused: rotator 1 is offline"]
    assert setup.rotators.turns == [(1, 91.0)]
