"""Re-sync under a transmitting station, in process: the server never resets the box
nor moves a keyed station's relays on its own, after a restart, a replug, a stall, a
noisy line or a state file that could not be saved (issue 19's four reproductions).

The box is the project's emulator on a real pseudo-terminal that outlives each
:class:`ServerApp` (as a real box outlives a killed server); the app reaches it through
a configuration whose ``Port`` is the pseudo-terminal's link.  A watcher records, after
every change in the box, which relays each station closes and whether its key line is
up; the checks read that record.  The whole-process versions (``kill -9``, SIGSTOP, a
pulled adapter) are in ``tests/faults/``.
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections.abc import AsyncIterator, Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui import state_store
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.engine.operations import SetFrequency
from moas_gui.hw.moas2.emulator.box import EmulatedBox, Traffic
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, remove_link, serve
from moas_gui.hw.moas2.link import LinkStatus, LinkTiming

pytestmark = [
    pytest.mark.skipif(not hasattr(__import__("os"), "openpty"),
                       reason="pseudo-terminals are POSIX"),
    pytest.mark.realtime,  # the server's link on a pseudo-terminal, its timeouts on the real clock
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.1, answer_timeout=0.5, retry_first=0.05, retry_max=0.2)
NOISY = LinkTiming(ping_interval=0.1, answer_timeout=0.2, retry_first=0.05, retry_max=0.2)
"""For the noisy line: each garbled answer is a question waiting out its answer time."""


@dataclass
class Snapshot:
    keyed: frozenset[int]
    closed: tuple[frozenset[int], ...]
    """Per station 1-6, the relays it closes."""


@dataclass
class Box:
    """An emulated MOAS II on a pseudo-terminal, with a record of what it did."""

    link: Path
    box: EmulatedBox = field(default_factory=lambda: EmulatedBox(EmulatorModel()))
    endpoint: PtyEndpoint | None = None
    record: list[Snapshot] = field(default_factory=list)
    received: bytearray = field(default_factory=bytearray)
    resets_while_keyed: int = 0

    def plug(self) -> None:
        self.endpoint = PtyEndpoint()
        serve(self.box, self.endpoint, asyncio.get_running_loop())
        make_link(self.endpoint.path, self.link)

    def unplug(self) -> None:
        assert self.endpoint is not None
        remove_link(self.link, self.endpoint.path)
        self.box.attach(None)
        self.endpoint.close()
        self.endpoint = None

    def watch(self) -> None:
        self.box.add_listener(self._traffic)
        self._note()

    def _traffic(self, kind: Traffic, data: bytes) -> None:
        if kind is Traffic.RECEIVED:
            self.received += data
            if b"*0;" in data and self.keyed():
                self.resets_while_keyed += 1
        self._note()

    def keyed(self) -> frozenset[int]:
        return frozenset(s.number for s in self.box.view().stations if s.key)

    def _note(self) -> None:
        view = self.box.view()
        self.record.append(Snapshot(self.keyed(), tuple(s.closed for s in view.stations)))

    def key(self, station: int, on: bool) -> None:
        self.box.set_tr(station, on)

    def closed(self, station: int) -> frozenset[int]:
        return self.box.view().station(station).closed

    def moved_while_keyed(self, station: int) -> list[tuple[frozenset[int], frozenset[int]]]:
        """Changes of ``station``'s closed relays between two snapshots in which it was
        keyed all along."""
        moves = []
        for before, after in zip(self.record, self.record[1:], strict=False):
            if station in before.keyed and station in after.keyed \
                    and before.closed[station - 1] != after.closed[station - 1]:
                moves.append((before.closed[station - 1], after.closed[station - 1]))
        return moves


@pytest_asyncio.fixture
async def box(tmp_path: Path) -> AsyncIterator[Box]:
    b = Box(tmp_path / "moas1")
    b.plug()
    b.watch()
    yield b
    if b.endpoint is not None:
        b.unplug()
    b.box.close()


@pytest.fixture
def station(tmp_path: Path, box: Box) -> Path:
    """small-station.moas on the pseudo-terminal (its stations in wait mode)."""
    data = (EXAMPLES / "small-station.moas").read_text()
    path = tmp_path / "station.moas"
    path.write_text(data.replace('"Port": "emulator"', json.dumps({"Port": str(box.link)})[1:-1]))
    return path


def new_app(timing: LinkTiming = FAST) -> ServerApp:
    return ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                   udp_bind="127.0.0.1", start_rotator_program=False,
                                   switch_timing=timing))


async def running(path: Path, timing: LinkTiming = FAST) -> ServerApp:
    app = new_app(timing)
    assert (await app.open(path)).ok
    await until(lambda: app._run is not None
                and all(link.ready for link in app._run.links.values()), what="a ready link")
    return app


def wanted(app: ServerApp, station: int) -> frozenset[int]:
    """The relays the engine wants station ``station`` to close while receiving."""
    assert app.engine is not None
    port = app.engine.switch_states()[1].station(station)
    return port.rx_relays


async def kill(app: ServerApp) -> None:
    """As ``kill -9`` leaves things: the state file as last written, the box untouched."""
    run = app._run
    assert run is not None and run.keeper is not None
    await run.keeper.flush()  # what a write already under way leaves on disk
    run.keeper.close()
    run.keeper = None  # nothing more is written: the process is gone
    await app.close()


async def band_change_held_while_keyed(app: ServerApp, box: Box) -> tuple[frozenset[int], ...]:
    """Radio 1 on 7.02 MHz (the 40 m dipole), keyed, moved to 14.2 MHz (the tribander):
    the box holds the change (wait mode).  Returns the relays of both antennas."""
    app.act(SetFrequency(1, 1, 7020.0))
    await until(lambda: bool(box.closed(1)), what="radio 1's 40 m antenna")
    forty = box.closed(1)
    box.key(1, True)
    await until(lambda: app._run is not None
                and app.engine.radio_view(1, 1).transmitting, what="station 1 keyed")  # type: ignore[union-attr]
    app.act(SetFrequency(1, 1, 14200.0))
    twenty = wanted(app, 1)
    assert twenty and twenty != forty
    await until(lambda: any(p for s in box.box.view().stations if s.number == 1
                            for p in s.pending), what="the change held by the box")
    assert box.closed(1) >= forty - twenty
    return forty, twenty


def no_harm(box: Box) -> None:
    assert box.resets_while_keyed == 0, "a reset reached the box while a station was keyed"
    assert box.moved_while_keyed(1) == [], "station 1's relays moved while it transmitted"


# ------------------------------------------------------------------------- restart

@pytest.mark.asyncio
async def test_a_restart_keeps_a_keyed_stations_relays_and_its_held_change_follows(
        box: Box, station: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    app = await running(station)
    forty, twenty = await band_change_held_while_keyed(app, box)
    await kill(app)
    caplog.clear()
    app = await running(station)
    try:
        assert b"*0;" not in box.received
        lines = [r.getMessage() for r in caplog.records]
        assert any("station 1 transmitting: its change waits for receive" in line
                   for line in lines), lines
        assert app.engine is not None and app.engine.radio_view(1, 1).khz == 14200.0
        assert box.closed(1) >= forty - twenty  # still on 40 m: it transmits
        box.key(1, False)
        await until(lambda: box.closed(1) == twenty, what="the 20 m antenna after receive")
        no_harm(box)
    finally:
        await app.close()


@pytest.mark.asyncio
async def test_transmit_and_receive_focus_come_back_after_a_restart(
        box: Box, station: Path) -> None:
    app = await running(station)
    app.set_focus(1, 2, "active")
    app.set_focus(1, 1, "focus")
    app.act(SetFrequency(1, 1, 7020.0))
    await kill(app)
    app = await running(station)
    try:
        assert app.radio_entry(1, 2)["active"] is True
        assert app.radio_entry(1, 1)["focus"] is True
        assert app.radio_entry(1, 1)["active"] is False
    finally:
        await app.close()


# ------------------------------------------------------------------------- replug and stall

async def outage_under_a_keyed_station(box: Box, station: Path, lose: Callable[[], None],
                                       regain: Callable[[], None]) -> None:
    """Radio 1's change held under its key; the link loses the box (``lose``) until it is
    unresponsive, then finds it again (``regain``): no reset and no reload on the way
    back, station 1's relays untouched until it receives, then the held change."""
    app = await running(station)
    try:
        forty, twenty = await band_change_held_while_keyed(app, box)
        link = app._run.links[1]  # type: ignore[union-attr]
        lose()
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE, what="the link lost")
        start = len(box.received)
        regain()
        await until(lambda: link.ready, what="the link back")
        again = bytes(box.received[start:])
        assert b"*0;" not in again and b"%0;" not in again, again  # no reset, no reload
        assert box.closed(1) >= forty - twenty
        box.key(1, False)
        await until(lambda: box.closed(1) == twenty, what="the 20 m antenna after receive")
        no_harm(box)
    finally:
        await app.close()


