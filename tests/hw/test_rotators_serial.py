"""Serial rotators through the MOAS Rotator protocol, against the fake program on 127.0.0.1.

The manager and the fake program share a fake clock: turns, reconnection pauses and
stall times pass at once; only the program started as a process runs in real time."""

from __future__ import annotations

import logging
import sys
from collections.abc import AsyncIterator
from dataclasses import replace

import pytest
import pytest_asyncio
from helpers import FakeClock, advance_until, free_port
from test_rotators_manager import Recorder

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorError, RotatorManager, Timing
from moas_gui.hw.rotators.moas_rotator_codec import Configure, Rotate, Stop, VersionRequest
from moas_gui.hw.rotators.moas_rotator_process import default_command
from moas_gui.testing.fake_moas_rotator import FakeMoasRotator

FAST = Timing(reconnect_min=0.05, reconnect_max=0.2, reply_timeout=0.5, connect_timeout=0.5,
              stall_min=1.0)


def serial(rotator_id: int, **fields: object) -> Rotator:
    base: dict[str, object] = {
        "id": rotator_id, "short_name": f"Serial {rotator_id}", "control": RotatorControl.SERIAL,
        "model": "Yaesu", "comm_port": f"COM{rotator_id}", "poll": 100,
    }
    base.update(fields)
    return Rotator(**base)  # type: ignore[arg-type]


@pytest.fixture
def clock() -> FakeClock:
    return FakeClock()


@pytest_asyncio.fixture
async def fake(clock: FakeClock) -> AsyncIterator[FakeMoasRotator]:
    program = FakeMoasRotator(speed=20.0, tick=0.02, clock=clock)
    await program.start()
    yield program
    await program.close()


async def running(rotators: list[Rotator], fake: FakeMoasRotator,
                  recorder: Recorder) -> RotatorManager:
    """A manager on the fake program, on the fake program's clock (the recorder's)."""
    assert recorder.clock is fake.clock
    manager = RotatorManager(rotators, on_change=recorder, moas_rotator_port=fake.port,
                             start_moas_rotator=False, timing=replace(FAST, clock=fake.clock))
    await manager.start()
    return manager


