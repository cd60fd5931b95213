"""RotatorGenius rotators against the controller emulator on 127.0.0.1.

The manager and the emulator share a fake clock: turns, polls, reply timeouts and
reconnection pauses pass at once (the bytes still go through real sockets); the test
with the real ``rotctl`` runs on the real clock."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator
from dataclasses import replace

import pytest
import pytest_asyncio
from helpers import FakeClock, run_on
from test_rotators_manager import Recorder

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorError, RotatorManager, Timing
from moas_gui.hw.rotators.genius_codec import GeniusCommand
from moas_gui.testing.genius_server import GeniusModel, GeniusServer

FAST = Timing(reconnect_min=0.05, reconnect_max=0.2, reply_timeout=0.3, connect_timeout=0.5)


@pytest_asyncio.fixture
async def genius() -> AsyncIterator[GeniusServer]:
    server = GeniusServer(GeniusModel(speed=40.0), clock=FakeClock())
    await server.start()
    yield server
    await server.close()


def genius_rotator(server: GeniusServer, rotator_id: int = 1, port: int = 1,
                   **fields: object) -> Rotator:
    base: dict[str, object] = {
        "id": rotator_id, "short_name": f"Tower {port}", "control": RotatorControl.ROTATOR_GENIUS,
        "address": f"127.0.0.1:{server.port}", "port": port, "poll": 50,
    }
    base.update(fields)
    return Rotator(**base)  # type: ignore[arg-type]


async def running(rotators: list[Rotator], recorder: Recorder) -> RotatorManager:
    """A manager on the recorder's clock (a fake one, unless the recorder waits in real
    time)."""
    timing = replace(FAST, clock=recorder.clock) if recorder.fake else FAST
    manager = RotatorManager(rotators, on_change=recorder, timing=timing)
    await manager.start()
    return manager


@pytest.mark.asyncio
async def test_polls_heading_and_turns_with_a_three_digit_azimuth(genius: GeniusServer) -> None:
    genius.model.set_azimuth(1, 20, genius.now())
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 20)
        await manager.rotate(1, 45)
        assert GeniusCommand("A", 1, 45, b"|A1045") in genius.commands
        assert manager.view(1).target == 45 and manager.view(1).moving
        done = await recorder.wait_for(lambda v: v.heading == 45 and not v.moving)
        assert done.target is None
        assert any(v.moving and v.heading is not None and 20 < v.heading < 45
                   for v in recorder.views)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_both_rotators_of_one_controller_share_one_connection(
    genius: GeniusServer,
) -> None:
    genius.model.set_azimuth(1, 100, genius.now())
    genius.model.set_azimuth(2, 200, genius.now())
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius, 1, 1), genius_rotator(genius, 2, 2)],
                            recorder)
    try:
        await recorder.wait_for(lambda v: v.id == 2 and v.heading == 200)
        await recorder.wait_for(lambda v: v.id == 1 and v.heading == 100)
        assert len(genius._writers) == 1
        await manager.rotate(2, 210)
        await recorder.wait_for(lambda v: v.id == 2 and v.heading == 210 and not v.moving)
        assert manager.view(1).heading == 100
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_stop_stops_the_controller(genius: GeniusServer) -> None:
    genius.model.speed = 10.0
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await manager.rotate(1, 90)
        await recorder.wait_for(lambda v: v.heading is not None and v.heading >= 2)
        await manager.stop(1)
        assert GeniusCommand("S", raw=b"|S") in genius.commands
        assert not manager.view(1).moving
        await recorder.clock.advance(0.3)
        assert genius.model.rotors[0].turn is None
        assert not manager.view(1).moving and manager.view(1).heading is not None
        assert manager.view(1).heading < 10
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_999_means_offline_until_the_sensor_comes_back(
    genius: GeniusServer, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, "moas_gui.hw.rotators")
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius, short_name="Top")], recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 0)
        genius.model.rotors[0].sensor = False
        offline = await recorder.wait_for(lambda v: not v.online)
        assert offline.heading == 0
        assert "rotator 1 reports no sensor (999); rotator 1 (Top) shown offline" in caplog.text
        with pytest.raises(RotatorError) as caught:
            await manager.rotate(1, 10)
        assert caught.value.code == "unavailable" and "no sensor" in caught.value.message
        seen = len(recorder.views)
        genius.model.rotors[0].sensor = True
        await recorder.wait_for(lambda v: v.online, since=seen)
        assert "has its sensor back" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_malformed_replies_are_logged_with_the_rotator_and_polling_carries_on(
    genius: GeniusServer, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius, short_name="Top")], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        genius.prefix = b"\x00\xffnoise|Q"
        await recorder.clock.advance(0.2)
        genius.model.set_azimuth(1, 33, genius.now())
        await recorder.wait_for(lambda v: v.heading == 33)
        assert "(rotator 1 (Top)) sent a malformed reply" in caplog.text
        assert manager.view(1).online
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_refused_turn_is_unavailable(
    genius: GeniusServer, caplog: pytest.LogCaptureFixture
) -> None:
    genius.model.rotors[0].limit_ccw, genius.model.rotors[0].limit_cw = 0, 300
    recorder = Recorder(genius.clock)
    # the configuration believes in a full turn; the controller knows better
    manager = await running([genius_rotator(genius)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        with pytest.raises(RotatorError, match="refused the turn to 330") as caught:
            await manager.rotate(1, 330)
        assert caught.value.code == "unavailable"
        manager.start_rotate(1, 331)  # the same without waiting: the refusal is logged
        async with asyncio.timeout(2):
            while "turning rotator 1 (Tower 1) to 331 failed" not in caplog.text:
                await asyncio.sleep(0.02)
        assert "refused the turn to 331" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_heading_outside_the_configured_travel_is_clamped_before_sending(
    genius: GeniusServer,
) -> None:
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius, ccw_limit=0, rotation=300)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await manager.rotate(1, 320)
        assert GeniusCommand("A", 1, 300, b"|A1300") in genius.commands
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_controller_going_away_and_coming_back(
    genius: GeniusServer, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await genius.drop()
        await recorder.wait_for(lambda v: not v.online)
        with pytest.raises(RotatorError, match="not connected"):
            await manager.rotate(1, 10)
        genius.model.set_azimuth(1, 60, genius.now())
        await genius.start()
        await recorder.wait_for(lambda v: v.online and v.heading == 60)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_controller_that_stops_answering_is_dropped_and_reconnected(
    genius: GeniusServer, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder(genius.clock)
    manager = await running([genius_rotator(genius)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        genius.mute = True
        await recorder.wait_for(lambda v: not v.online)
        assert "did not answer within 0.3 s; reconnecting" in caplog.text
        genius.mute = False
        genius.model.set_azimuth(1, 5, genius.now())
        await recorder.wait_for(lambda v: v.online and v.heading == 5)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_unit_that_never_answers_a_turn_is_believed_when_the_heading_moves(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = FakeClock()
    server = GeniusServer(GeniusModel(speed=40.0), acknowledge_turns=False, clock=clock)
    await server.start()
    server.model.set_azimuth(1, 20, server.now())
    recorder = Recorder(clock)
    manager = await running([genius_rotator(server)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 20)
        await run_on(clock, manager.rotate(1, 60))
        assert GeniusCommand("A", 1, 60, b"|A1060") in server.commands
        assert manager.view(1).target == 60 and manager.view(1).moving
        await recorder.wait_for(lambda v: v.heading == 60 and not v.moving)
        assert all(v.online for v in recorder.views[1:])
        assert "reconnecting" not in caplog.text
        # Already there: nothing moves, and the turn is still taken as done.
        await run_on(clock, manager.rotate(1, 60))
        assert "reconnecting" not in caplog.text
    finally:
        await manager.close()
        await server.close()


@pytest.mark.asyncio
async def test_a_silent_unit_that_does_not_move_leaves_the_turn_unconfirmed_and_stays_connected(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = FakeClock()
    server = GeniusServer(GeniusModel(speed=40.0), acknowledge_turns=False, clock=clock)
    server.model.rotors[0].limit_ccw, server.model.rotors[0].limit_cw = 0, 300
    await server.start()
    recorder = Recorder(clock)
    manager = await running([genius_rotator(server)], recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        with pytest.raises(RotatorError, match="did not confirm the turn to 330") as caught:
            await run_on(clock, manager.rotate(1, 330))
        assert caught.value.code == "unavailable"
        assert manager.view(1).online and not manager.view(1).moving
        assert "reconnecting" not in caplog.text
        await run_on(clock, manager.rotate(1, 90))  # the link still works
        await recorder.wait_for(lambda v: v.heading == 90 and not v.moving)
    finally:
        await manager.close()
        await server.close()


@pytest.mark.realtime  # the real rotctl, waiting on the real clock
@pytest.mark.asyncio
async def test_real_rotctl_turns_a_unit_that_never_answers_a_turn() -> None:
    from test_rotators_rotctld_listener import close_all, free_port, manager_rotators, rotctl

    from moas_gui.net.rotctld_server import start_rotctld_servers

    # on the real clock, the rotor quick: rotctl waits for the turn in real time
    server = GeniusServer(GeniusModel(speed=200.0), acknowledge_turns=False)
    await server.start()
    port = free_port()
    recorder = Recorder()
    manager = await running([genius_rotator(server, rotctld_port=port)], recorder)
    listeners = await start_rotctld_servers(manager, manager_rotators(manager), "127.0.0.1")
    try:
        await recorder.wait_for(lambda v: v.online)
        code, out = await rotctl(port, "P", "60", "0")
        assert code == 0, out
        await recorder.wait_for(lambda v: v.heading == 60 and not v.moving)
        assert all(v.online for v in recorder.views[1:])
    finally:
        await close_all(listeners)
        await manager.close()
        await server.close()