@pytest.mark.asyncio
async def test_a_replug_under_a_keyed_station_sends_only_what_differs(
        box: Box, station: Path) -> None:
    await outage_under_a_keyed_station(box, station, box.unplug, box.plug)


@pytest.mark.asyncio
async def test_a_stall_longer_than_every_timeout_reloads_nothing_under_a_keyed_station(
        box: Box, station: Path) -> None:
    # the server hears nothing for longer than every timeout (a stopped process, a
    # suspended laptop): the box's answers are lost meanwhile
    def answer_again() -> None:
        assert box.endpoint is not None
        box.box.attach(box.endpoint.write)

    await outage_under_a_keyed_station(box, station, lambda: box.box.attach(None),
                                       answer_again)


# ------------------------------------------------------------------------- a noisy line

@pytest.mark.asyncio
async def test_a_noisy_line_that_garbles_the_status_answers_never_resets_a_keyed_box(
        box: Box, station: Path, caplog: pytest.LogCaptureFixture) -> None:
    app = await running(station, NOISY)
    try:
        _, twenty = await band_change_held_while_keyed(app, box)
        link = app._run.links[1]  # type: ignore[union-attr]
        assert box.endpoint is not None
        endpoint = box.endpoint
        garbled = {"n": 0}

        def noisy(data: bytes) -> None:  # box status answers come out as noise
            if b'"B' in data and garbled["n"] < 4:
                garbled["n"] += 1
                data = data.replace(b'"B', b'"\x07\x1bZZ')
            endpoint.write(data)

        caplog.set_level(logging.INFO)
        box.box.attach(None)
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE, what="the link unresponsive")
        start = len(box.received)
        box.box.attach(noisy)
        await until(lambda: link.ready, what="the link back after the noise")
        assert garbled["n"] == 4
        again = bytes(box.received[start:])
        assert b"*0;" not in again, again
        assert any("did not answer every status request" in r.getMessage()
                   for r in caplog.records)
        box.key(1, False)
        await until(lambda: box.closed(1) == twenty, what="the 20 m antenna after receive")
        no_harm(box)
    finally:
        await app.close()


