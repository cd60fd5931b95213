"""The OTRSP source on a real pseudo-terminal through pyserial, and its command parser.

No public capture of a logger's OTRSP stream was found.  The session below is
written from the protocol's command list (K1XM, k1xm.org/OTRSP, and the
reference device's firmware, m1dst/SO2Rduino) and from what N1MM Logger+ is
reported to send (kg3v.com/2017/06/02/using-n1mm-otrsp-data-for-antenna-switching/:
``AUX1``/``AUX2`` with the Antennas-table row on a band change, ``TX``/``RX`` on
focus changes): a logger opening the port asks the device's name, puts radio
1 on 20 m (row 3) and radio 2 on 40 m (row 5), gives radio 1 the focus in
stereo, then moves the transmit focus to radio 2.
"""

from __future__ import annotations

import asyncio
import logging
import os
import sys
from collections.abc import AsyncIterator, Iterator
from pathlib import Path

import pytest
import pytest_asyncio
from rig_support import Pty

from moas_gui.retry import Backoff, Pauses
from moas_gui.sources.base import ActiveRadio, FocusRadio, SourceEvent
from moas_gui.sources.otrsp import AuxAntenna, OtrspMap, OtrspSource
from moas_gui.sources.otrsp_command import (
    Aux,
    CommandParser,
    OtrspError,
    Query,
    RxFocus,
    TxFocus,
    parse_command,
)

SESSION = b"?NAME\rAUX13\rAUX25\rRX1S\rTX1\rTX2\r"
MAPPING = OtrspMap(station=3, radios={1: 1, 2: 2},
                   antennas={(1, 3): 12, (2, 5): 21, (2, 3): 22})


# -- the parser ---------------------------------------------------------------------------

def test_the_session_parses_to_its_commands() -> None:
    assert CommandParser().feed(SESSION) == [
        Query("NAME"), Aux(1, 3), Aux(2, 5), RxFocus(1, "stereo"), TxFocus(1), TxFocus(2)]


@pytest.mark.parametrize(("text", "command"), [
    ("TX2", TxFocus(2)), ("rx2", RxFocus(2, "mono")), ("RX1R", RxFocus(1, "reverse")),
    ("AUX215", Aux(2, 15)), ("AUX1255", Aux(1, 255)), ("?AUX1", Query("AUX1")),
])
def test_each_command_form(text: str, command: object) -> None:
    assert parse_command(text) == command


def test_cr_lf_and_bare_lf_end_lines_too_and_bytes_may_come_one_by_one() -> None:
    parser = CommandParser()
    out = [c for b in b"TX1\r\nTX2\nAUX14\r" for c in parser.feed(bytes([b]))]
    assert out == [TxFocus(1), TxFocus(2), Aux(1, 4)]


@pytest.mark.parametrize(("data", "reason"), [
    (b"TX3\r", "unknown"), (b"HELLO\r", "unknown"), (b"AUX1256\r", "out_of_range"),
    (b"AUX3 1\r", "unknown"), (b"\xff\xfe\r", "not_ascii"), (b"X" * 100 + b"\r", "too_long"),
])
def test_malformed_lines_are_refused_with_a_reason(data: bytes, reason: str) -> None:
    out = CommandParser().feed(data)
    assert len(out) == 1 and isinstance(out[0], OtrspError) and out[0].reason == reason


def test_an_overlong_line_is_skipped_to_its_end_and_the_next_line_counts() -> None:
    parser = CommandParser()
    first = parser.feed(b"Z" * 500)
    assert [e.reason for e in first if isinstance(e, OtrspError)] == ["too_long"]
    assert parser.feed(b"Z" * 500 + b"\rTX2\r") == [TxFocus(2)]


# -- the logic without a port -------------------------------------------------------------

def test_the_session_gives_focus_and_mapped_antennas_once_each() -> None:
    events: list[SourceEvent | AuxAntenna] = []
    source = OtrspSource("/dev/null", MAPPING, events.append)
    source.feed(SESSION + b"TX2\rAUX13\r")  # repeats change nothing
    origin = "OTRSP /dev/null"
    assert events == [AuxAntenna(3, 1, 12, 3, origin), AuxAntenna(3, 2, 21, 5, origin),
                      FocusRadio(3, 1, origin), ActiveRadio(3, 1, origin),
                      ActiveRadio(3, 2, origin)]


