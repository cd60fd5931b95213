"""The server runs rigctld, flrig and OTRSP sources itself, from its configuration and its
command line: the real ``rigctld -m 1`` changed by the real ``rigctl``, a stand-in flrig
over HTTP on 127.0.0.1, a logger's OTRSP written to a real pseudo-terminal; the switch is
the emulator on another pseudo-terminal, opened through pyserial, whose relays the tests
read."""

from __future__ import annotations

import asyncio
import json
import shutil
import sys
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import pytest_asyncio
from flrig_fake import FakeFlrig
from helpers import free_port, until
from rig_support import Pty, rigctl, start_rigctld

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.cli.server import check
from moas_gui.config import Config
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, serve
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.spec import server_spec
from moas_gui.status import ServerState

pytestmark = [
    pytest.mark.realtime,  # the server on the emulator's pseudo-terminal, the real rigctld
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
    pytest.mark.skipif(shutil.which("rigctld") is None or shutil.which("rigctl") is None,
                       reason="Hamlib's rigctld and rigctl (Debian libhamlib-utils)"),
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)
TRIBANDER, DIPOLE_80, VERTICAL = 0, 2, 3
"""small-station.moas: the tribander covers 20, 15 and 10 m, the vertical every band."""


@dataclass
class Station:
    """The server and everything around it."""

    app: ServerApp
    box: EmulatedBox
    rig_port: int
    flrig: FakeFlrig
    otrsp: Pty
    path: Path

    @property
    def config(self) -> Config:
        assert self.app.config is not None
        return self.app.config

    def relays_of(self, radio: int) -> frozenset[int]:
        """The relays the configuration gives radio ``radio`` of station 1 for its antenna."""
        assert self.app.engine is not None
        view = self.app.engine.radio_view(1, radio)
        antenna = self.config.antenna(view.tx) if view.tx is not None else None
        if antenna is None or view.khz is None:
            return frozenset({-1})  # no relay is -1: never on the box
        return next((e.relays for c in antenna.control if c.range.contains(view.khz)
                     for e in c.stations if e.applies_to(1, radio)), frozenset({-1}))

    def box_has(self, *radios: int) -> bool:
        """Whether the box's closed relays are exactly those of ``radios``' antennas."""
        wanted = frozenset[int]().union(*(self.relays_of(r) for r in radios))
        return self.box.view().relays == wanted

    def closed(self, radio: int) -> bool:
        """Whether the relays of ``radio``'s antenna are closed on the box."""
        return self.relays_of(radio) <= self.box.view().relays


def station_file(tmp_path: Path, switch_port: str, **keys: object) -> Path:
    data = json.loads((EXAMPLES / "small-station.moas").read_text(encoding="utf-8"))
    data["Switches"][0]["Port"] = switch_port
    data["UseN1MMLogger"] = False
    data.update(keys)
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(data, indent=2), encoding="utf-8")
    return path


def options(*sources: str) -> ServerOptions:
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         sources=tuple(server_spec(s) for s in sources))


@pytest_asyncio.fixture
async def box() -> AsyncIterator[tuple[EmulatedBox, PtyEndpoint]]:
    emulated = EmulatedBox()
    endpoint = PtyEndpoint()
    serve(emulated, endpoint, asyncio.get_running_loop())
    yield emulated, endpoint
    endpoint.close()
    emulated.close()


@pytest_asyncio.fixture
async def station(tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint]
                  ) -> AsyncIterator[Station]:
    rig_port = free_port()
    rigctld = await asyncio.to_thread(start_rigctld, rig_port)
    flrig = FakeFlrig()
    await flrig.start()
    otrsp = Pty(tmp_path / "otrsp")
    path = station_file(
        tmp_path, box[1].path,
        Rigctld=[{"Station": 1, "Radio": 1, "Address": f"127.0.0.1:{rig_port}", "Rate": 50}],
        Flrig=[{"Station": 1, "Radio": 2, "Address": f"127.0.0.1:{flrig.port}", "Rate": 50}],
        OTRSP=[{"Station": 1, "Port": str(otrsp.link),
                "AUX1": [{"Value": 3, "Antenna": VERTICAL}, {"Value": 5, "Antenna": TRIBANDER}],
                "AUX2": [{"Value": 2, "Antenna": DIPOLE_80}]}])
    app = ServerApp(options())
    try:
        assert (await app.open(path)).ok
        await until(lambda: app.status.state is ServerState.NORMAL, what="the switch ready")
        yield Station(app, box[0], rig_port, flrig, otrsp, path)
    finally:
        await app.close()
        await flrig.close()
        rigctld.terminate()
        await asyncio.to_thread(rigctld.wait, 5)
        otrsp.vanish()