# ------------------------------------------------------------------------- a stale state file

@pytest.mark.asyncio
async def test_after_a_failed_save_the_box_wins_over_the_stale_state(
        box: Box, station: Path, monkeypatch: pytest.MonkeyPatch,
        caplog: pytest.LogCaptureFixture) -> None:
    app = await running(station)
    app.act(SetFrequency(1, 1, 7020.0))
    await until(lambda: bool(box.closed(1)))
    forty = box.closed(1)
    assert app._run is not None and app._run.keeper is not None
    await app._run.keeper.flush()  # the file says: radio 1 on 7.02 MHz

    def disk_full(path: Path, data: bytes) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(state_store, "write_atomic", disk_full)
    app.act(SetFrequency(1, 1, 14200.0))  # not saved
    twenty = wanted(app, 1)
    await until(lambda: box.closed(1) == twenty)
    box.key(1, True)
    await until(lambda: app.engine is not None and app.engine.radio_view(1, 1).transmitting)
    await kill(app)
    monkeypatch.undo()
    caplog.set_level(logging.INFO)
    app = await running(station)
    try:
        assert b"*0;" not in box.received
        assert app.engine is not None
        view = app.engine.radio_view(1, 1)
        assert wanted(app, 1) == twenty, "the engine took the antenna the box holds"
        assert view.tx is not None
        lines = [r.getMessage() for r in caplog.records]
        assert any("keeping what the box holds" in line for line in lines), lines
        assert any("kept the antennas switch 1 holds" in line for line in lines), lines
        box.key(1, False)
        await until(lambda: box.closed(1) == twenty)
        assert box.closed(1) != forty
        no_harm(box)
    finally:
        await app.close()


# ------------------------------------------------------------------------- the operator

@pytest.mark.asyncio
async def test_reset_switches_by_the_operator_names_the_keyed_station(
        box: Box, station: Path, caplog: pytest.LogCaptureFixture) -> None:
    app = await running(station)
    try:
        app.act(SetFrequency(1, 1, 21200.0))
        await until(lambda: bool(box.closed(1)))
        box.key(1, True)
        link = app._run.links[1]  # type: ignore[union-attr]
        await until(lambda: link.session.keyed() == {1}, what="the link told station 1 keyed")
        caplog.set_level(logging.WARNING)
        app.reset_switches()
        await until(lambda: b"*0;" in box.received)
        assert any("reset by the operator with station 1 transmitting" in r.getMessage()
                   for r in caplog.records)
    finally:
        await app.close()

