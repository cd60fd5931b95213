"""The server follows a FlexRadio's slices itself: the test radio over real TCP on
127.0.0.1, the switch the emulator on a pseudo-terminal opened through pyserial, whose
relays the tests read."""

from __future__ import annotations

import asyncio
import json
import logging
import sys
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.config import Config, load_config
from moas_gui.config.summary import summarize
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, serve
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.sources.flex import FlexSource
from moas_gui.status import ServerState
from moas_gui.testing.flex_radio import FlexRadio

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


@dataclass
class Station:
    app: ServerApp
    box: EmulatedBox
    radio: FlexRadio

    @property
    def config(self) -> Config:
        assert self.app.config is not None
        return self.app.config

    @property
    def flex(self) -> FlexSource:
        assert self.app.sources is not None
        return self.app.sources.flex[0]

    def khz(self, radio: int) -> float | None:
        assert self.app.engine is not None
        return self.app.engine.radio_view(1, radio).khz

    def relays_of(self, radio: int) -> frozenset[int]:
        assert self.app.engine is not None
        view = self.app.engine.radio_view(1, radio)
        antenna = self.config.antenna(view.tx) if view.tx is not None else None
        if antenna is None or view.khz is None:
            return frozenset({-1})
        return next((e.relays for c in antenna.control if c.range.contains(view.khz)
                     for e in c.stations if e.applies_to(1, radio)), frozenset({-1}))

    def box_has(self, *radios: int) -> bool:
        wanted = frozenset[int]().union(*(self.relays_of(r) for r in radios))
        return self.box.view().relays == wanted


def station_file(tmp_path: Path, switch_port: str, **keys: object) -> Path:
    data = json.loads((EXAMPLES / "small-station.moas").read_text(encoding="utf-8"))
    data["Switches"][0]["Port"] = switch_port
    data["UseN1MMLogger"] = False
    data.update(keys)
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(data, indent=2), encoding="utf-8")
    return path


def options(**kw: object) -> ServerOptions:
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         **kw)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def box() -> AsyncIterator[tuple[EmulatedBox, PtyEndpoint]]:
    emulated = EmulatedBox()
    endpoint = PtyEndpoint()
    serve(emulated, endpoint, asyncio.get_running_loop())
    yield emulated, endpoint
    endpoint.close()
    emulated.close()


async def open_station(tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint],
                       slices: str = "") -> AsyncIterator[Station]:
    radio = FlexRadio()
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1, active=1, rxant="ANT1", txant="ANT1")
    radio.set_slice(1, RF_frequency=3.525, rxant="RX_A", txant="ANT2")
    entry: dict[str, object] = {"Address": f"127.0.0.1:{radio.port}", "Retry": 0.05}
    if slices:
        entry["Slices"] = slices
    path = station_file(tmp_path, box[1].path, FlexRadios=[entry])
    app = ServerApp(options())
    station = Station(app, box[0], radio)
    try:
        assert (await app.open(path)).ok
        await until(lambda: app.status.state is ServerState.NORMAL, what="the switch ready")
        yield station
    finally:
        await app.close()
        await station.radio.stop()  # the one a test started again, if it did


@pytest_asyncio.fixture
async def station(tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint]
                  ) -> AsyncIterator[Station]:
    async for s in open_station(tmp_path, box):
        yield s