def test_an_unmapped_aux_value_says_nothing_but_one_debug_line(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.otrsp")
    events: list[object] = []
    source = OtrspSource("COM7", MAPPING, events.append)
    source.feed(b"AUX19\rAUX19\rAUX19\rGARBAGE\rGARBAGE\r")
    assert events == []
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) == 2
    assert "AUX1 9 is not mapped to an antenna" in lines[0]
    assert "'GARBAGE' is not an OTRSP command" in lines[1]


# -- a real pseudo-terminal ---------------------------------------------------------------

pty_only = pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX")


@pytest.fixture
def pty(tmp_path: Path) -> Iterator[Pty]:
    terminal = Pty(tmp_path / "otrsp-port")
    yield terminal
    if terminal.master >= 0:
        os.close(terminal.master)


class Events(list[object]):
    async def until(self, count: int, timeout: float = 5.0) -> None:
        async def wait() -> None:
            while len(self) < count:
                await asyncio.sleep(0.01)
        await asyncio.wait_for(wait(), timeout)


@pytest_asyncio.fixture
async def source(pty: Pty) -> AsyncIterator[tuple[OtrspSource, Events]]:
    events = Events()
    running = OtrspSource(str(pty.link), MAPPING, events.append)
    running._backoff = Pauses(Backoff(first=0.05, most=0.1))
    await running.start()
    while not running.link.connected:
        await asyncio.sleep(0.01)
    yield running, events
    await running.close()


@pytest.mark.realtime  # a real pseudo-terminal, on the real clock
@pty_only
@pytest.mark.asyncio
async def test_the_logger_session_over_a_pty(pty: Pty, source: tuple) -> None:
    _, events = source
    pty.write(SESSION)
    assert await pty.read_until(b"\r") == b"NAMEmoas-gui\r"
    await events.until(5)
    origin = f"OTRSP {pty.link}"
    assert events[-1] == ActiveRadio(3, 2, origin)
    assert AuxAntenna(3, 2, 21, 5, origin) in events
    pty.write(b"?TX\r?AUX2\r?RX\r?ECR0\r")
    assert await pty.read_until(b"?ECR0\r") == b"TX2\rAUX25\rRX1S\r?ECR0\r"


@pytest.mark.realtime  # a real pseudo-terminal, on the real clock
@pty_only
@pytest.mark.asyncio
async def test_a_port_that_vanishes_and_returns_is_logged_once_each_way(
        pty: Pty, source: tuple, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.otrsp")
    running, events = source
    pty.write(b"TX2\r")
    await events.until(1)
    pty.vanish()
    pty.link.unlink()
    while running.link.failures < 4:
        await asyncio.sleep(0.02)
    pty.open()
    while not running.link.connected:
        await asyncio.sleep(0.02)
    pty.write(b"TX1\r")
    await events.until(2)
    assert events[-1] == ActiveRadio(3, 1, f"OTRSP {pty.link}")
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert len(warnings) == 1 and f"OTRSP port {pty.link} lost" in warnings[0]
    assert sum("is back" in r.getMessage() for r in caplog.records) == 1


@pytest.mark.realtime  # a real pseudo-terminal, on the real clock
@pty_only
@pytest.mark.asyncio
async def test_a_flood_of_garbage_on_the_pty_changes_nothing(pty: Pty, source: tuple,
                                                             caplog: pytest.LogCaptureFixture
                                                             ) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.sources.otrsp")
    running, events = source
    pty.write(bytes(range(256)) * 20 + b"\rAUX1200\r" * 50 + b"TX9\r" * 50)
    pty.write(b"TX2\r")
    await events.until(1)
    assert list(events) == [ActiveRadio(3, 2, f"OTRSP {pty.link}")]
    assert running.bad.total >= 100
    assert len([r for r in caplog.records if "dropped" in r.getMessage()]) <= 4