@pytest.mark.asyncio
async def test_rigctl_changing_the_rig_moves_the_radio_and_the_switch_relays(
        station: Station) -> None:
    app = station.app
    assert app.engine is not None
    await until(lambda: app.engine.radio_view(1, 1).khz == 145000.0,  # type: ignore[union-attr]
                what="the dummy rig's first frequency in the engine")
    await rigctl(station.rig_port, "F", "14025000")
    await until(lambda: app.engine.radio_view(1, 1).khz == 14025.0,  # type: ignore[union-attr]
                what="rigctl's 20 m in the engine")
    await until(lambda: station.box_has(1, 2), what="radio 1's 20 m antenna on the relays")
    await rigctl(station.rig_port, "F", "3525000")
    await until(lambda: app.engine.radio_view(1, 1).khz == 3525.0,  # type: ignore[union-attr]
                what="rigctl's 80 m in the engine")
    await until(lambda: station.box_has(1, 2), what="radio 1's 80 m antenna on the relays")
    rig = app.sources.polled[0]  # type: ignore[union-attr]
    assert rig.origin == f"rigctld 127.0.0.1:{station.rig_port}" and rig.interval == 0.02


@pytest.mark.asyncio
async def test_flrig_split_reaches_the_configured_radio(station: Station) -> None:
    app, flrig = station.app, station.flrig
    assert app.engine is not None
    await until(lambda: app.engine.radio_view(1, 2).khz == 14070.0,  # type: ignore[union-attr]
                what="flrig's VFO A on station 1 radio 2")
    await until(lambda: station.closed(2), what="radio 2's antenna on the relays")
    flrig.rig.update(vfoA=21025000, vfoB=21030000, split=1)
    await until(lambda: app.engine.radio_view(1, 2).khz == 21025.0,  # type: ignore[union-attr]
                what="flrig's new band")
    assert app.engine.radio_view(1, 2).tx_khz == 21030.0
    await until(lambda: station.closed(2), what="radio 2's 15 m antenna on the relays")
    assert app.engine.radio_view(1, 1).khz == 145000.0, "radio 1 is rigctld's alone"


@pytest.mark.asyncio
async def test_otrsp_aux_selects_the_mapped_antenna_and_tx_moves_the_transmit_focus(
        station: Station) -> None:
    app, pty = station.app, station.otrsp
    assert app.engine is not None and app.sources is not None
    station.flrig.rig["vfoA"] = 3_525_000
    await until(lambda: app.engine.radio_view(1, 2).khz == 3525.0,  # type: ignore[union-attr]
                what="flrig's 80 m on radio 2")
    await until(lambda: app.sources.otrsp[0].link.connected,  # type: ignore[union-attr]
                what="the OTRSP port open")
    pty.write(b"AUX22\r")  # radio 2 takes the 80 m dipole, and leaves the vertical free
    await until(lambda: app.engine.radio_view(1, 2).tx == DIPOLE_80,  # type: ignore[union-attr]
                what="AUX2 2 selecting the 80 m dipole")
    # radio 1 to 20 m by its own rig: a frequency set beside it would last only until the
    # rigctld source next reports (a reconnection under load reports 145 MHz again)
    await rigctl(station.rig_port, "F", "14025000")
    await until(lambda: app.engine.radio_view(1, 1).khz == 14025.0,  # type: ignore[union-attr]
                what="rigctld's 20 m on radio 1")
    pty.write(b"AUX19\r")  # no antenna for AUX1 9: nothing changes
    pty.write(b"AUX15\r")  # the tribander for radio 1
    await until(lambda: app.engine.radio_view(1, 1).tx == TRIBANDER,  # type: ignore[union-attr]
                what="AUX1 5 selecting the tribander")
    pty.write(b"AUX13\rTX2\r")
    await until(lambda: app.engine.radio_view(1, 1).tx == VERTICAL,  # type: ignore[union-attr]
                what="AUX1 3 selecting the vertical")
    await until(lambda: app.radio_entry(1, 2)["active"] is True, what="TX2: radio 2 active")
    assert app.radio_entry(1, 1)["active"] is False
    await until(lambda: station.box_has(1, 2), what="the vertical and the dipole on the relays")
    assert station.box.view().relays == {3, 19, 6, 25}
    pty.write(b"?TX\r")
    assert await pty.read_until(b"\r") == b"TX2\r"