@pytest_asyncio.fixture
async def so2r(tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint]) -> AsyncIterator[Station]:
    async for s in open_station(tmp_path, box, slices="A=1/1,B=1/2"):
        yield s


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_band_changes_on_the_radio_move_the_relays(station: Station) -> None:
    await until(lambda: station.khz(1) == 14025.0 and station.khz(2) == 3525.0,
                what="both slices in the engine")
    await until(lambda: station.box_has(1, 2), what="both radios' antennas on the relays")
    before = station.box.view().relays
    station.radio.set_slice(0, RF_frequency=21.025)
    await until(lambda: station.khz(1) == 21025.0, what="slice A on 15 m")
    await until(lambda: station.box_has(1, 2), what="radio 1's 15 m antenna on the relays")
    station.radio.send_raw(b"S1|slice 1 RF_frequency=seven\nnonsense\n" + b"x" * 9000 + b"\n")
    station.radio.set_slice(1, RF_frequency=7.025)  # the line after the bad ones
    await until(lambda: station.khz(2) == 7025.0, what="slice B on 40 m")
    assert station.flex.bad.counts == {"bad_frequency": 1, "not_flex": 1, "too_long": 1}
    assert station.flex.connects == 1
    await until(lambda: station.box_has(1, 2) and station.box.view().relays != before,
                what="radio 2's 40 m antenna on the relays")
    assert station.flex.describe()[1:] == [
        "station 1 radio 1: slice A 21,025.000 kHz CW, RX ANT1, TX ANT1",
        "station 1 radio 2: slice B 7,025.000 kHz CW, RX RX_A, TX ANT2"]
    assert all(not c.startswith(("slice set", "client gui")) for c in station.radio.commands)


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_so2r_slices_feed_two_radios_and_tx_moves_the_focus(so2r: Station) -> None:
    app = so2r.app
    await until(lambda: so2r.khz(1) == 14025.0 and so2r.khz(2) == 3525.0, what="A and B")
    await until(lambda: app.radio_entry(1, 1)["active"] is True, what="A transmits")
    so2r.radio.set_slice(1, tx=1)
    await until(lambda: app.radio_entry(1, 2)["active"] is True, what="TX to slice B")
    assert app.radio_entry(1, 1)["active"] is False
    assert so2r.khz(1) == 14025.0 and so2r.khz(2) == 3525.0  # each slice keeps its radio
    so2r.radio.set_interlock("TRANSMITTING")
    await until(lambda: so2r.flex.describe()[2].endswith("transmitting"), what="keyed")
    assert so2r.flex._sent[(1, 2)] == (3525.0, True)
    assert so2r.flex._sent[(1, 1)] == (14025.0, False)
    so2r.radio.set_interlock("READY")
    await until(lambda: so2r.flex._sent[(1, 2)] == (3525.0, False), what="unkeyed")
    await until(lambda: so2r.box_has(1, 2), what="the relays of both")


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_a_slice_removed_leaves_its_radio_unknown_and_the_other_followed(
        so2r: Station) -> None:
    await until(lambda: so2r.khz(2) == 3525.0, what="slice B on radio 2")
    so2r.radio.remove_slice(1)
    await until(lambda: so2r.flex.describe()[2] == "station 1 radio 2: no slice, frequency "
                                                   "unknown", what="B gone")
    so2r.radio.set_slice(0, RF_frequency=28.025)
    await until(lambda: so2r.khz(1) == 28025.0, what="A still followed")
    await until(lambda: so2r.box_has(1, 2), what="radio 1's 10 m antenna")
    assert so2r.khz(2) == 3525.0  # nothing new said of radio 2: no band guessed
    so2r.radio.set_slice(1, RF_frequency=1.825)
    await until(lambda: so2r.khz(2) == 1825.0, what="a new slice B")


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_the_radio_gone_and_back(station: Station,
                                       caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO)
    await until(lambda: station.khz(1) == 14025.0, what="the first frequency")
    port = station.radio.port
    await station.radio.stop()
    await until(lambda: not station.flex.online, what="offline")
    assert station.app.sources is not None
    words = station.app.sources.describe_flex()
    assert "offline" in words[0] and words[1:] == [
        "station 1 radio 1: no slice, frequency unknown",
        "station 1 radio 2: no slice, frequency unknown"]
    assert station.app.status.state is ServerState.NORMAL  # the switch goes on
    back = FlexRadio(port=port)
    back.set_slice(0, RF_frequency=7.025, tx=1)
    await back.start()
    station.radio = back  # the fixture stops this one
    await until(lambda: station.khz(1) == 7025.0, what="the radio back on 40 m")
    await until(lambda: station.box_has(1, 2), what="radio 1's 40 m antenna on the relays")
    assert "is back" in caplog.text and "frequency unknown until it is back" in caplog.text


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_a_peer_that_is_not_a_flexradio_is_refused_and_the_rest_runs(
        tmp_path: Path, box: tuple[EmulatedBox, PtyEndpoint],
        caplog: pytest.LogCaptureFixture) -> None:
    async def smtp(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        writer.write(b"220 mail.example ESMTP ready\r\n")
        await writer.drain()
        writer.close()

    other = await asyncio.start_server(smtp, "127.0.0.1", 0)
    port = other.sockets[0].getsockname()[1]
    radio = FlexRadio()
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    path = station_file(tmp_path, box[1].path)
    app = ServerApp(options(flex=(f"127.0.0.1:{port}", f"127.0.0.1:{radio.port}"),
                            flex_radios="A=1/2"))
    try:
        assert (await app.open(path)).ok
        assert app.sources is not None and len(app.sources.flex) == 2
        await until(lambda: app.engine is not None and app.engine.radio_view(1, 2).khz
                    == 14025.0, what="the real radio's slice A on radio 2")
        await until(lambda: app.sources is not None and app.sources.flex[0].refusals >= 1,
                    what="the other peer refused")
        errors = [r.getMessage() for r in caplog.records if r.levelname == "ERROR"]
        assert any(f"the peer at 127.0.0.1:{port} is not a FlexRadio: it began with '220 mail" in m
                   for m in errors), errors
        await until(lambda: app.status.state is ServerState.NORMAL, what="the switch runs")
    finally:
        await app.close()
        await radio.stop()
        other.close()
        await other.wait_closed()


def test_flexradios_entries_are_checked_where_they_are(tmp_path: Path) -> None:
    path = station_file(tmp_path, "/dev/ttyNONE", FlexRadios=[
        {"Address": "Shack", "Slices": "A=1/1,B=1/9"},
        {"Address": "", "Station": 1},
        {"Address": "10.0.0.2", "Slices": "A=1"},
        {"Address": "shack"}])
    result = load_config(path)
    messages = [p.message for p in result.problems]
    assert result.config is None
    assert any("feeds station 1 radio 9, which is not in \"Radios\"" in m for m in messages)
    assert any("\"Address\" of this FlexRadios entry is empty" in m for m in messages)
    assert any("\"Slices\" of this FlexRadios entry: 'A=1'" in m for m in messages)
    assert any("reads \"shack\" again" in m for m in messages)
    good = station_file(tmp_path, "/dev/ttyNONE", FlexRadios=[
        {"Address": "1234-5678-9012-3456", "Slices": "A=1/1,B=1/2", "Retry": 2}])
    config = load_config(good).config
    assert config is not None and config.flex_radios[0].slices == "A=1/1,B=1/2"
    assert "FlexRadio 1234-5678-9012-3456: slices A=1/1,B=1/2, first retry after 2 s" in \
        summarize(config)
