"""The saved state, in process: written whole and coalesced, restored for the same
configuration only, a bad file ignored with one log line; what a box must report
to be trusted without a reset; every listener bound before clients are accepted."""

from __future__ import annotations

import asyncio
import json
import logging
import os
import shutil
import socket
import threading
from collections.abc import AsyncIterator, Callable
from dataclasses import replace
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.config import load_config
from moas_gui.engine import Engine, SwitchState
from moas_gui.engine.snapshot import SnapshotError, export_selections, restore_selections
from moas_gui.engine.switchstate import StationAntennas
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.hw.moas2.messages import BoxStatus, PolarityStatus, Pong, RelayStatus, TRState
from moas_gui.hw.moas2.resync import Survey, reconcile
from moas_gui.hw.moas2.sync import UNSURE
from moas_gui.sources.n1mm_packet import radio_info_packet
from moas_gui.state_store import (
    SavedState,
    StateKeeper,
    decode,
    encode,
    fingerprint,
    load,
    state_path,
    switch_from_data,
    switch_to_data,
    write_atomic,
)

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def options() -> ServerOptions:
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST)


async def _logger_tunes(app: ServerApp, radio: int, khz: float) -> None:
    """An N1MM Logger packet for station 1's ``radio``, through the app's real listener,
    and the wait until the engine has its frequency."""
    address = app.n1mm_address
    assert address is not None
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.sendto(radio_info_packet(radio, khz), address)
    await until(lambda: app.engine is not None and app.engine.radio_view(1, radio).khz == khz,
                what=f"radio {radio} on {khz} kHz")


@pytest_asyncio.fixture
async def app() -> AsyncIterator[ServerApp]:
    server = ServerApp(options())
    yield server
    await server.close()


@pytest.fixture
def station(tmp_path: Path) -> Path:
    path = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", path)
    return path


async def _saved_station(station: Path) -> tuple[Path, dict[tuple[int, int], object]]:
    """Run ``station`` once, tune both radios, close: the state file and the views."""
    app = ServerApp(options())
    await app.open(station)
    await _logger_tunes(app, 1, 14025.0)
    app.apply_changes(app.engine.set_frequency(1, 2, 7020.0))
    await until(lambda: all(link.ready for link in app._run.links.values()))  # type: ignore[union-attr]
    views = {(v.station, v.radio): v for v in app.engine.radios()}
    await app.close()
    return state_path(station), views


# -- restoring ------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_the_same_configuration_comes_back_with_the_same_selections(
        station: Path, app: ServerApp) -> None:
    where, views = await _saved_station(station)
    assert where.exists() and views[(1, 1)].tx is not None and views[(1, 2)].tx is not None
    await app.open(station)
    assert {(v.station, v.radio): v for v in app.engine.radios()} == views
    assert app.engine.switch_states() == {1: app._run.links[1].session.desired}  # type: ignore[union-attr]


@pytest.mark.asyncio
async def test_an_edited_configuration_starts_afresh_with_one_line(
        station: Path, app: ServerApp, caplog: pytest.LogCaptureFixture) -> None:
    await _saved_station(station)
    station.write_text(station.read_text() + "\n")
    caplog.set_level(logging.INFO)
    await app.open(station)
    lines = [r.getMessage() for r in caplog.records if "saved state" in r.getMessage()]
    assert len(lines) == 1 and "another version of the configuration" in lines[0], lines
    assert all(v.tx is None for v in app.engine.radios())