@pytest.mark.asyncio
async def test_connect_sends_version_then_configure_with_the_model_before_the_port(
    fake: FakeMoasRotator,
) -> None:
    recorder = Recorder(fake.clock)
    fake.move_to("COM1", 200)
    manager = await running([serial(1, ccw_limit=180, has_stop=True)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading is not None)
        assert fake.commands[:2] == [VersionRequest(), Configure(1, "4", "COM1", 100)]
        # Yaesu counts from the CCW stop at south: 200 from there is 20 degrees
        assert manager.view(1).heading == 20
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_rotate_sends_degrees_from_the_ccw_stop_and_follows_the_reports(
    fake: FakeMoasRotator,
) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1, ccw_limit=180, has_stop=True)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 180)
        await manager.rotate(1, 190)  # 10 degrees clockwise of the stop
        assert Rotate(1, 10.0) in fake.commands
        view = manager.view(1)
        assert view.target == 190 and view.moving
        done = await recorder.wait_for(lambda v: v.heading == 190 and not v.moving)
        assert done.target is None
        assert {v.heading for v in recorder.views} >= {182, 185, 188}
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_compass_controllers_get_the_compass_bearing(fake: FakeMoasRotator) -> None:
    """The manual's tribander: a Rotor-EZ with its stop at south (6.9.1)."""
    recorder = Recorder(fake.clock)
    rotor_ez = serial(0, model="RotorEZ", comm_port="COM14", ccw_limit=180, has_stop=True,
                      poll=2000)
    fake.move_to("COM14", 350)
    manager = await running([rotor_ez], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 350)
        assert Configure(0, "2", "COM14", 2000) in fake.commands
        await manager.rotate(0, 10)
        assert Rotate(0, 10.0) in fake.commands
        await recorder.wait_for(lambda v: v.heading == 10 and not v.moving)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_rotators_at_one_address_share_one_connection(fake: FakeMoasRotator) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1), serial(2), serial(3)], fake, recorder)
    try:
        await fake.wait_for(lambda: len(fake.configured) == 3)
        assert fake.connections == 1
        await manager.rotate(3, 4)
        await recorder.wait_for(lambda v: v.id == 3 and v.heading == 4 and not v.moving)
        assert manager.view(1).heading == 0 and manager.view(2).heading == 0
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_stop_sends_stop_and_ends_the_turn(fake: FakeMoasRotator) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await manager.rotate(1, 300)
        await recorder.wait_for(lambda v: v.heading is not None and v.heading >= 3)
        await manager.stop(1)
        await fake.wait_for(lambda: Stop(1) in fake.commands)
        view = manager.view(1)
        assert view.target is None
        await fake.clock.advance(0.5)
        settled = manager.view(1)
        assert not settled.moving and settled.heading is not None and settled.heading < 20
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_program_going_away_mid_turn_shows_offline_then_reconfigures_and_finishes(
    fake: FakeMoasRotator, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, "moas_gui.hw.rotators")
    recorder = Recorder(fake.clock)
    manager = await running([serial(1), serial(2)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.id == 1 and v.online)
        await manager.rotate(1, 30)
        await recorder.wait_for(lambda v: v.id == 1 and v.heading is not None and v.heading >= 5)
        await fake.drop()
        offline = await recorder.wait_for(lambda v: v.id == 1 and not v.online)
        assert offline.heading is not None and offline.heading >= 5  # last known heading kept
        assert not manager.view(2).online
        with pytest.raises(RotatorError) as caught:
            await manager.rotate(2, 10)
        assert caught.value.code == "unavailable" and "not connected" in caught.value.message
        commands_before = len(fake.commands)
        await fake.start()
        await advance_until(fake.clock, lambda: len(fake.configured) == 2, what="the reconnection")
        after = fake.commands[commands_before:]
        assert after[0] == VersionRequest()
        assert Configure(1, "4", "COM1", 100) in after and Configure(2, "4", "COM2", 100) in after
        assert Rotate(1, 30.0) in after
        await recorder.wait_for(lambda v: v.id == 1 and v.online and v.heading == 30
                                and not v.moving)
        assert "resuming the turn" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_stop_while_the_program_is_away_cancels_the_resumed_turn(
    fake: FakeMoasRotator,
) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        manager.start_rotate(1, 40)
        await recorder.wait_for(lambda v: v.heading is not None and v.heading >= 3)
        await fake.drop()
        await recorder.wait_for(lambda v: not v.online)
        with pytest.raises(RotatorError) as caught:
            manager.start_stop(1)
        assert caught.value.code == "unavailable"
        assert manager.view(1).target is None
        before = len(fake.commands)
        await fake.start()
        await advance_until(fake.clock, lambda: 1 in fake.configured, what="the reconnection")
        await fake.clock.advance(0.2)
        assert not any(isinstance(c, Rotate) for c in fake.commands[before:])
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_malformed_lines_are_logged_naming_the_rotator_and_reports_carry_on(
    fake: FakeMoasRotator, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1, short_name="Tribander")], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        fake.send_raw(b"1 north\r\x00\xff\xfe garbage\r9 45\r")
        fake.move_to("COM1", 77)
        await recorder.wait_for(lambda v: v.heading == 77)
        assert "malformed line about rotator 1 (Tribander): '1 north'" in caplog.text
        assert "heading 'north' is not a number" in caplog.text
        assert "reports rotator 9, which is not configured here" in caplog.text
        assert manager.view(1).online
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_turn_that_never_arrives_ends_after_the_stall_time(
    fake: FakeMoasRotator, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, "moas_gui.hw.rotators")
    fake.speed = 0.0  # a jammed rotator: the controller never moves
    recorder = Recorder(fake.clock)
    manager = await running([serial(1)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await manager.rotate(1, 90)
        assert manager.view(1).moving
        seen = len(recorder.views)
        ended = await recorder.wait_for(lambda v: not v.moving and v.target is None,
                                        timeout=3.0, since=seen)
        assert ended.heading == 0
        assert "stopped short of its target" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_rotator_turned_at_the_controller_shows_moving_while_it_turns(
    fake: FakeMoasRotator,
) -> None:
    recorder = Recorder(fake.clock)
    manager = await running([serial(1)], fake, recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 0)
        fake.move_to("COM1", 5)
        moving = await recorder.wait_for(lambda v: v.heading == 5)
        assert moving.moving and moving.target is None
        await recorder.wait_for(lambda v: v.heading == 5 and not v.moving, timeout=2.0)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_no_program_at_the_address_keeps_the_rotator_offline_and_retrying(
    caplog: pytest.LogCaptureFixture,
) -> None:
    port = free_port()
    clock = FakeClock()
    manager = RotatorManager([serial(1)], moas_rotator_port=port, start_moas_rotator=False,
                             timing=replace(FAST, clock=clock))
    caplog.set_level(logging.DEBUG, "moas_gui.hw.rotators")

    def failures() -> list[int]:
        return [r.levelno for r in caplog.records if "cannot connect" in r.getMessage()]

    await manager.start()
    try:
        await advance_until(clock, lambda: len(failures()) >= 3, what="three attempts")
        assert not manager.view(1).online
        assert f"MOAS Rotator at 127.0.0.1:{port}: cannot connect" in caplog.text
        # later failures only at debug level
        assert failures()[:3] == [logging.WARNING, logging.DEBUG, logging.DEBUG]
        program = FakeMoasRotator(port=port, clock=clock)
        await program.start()
        try:
            await advance_until(clock, lambda: 1 in program.configured, limit=3.0,
                           what="the program configured")
        finally:
            await program.close()
    finally:
        await manager.close()


# ---- StartMOASRotator -------------------------------------------------------------------


@pytest.mark.realtime  # a real process, its controller turning on the real clock
@pytest.mark.asyncio
async def test_local_serial_rotator_starts_the_program_and_stops_it_on_exit() -> None:
    port = free_port()
    command = [sys.executable, "-m", "moas_gui.testing.fake_moas_rotator", "--port", str(port)]
    recorder = Recorder()
    manager = RotatorManager([serial(1, address="localhost")], on_change=recorder,
                             moas_rotator_port=port, moas_rotator_command=command, timing=FAST)
    await manager.start()
    try:
        assert manager.local_program is not None
        process = manager.local_program.process
        assert process is not None and process.returncode is None
        await recorder.wait_for(lambda v: v.online and v.heading == 0, timeout=10.0)
        await manager.rotate(1, 2)
        await recorder.wait_for(lambda v: v.heading == 2 and not v.moving, timeout=5.0)
    finally:
        await manager.close()
    assert process.returncode is not None


def test_no_program_is_started_when_the_configuration_says_false_or_none_is_local() -> None:
    assert RotatorManager([serial(1)], start_moas_rotator=False).local_program is None
    assert RotatorManager([serial(1, address="192.0.2.7")]).local_program is None
    assert RotatorManager([serial(1, model="Bad Model")]).local_program is None
    rotator = serial(1, address="127.0.0.1")
    started = RotatorManager([rotator]).local_program
    assert started is not None and started.command == default_command(13020, [rotator.comm_port])
    # loopback only, and the configuration's port is what CONFIGURE may open
    assert started.command[1:] == ["-m", "moas_gui.cli.rotator", "--bind", "127.0.0.1",
                                   "--allow", rotator.comm_port]


@pytest.mark.asyncio
async def test_a_program_already_answering_is_not_started_twice(fake: FakeMoasRotator) -> None:
    manager = RotatorManager([serial(1)], moas_rotator_port=fake.port,
                             moas_rotator_command=["/bin/false"], timing=FAST)
    await manager.start()
    try:
        assert manager.local_program is not None and manager.local_program.process is None
        await fake.wait_for(lambda: 1 in fake.configured)
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_program_that_cannot_start_is_logged_and_nothing_else_stops(
    caplog: pytest.LogCaptureFixture,
) -> None:
    port = free_port()
    manager = RotatorManager(
        [serial(1), Rotator(id=2, control=RotatorControl.TEST)], moas_rotator_port=port,
        moas_rotator_command=["/nonexistent/moas-rotator"], timing=FAST,
    )
    await manager.start()
    try:
        assert "could not start the MOAS Rotator program" in caplog.text
        await manager.rotate(2, 1)
        assert manager.view(2).target == 1
    finally:
        await manager.close()