@pytest.mark.asyncio
async def test_close_and_restart_close_every_rig_source(station: Station) -> None:
    app, flrig = station.app, station.flrig
    sources = app.sources
    assert sources is not None
    await until(lambda: flrig.connections >= 1 and sources.otrsp[0].link.connected)
    first = (*sources.polled, *sources.otrsp)
    await app.restart()
    assert app.sources is not sources and all(s._task is None for s in first)
    assert app.sources is not None and len(app.sources.polled) == 2
    flrig.rig["vfoA"] = 7025000
    await until(lambda: app.engine.radio_view(1, 2).khz == 7025.0,  # type: ignore[union-attr]
                what="flrig followed after the restart")
    await until(lambda: len(flrig._writers) == 1, what="one connection to flrig, not two")
    again = (*app.sources.polled, *app.sources.otrsp)
    await app.close()
    assert all(s._task is None for s in again)
    await until(lambda: not flrig._writers, what="the server's flrig connection closed")


@pytest.mark.asyncio
async def test_command_line_sources_run_beside_the_files_and_bad_ones_are_left_out(
        tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint],
        caplog: pytest.LogCaptureFixture) -> None:
    rig_port = free_port()
    rigctld = await asyncio.to_thread(start_rigctld, rig_port)
    path = station_file(tmp_path, box[1].path)
    app = ServerApp(options(f"rigctld:{rig_port},station=1,radio=2,rate=50",
                            f"rigctld:{rig_port},station=1,radio=7",
                            "otrsp:/dev/ttyNONE,station=1,ant1.3=99"))
    try:
        assert (await app.open(path)).ok
        assert app.sources is not None and len(app.sources.polled) == 1
        assert app.sources.otrsp == []
        errors = [r.getMessage() for r in caplog.records if r.levelname == "ERROR"]
        assert any("station 1 radio 7 is not in the configuration" in m for m in errors), errors
        assert any("antenna 99 is not in the configuration" in m for m in errors), errors
        await rigctl(rig_port, "F", "7025000")
        await until(lambda: app.engine.radio_view(1, 2).khz == 7025.0,  # type: ignore[union-attr]
                    what="the command line's rigctld on station 1 radio 2")
        assert app.engine.radio_view(1, 1).khz is None  # type: ignore[union-attr]
    finally:
        await app.close()
        rigctld.terminate()
        await asyncio.to_thread(rigctld.wait, 5)


@pytest.mark.asyncio
async def test_a_source_entry_that_is_wrong_opens_nothing_and_says_where(
        tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint],
        capsys: pytest.CaptureFixture[str]) -> None:
    path = station_file(tmp_path, box[1].path,
                        Rigctld=[{"Station": 1, "Radio": 1, "Address": "127.0.0.1:99999"}])
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1) if "99999" in text)
    app = ServerApp(options())
    try:
        result = await app.open(path)
        assert result.config is None and app.sources is None
        [problem] = result.errors
        assert problem.line == line
        assert "\"Address\" of this Rigctld entry is \"127.0.0.1:99999\"" in problem.message
        assert check(str(path)) == 1  # moas-server --check
        printed = capsys.readouterr().out
        assert f"station.moas:{line}:" in printed and "99999" in printed
    finally:
        await app.close()