def _truncated(raw: bytes) -> bytes:
    return raw[: len(raw) // 2]


def _garbage(raw: bytes) -> bytes:
    return b"\x00\xff" * 50


def _empty(raw: bytes) -> bytes:
    return b""


def _radio_not_in_config(raw: bytes) -> bytes:
    data = json.loads(raw)
    data["engine"]["radios"][0]["radio"] = [5, 9]
    return json.dumps(data).encode()


def _antenna_not_in_config(raw: bytes) -> bytes:
    data = json.loads(raw)
    data["engine"]["radios"][0]["tx"] = 9999
    return json.dumps(data).encode()


def _switch_of_wrong_type(raw: bytes) -> bytes:
    data = json.loads(raw)
    data["switches"]["1"]["stations"][0][0] = "antenna"
    return json.dumps(data).encode()


def _deep(raw: bytes) -> bytes:
    return b"[" * 100_000


@pytest.mark.asyncio
@pytest.mark.parametrize("spoil", [_truncated, _garbage, _empty, _radio_not_in_config,
                                   _antenna_not_in_config, _switch_of_wrong_type, _deep])
async def test_a_bad_state_file_is_ignored_with_one_line_and_the_server_starts(
        station: Path, app: ServerApp, caplog: pytest.LogCaptureFixture,
        spoil: Callable[[bytes], bytes]) -> None:
    where, _ = await _saved_station(station)
    where.write_bytes(spoil(where.read_bytes()))
    caplog.set_level(logging.INFO)
    result = await app.open(station)
    assert result.config is not None and app.status.file == station.name
    lines = [r for r in caplog.records if "saved state" in r.getMessage()]
    assert len(lines) == 1, [r.getMessage() for r in lines]
    assert lines[0].levelno == logging.WARNING and str(where) in lines[0].getMessage()
    assert "ignored" in lines[0].getMessage() and "Traceback" not in caplog.text
    assert all(v.tx is None for v in app.engine.radios())
    # ... and the server carries on: a logger packet still selects, and is saved again
    await _logger_tunes(app, 1, 14025.0)
    assert app.engine.radio_view(1, 1).tx is not None
    await app._run.keeper.flush()  # type: ignore[union-attr]
    saved = load(where, fingerprint(station.read_bytes()))
    assert saved is not None and saved.engine["radios"][0]["tx"] is not None


# -- writing --------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_changes_are_coalesced_into_few_writes(tmp_path: Path) -> None:
    calls = []

    def collect() -> SavedState:
        calls.append(1)
        return SavedState("x", {"n": len(calls)})

    # a delay no test waits for: what is written, is written without waiting for it
    keeper = StateKeeper(tmp_path / "s.json", collect, delay=3600)
    keeper.changed()                      # after a quiet spell: written at once
    await until(lambda: keeper.writes == 1, what="the first change written at once")
    for i in range(10_000):               # a burst: held back, to be gathered
        keeper.changed()
        if i % 1000 == 0:
            await asyncio.sleep(0)
    await asyncio.sleep(0.05)
    assert keeper.writes == 1, "the burst waits for the delay"
    await keeper.flush()                  # (the delay over:) one write for the whole burst
    assert keeper.writes == 2 and len(calls) == 2
    keeper.changed()
    await keeper.flush()
    assert keeper.writes == 3
    assert decode((tmp_path / "s.json").read_bytes(), "x").engine == {"n": 3}


@pytest.mark.asyncio
async def test_the_state_is_encoded_off_the_loop_and_an_unchanged_one_not_written_again(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    encoded_on: list[int] = []

    def spy(saved: SavedState) -> bytes:
        encoded_on.append(threading.get_ident())
        return encode(saved)

    monkeypatch.setattr("moas_gui.state_store.encode", spy)
    collected_on: list[int] = []

    def collect() -> SavedState:
        collected_on.append(threading.get_ident())
        return SavedState("x", {"n": 1})

    keeper = StateKeeper(tmp_path / "s.json", collect, delay=0)
    keeper.changed()
    await keeper.flush()
    keeper.changed()                      # the same state again: encoded, not written
    await keeper.flush()
    loop_thread = threading.get_ident()
    assert collected_on == [loop_thread, loop_thread], "collected on the loop, as it stands"
    assert len(encoded_on) == 2 and loop_thread not in encoded_on, "encoded on a worker"
    assert keeper.writes == 1
    assert decode((tmp_path / "s.json").read_bytes(), "x").engine == {"n": 1}


def test_a_write_cut_short_leaves_the_old_file_whole(tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "state" / "s.json"
    write_atomic(target, b"old, whole")

    def crash(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", crash)
    with pytest.raises(OSError):
        write_atomic(target, b"new" * 1000)
    assert target.read_bytes() == b"old, whole"
    assert sorted(p.name for p in target.parent.iterdir()) == ["s.json"]


def test_state_files_live_in_the_users_state_directory_one_per_configuration(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "xdg"))
    a, b = state_path(tmp_path / "a" / "station.moas"), state_path(tmp_path / "b" / "station.moas")
    assert a.parent == b.parent == tmp_path / "xdg" / "moas-gui" and a != b
    assert a.name.startswith("station-") and a.name.endswith(".state.json")


def test_a_switch_state_survives_the_file() -> None:
    state = SwitchState(
        stations=(StationAntennas(1, frozenset({1, 2}), 2, frozenset({3}), 5, frozenset({9}),
                                  frozenset({40})),) + tuple(StationAntennas() for _ in range(5)),
        station0=frozenset({63}), conflicts=frozenset({(1, 1), (1, 2)}),
        fast=frozenset({(0, 63)}), systems=((4, 1),), inhibited=frozenset({2}),
        inhibit_others=(frozenset({2}),) + (frozenset(),) * 5,
        use_alternate=(frozenset(),) * 5 + (frozenset({1}),), interrupt=frozenset({1}),
        enable_low=frozenset({3}), receive_delay=(0, 5, 0, 0, 0, 9999), inhibit_time=30,
        interrupt_delay=7, active=True)
    again = switch_from_data(json.loads(json.dumps(switch_to_data(state))), "switch 1")
    assert again == state
    raw = encode(SavedState("f", {"a": 1}, {1: state}))
    assert decode(raw, "f").switches == {1: state}


# -- the engine's part ----------------------------------------------------------------------

@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.moas")))
def test_every_example_comes_back_to_the_same_decisions(example: str) -> None:
    config = load_config(EXAMPLES / example).unwrap()
    engine = Engine(config, now=5.0)
    for view, khz in zip(engine.radios(), (14025.0, 7020.0, 3510.0, 21030.0, 28040.0, 1830.0) * 9,
                         strict=False):
        try:
            engine.set_frequency(view.station, view.radio, khz)
        except Exception:  # noqa: BLE001, S112 - a sub or alternate receiver follows its main
            continue
    data = json.loads(json.dumps(export_selections(engine)))
    again = Engine(config, now=1000.0)
    restore_selections(again, data)
    assert again.radios() == engine.radios()
    assert again.switch_states() == engine.switch_states()
    # the next decision is the same too: back to a band already used
    first = next(v for v in engine.radios() if v.khz is not None)
    for e in (engine, again):
        e.set_frequency(first.station, first.radio, 7020.0)
        e.set_frequency(first.station, first.radio, first.khz)
    assert again.radios() == engine.radios()


def test_a_snapshot_that_does_not_fit_leaves_the_engine_as_it_was() -> None:
    config = load_config(EXAMPLES / "small-station.moas").unwrap()
    engine = Engine(config)
    engine.set_frequency(1, 1, 14025.0)
    data = export_selections(engine)
    fresh = Engine(config)
    before = (fresh.radios(), fresh.switch_states())
    for spoil in ({"radios": [{"radio": [1, 1], "khz": "fast"}]}, {"running": "yes"},
                  {"format": 99}, {"maps": {"1": {}}}, {"latched": [True]}):
        with pytest.raises(SnapshotError):
            restore_selections(fresh, {**data, **spoil})
        assert (fresh.radios(), fresh.switch_states()) == before


# -- what a box must report to be trusted ---------------------------------------------------

HELD = replace(SwitchState(), stations=(
    StationAntennas(3, frozenset({1, 2}), 3, frozenset({1, 2}), 63, frozenset(), frozenset({40})),
    StationAntennas(5, frozenset({7}), 6, frozenset({8})),
) + tuple(StationAntennas() for _ in range(4)), station0=frozenset({60}))


def _box(tx: tuple[int, ...] = (3, 5, 63, 63, 63, 63),
         rx: tuple[int, ...] = (3, 6, 63, 63, 63, 63)) -> BoxStatus:
    return BoxStatus((TRState.RECEIVE,) * 6, tx, rx, (63,) * 6)


def _survey(pong: Pong, box: BoxStatus, polarity: frozenset[int],
            relays: set[int]) -> Survey:
    return Survey(pong, box, PolarityStatus(polarity), RelayStatus(frozenset(relays)))


def test_a_box_that_still_holds_the_saved_state_is_trusted() -> None:
    for relays in ({1, 2, 8, 60}, {1, 2, 40, 7, 60}):  # receiving; transmitting (extras)
        r = reconcile(HELD, None, _survey(Pong(True), _box(), frozenset(), relays))
        assert (r.why, dict(r.adopt)) == ("", {})
        # the tables and settings are taken as held; every station's antennas go again
        assert r.believed is not None
        assert replace(r.believed, stations=HELD.stations) == HELD
        assert r.believed.stations == (UNSURE,) * 6


@pytest.mark.parametrize(("pong", "box", "polarity", "relays", "why"), [
    (Pong(False), _box(), frozenset(), {1, 2, 8, 60}, "inactive"),
    (Pong(True), _box(), frozenset({1}), {1, 2, 8, 60}, "polarity"),
    (Pong(True), _box(), frozenset(), {1, 2, 8}, "relays"),
    (Pong(True), _box(), frozenset(), {1, 2, 8, 60, 33}, "relays"),
])
def test_a_box_that_does_not_is_loaded_again_as_values(
        pong: Pong, box: BoxStatus, polarity: frozenset[int], relays: set[int],
        why: str) -> None:
    r = reconcile(HELD, None, _survey(pong, box, polarity, relays))
    assert why in r.why and r.believed is None


def test_a_station_showing_other_antennas_than_the_saved_state_is_adopted() -> None:
    r = reconcile(HELD, None, _survey(Pong(True), _box(rx=(3, 5, 63, 63, 63, 63)), frozenset(),
                                      {1, 2, 8, 60}))
    assert dict(r.adopt) == {2: (5, 5, 63)} and "station 2" in r.why


def test_a_stopped_state_is_always_loaded() -> None:
    r = reconcile(replace(HELD, active=False), None,
                  _survey(Pong(True), _box(), frozenset(), set()))
    assert r.believed is None and r.why


# -- binding --------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_the_logger_port_is_bound_before_clients_are_accepted(
        station: Path, app: ServerApp, caplog: pytest.LogCaptureFixture) -> None:
    data = json.loads(station.read_text())
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        data["Rotators"][0]["RotctldPort"] = probe.getsockname()[1]
    station.write_text(json.dumps(data))
    caplog.set_level(logging.INFO)
    await app.open(station)
    messages = [r.getMessage() for r in caplog.records]
    udp = next(i for i, m in enumerate(messages) if m.startswith("Listening for N1MM Logger"))
    rotctld = next(i for i, m in enumerate(messages) if "rotctld" in m and "listening" in m)
    tcp = next(i for i, m in enumerate(messages) if m.startswith("Accepting clients"))
    assert udp < tcp and rotctld < tcp, messages


def test_slots_given_out_as_needed_come_back_the_same() -> None:
    """More antennas than a switch has slots: the slots given out (and those just given
    up) are part of the state, so the restored switch state is the very same."""
    from engine_builders import antenna, config, radio

    from moas_gui.config.model import Switch

    antennas = [antenna(i, (20,), {(1, 1): [i % 60], (1, 2): [i % 60]}, fast=(i,))
                for i in range(80)]
    cfg = config(antennas, [radio(1, 1, 1), radio(1, 2, 2)], switches=[Switch(1, "emulator")])
    engine = Engine(cfg)
    engine.set_frequency(1, 1, 14025, now=0)
    engine.set_frequency(1, 2, 14100, now=0)
    for i in range(2, 75):
        engine.select(1, 1, i, now=float(i))
    data = json.loads(json.dumps(export_selections(engine)))
    assert data["maps"]["1"]["slots"], "slots are given out as needed here"
    again = Engine(cfg, now=3.0)
    restore_selections(again, data)
    assert again.switch_states() == engine.switch_states()
    assert all(again.slot_of(1, i, 1, 1) == engine.slot_of(1, i, 1, 1) for i in range(80))
    engine.select(1, 2, 74 - 1, now=100.0)
    again.select(1, 2, 74 - 1, now=100.0)
    assert again.switch_states() == engine.switch_states()


@pytest.mark.asyncio
async def test_stopped_switches_stay_stopped_after_a_restart(station: Path, app: ServerApp) -> None:
    first = ServerApp(options())
    await first.open(station)
    await _logger_tunes(first, 1, 14025.0)
    await until(lambda: first._run.links[1].ready)  # type: ignore[union-attr]
    first.stop_switches()
    assert first.switches_stopped
    await first.close()
    await app.open(station)
    assert app.switches_stopped and not app.engine.running
    assert app.engine.radio_view(1, 1).tx is not None
    await until(lambda: not app.emulators()[1].view().active and app._run.links[1].ready)  # type: ignore[union-attr]
    assert app.emulators()[1].view().relays == frozenset()
    app.start_switches()
    await until(lambda: app.emulators()[1].view().relays != frozenset())


@pytest.mark.realtime
def test_a_temporary_left_by_a_writer_that_is_gone_is_removed_at_once(tmp_path: Path) -> None:
    """A server killed in the middle of a save leaves ``.NAME.PID.tmp``: the next one
    removes it at once (its writer is gone), not only a minute later; a temporary of a
    process still running is kept (it may be writing right now)."""
    import subprocess
    import sys

    from moas_gui.state_store import remove_stale_temporaries

    target = tmp_path / "s.json"
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    gone = tmp_path / f".s.json.{int(ended.stdout)}.tmp"
    gone.write_text("half")
    living = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        alive = tmp_path / f".s.json.{living.pid}.tmp"
        alive.write_text("being written")
        assert remove_stale_temporaries(target) == 1
        assert not gone.exists() and alive.exists()
    finally:
        living.kill()
        living.wait()


@pytest.mark.asyncio
async def test_a_change_still_waiting_to_be_saved_is_written_before_a_restart(
        station: Path, app: ServerApp) -> None:
    # saves are coalesced (issue 41: at most a second late); File > Restart writes what
    # waits before the configuration closes, so the reopened engine starts from it
    await app.open(station)
    keeper = app._run.keeper  # type: ignore[union-attr]
    assert keeper is not None
    await _logger_tunes(app, 1, 14025.0)
    await keeper.flush()
    keeper.delay = 3600.0  # what follows waits for a write no test waits for
    await _logger_tunes(app, 1, 7025.0)
    await asyncio.sleep(0.05)
    assert load(state_path(station), fingerprint(station.read_bytes())) is not None
    assert _saved_khz(station) == 14025.0, "the second change waits"
    await app.restart()
    assert _saved_khz(station) == 7025.0
    assert app.engine is not None and app.engine.radio_view(1, 1).khz == 7025.0
    assert app._run is not None and app._run.keeper is not keeper


def _saved_khz(station: Path) -> float | None:
    data = json.loads(state_path(station).read_text(encoding="utf-8"))
    return next(float(r["khz"]) for r in data["engine"]["radios"] if r["radio"] == [1, 1])
