"""The rotctld-compatible listener: its codec, raw sockets, and the real ``rotctl -m 2``."""

from __future__ import annotations

import asyncio
import logging
import shutil
import socket
from collections.abc import AsyncIterator
from dataclasses import replace

import pytest
import pytest_asyncio
from helpers import FakeClock, free_port
from hypothesis import given
from hypothesis import strategies as st
from test_rotators_manager import Recorder

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorManager, Timing
from moas_gui.hw.rotators.headings import Travel
from moas_gui.net.rotctld_codec import (
    RequestParser,
    RotctldRequest,
    answer,
    azimuth_for,
    move_target,
    scale_for,
)
from moas_gui.net.rotctld_server import RotctldServer, start_rotctld_servers

FAST = Timing(test_tick=0.05, reconnect_min=0.05, reconnect_max=0.2, reply_timeout=0.5,
              connect_timeout=0.5)
ROTCTL = shutil.which("rotctl")


# ---- the codec ---------------------------------------------------------------------------

def parse(*chunks: bytes) -> list[RotctldRequest]:
    parser = RequestParser()
    out: list[RotctldRequest] = []
    for chunk in chunks:
        out += parser.feed(chunk)
    return out


def test_commands_are_read_from_a_stream_not_from_lines() -> None:
    assert parse(b"P 10 20 p\n") == [RotctldRequest("set_pos", ("10", "20")),
                                     RotctldRequest("get_pos")]
    assert parse(b"P\n10\n", b"20\n") == [RotctldRequest("set_pos", ("10", "20"))]
    assert parse(b"p\r\n\\get_pos\n\\dump_state\n") == [
        RotctldRequest("get_pos"), RotctldRequest("get_pos"), RotctldRequest("dump_state")]


def test_an_argument_is_complete_only_when_whitespace_follows() -> None:
    parser = RequestParser()
    assert parser.feed(b"P 12") == []
    assert parser.feed(b"3.5 4") == []
    assert parser.feed(b"5\n") == [RotctldRequest("set_pos", ("123.5", "45"))]


def test_extended_prefixes_choose_the_record_separator() -> None:
    assert parse(b"+p\n;p\n|\\set_pos 1 2\n") == [
        RotctldRequest("get_pos", separator="\n"), RotctldRequest("get_pos", separator=";"),
        RotctldRequest("set_pos", ("1", "2"), separator="|")]


def test_comments_blank_lines_unknown_commands_and_quit() -> None:
    assert parse(b"# hello\n\n\nZ\n\\bogus\nq\n") == [
        RotctldRequest("Z", known=False), RotctldRequest("bogus", known=False),
        RotctldRequest("quit")]


def test_a_flood_without_commands_is_dropped_and_flagged() -> None:
    parser = RequestParser()
    parser.feed(b"\\" + b"x" * 5000)
    assert parser.overflowed
    assert parser.feed(b"\np\n") == [RotctldRequest("get_pos")]


@given(st.binary(max_size=300))
def test_the_parser_survives_any_bytes(data: bytes) -> None:
    parser = RequestParser()
    parser.feed(data)
    parser.feed(b"\n# resync\n")
    assert parser.feed(b"\np\n")[-1] == RotctldRequest("get_pos")


def test_default_and_extended_answers_match_rotctld() -> None:
    values = (("Azimuth", "39.26"), ("Elevation", "0.00"))
    assert answer(RotctldRequest("get_pos"), values) == b"39.26\n0.00\n"
    assert answer(RotctldRequest("get_pos", separator="\n"), values) == \
        b"get_pos:\nAzimuth: 39.26\nElevation: 0.00\nRPRT 0\n"
    assert answer(RotctldRequest("get_pos", separator=";"), values) == \
        b"get_pos:;Azimuth: 39.26;Elevation: 0.00;RPRT 0\n"
    assert answer(RotctldRequest("set_pos", ("135", "22.5"), separator="|")) == \
        b"set_pos: 135 22.5|RPRT 0\n"
    assert answer(RotctldRequest("set_pos", ("500", "10"), separator="\n"), code=1) == \
        b"set_pos: 500 10\nRPRT -1\n"
    assert answer(RotctldRequest("stop")) == b"RPRT 0\n"
    assert answer(RotctldRequest("stop"), code=9) == b"RPRT -9\n"


def test_the_offered_scale_starts_at_the_stop_and_always_covers_a_compass() -> None:
    south = scale_for(Travel(180, 360, has_stop=True))
    assert (south.min_az, south.max_az) == (-180.0, 360.0)
    assert azimuth_for(south, 270) == -90.0
    overlap = scale_for(Travel(0, 450, has_stop=True))
    assert (overlap.min_az, overlap.max_az) == (0.0, 450.0)
    assert azimuth_for(overlap, 40) == 40.0
    free = scale_for(Travel(0, 360))
    assert (free.min_az, free.max_az) == (-180.0, 540.0)
    assert azimuth_for(free, 359.5) == 359.5


# ---- the listener on a socket ------------------------------------------------------------

def manager_rotators(manager: RotatorManager) -> list[Rotator]:
    """The rotators ``manager`` serves, as the server hands them to the listeners."""
    return [manager.rotator(rotator_id) for rotator_id in manager.drivers]


async def close_all(listeners: list[RotctldServer]) -> None:
    for listener in listeners:
        await listener.close()


def listened_rotator(port: int, **fields: object) -> Rotator:
    base: dict[str, object] = {"id": 6, "short_name": "Stack", "control": RotatorControl.TEST,
                               "ccw_limit": 180, "rotation": 360, "has_stop": True,
                               "rotctld_port": port}
    base.update(fields)
    return Rotator(**base)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def served() -> AsyncIterator[tuple[RotatorManager, int, Recorder]]:
    """A Test rotator behind a listener, and an offline Hamlib one: on a fake clock, which
    the recorder moves on while a test waits for a view (the Test rotator's turns take
    no time)."""
    port = free_port()
    recorder = Recorder(FakeClock())
    manager = RotatorManager(
        [listened_rotator(port),
         Rotator(id=7, control=RotatorControl.HAMLIB, address=f"127.0.0.1:{free_port()}",
                 rotctld_port=free_port())],
        on_change=recorder, timing=replace(FAST, clock=recorder.clock),
    )
    await manager.start()
    listeners = await start_rotctld_servers(manager, manager_rotators(manager), "127.0.0.1")
    yield manager, port, recorder
    await close_all(listeners)
    await manager.close()


async def exchange(port: int, data: bytes, expect_lines: int) -> list[str]:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        writer.write(data)
        async with asyncio.timeout(2.0):
            return [(await reader.readline()).decode() for _ in range(expect_lines)]
    finally:
        writer.close()
        await writer.wait_closed()


@pytest.mark.asyncio
async def test_dump_state_offers_the_rotators_scale(served: tuple[RotatorManager, int, Recorder],
                                                    ) -> None:
    _, port, _ = served
    lines = await exchange(port, b"\\dump_state\n", 9)
    assert lines == ["1\n", "2\n", "min_az=-180.000000\n", "max_az=360.000000\n",
                     "min_el=0.000000\n", "max_el=90.000000\n", "south_zero=0\n",
                     "rot_type=AzEl\n", "done\n"]
    extended = await exchange(port, b"+\\dump_state\n", 11)
    assert extended[0] == "dump_state:\n" and extended[1] == "rotctld Protocol Ver: 1\n"
    assert extended[-1] == "RPRT 0\n"


@pytest.mark.asyncio
async def test_position_turn_and_stop_over_a_socket(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, port, recorder = served
    assert await exchange(port, b"+p\n", 4) == [
        "get_pos:\n", "Azimuth: -180.00\n", "Elevation: 0.00\n", "RPRT 0\n"]
    assert await exchange(port, b"P -175 0\n", 1) == ["RPRT 0\n"]
    assert manager.view(6).target == 185
    await recorder.wait_for(lambda v: v.id == 6 and v.heading == 185 and not v.moving)
    assert await exchange(port, b"p\n", 2) == ["-175.00\n", "0.00\n"]
    assert await exchange(port, b"+S\n", 2) == ["stop:\n", "RPRT 0\n"]


@pytest.mark.asyncio
async def test_bad_input_gets_rotctlds_answers_and_a_log_line(
    served: tuple[RotatorManager, int, Recorder], caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, "moas_gui")
    manager, port, _ = served
    assert await exchange(port, b"P abc 10\n", 1) == ["RPRT -1\n"]
    assert await exchange(port, b"Z\nV SPEED 2\n", 1) == ["RPRT -4\n"]  # Z: no answer at all
    assert "sent 'Z', which is not a rotctld command" in caplog.text
    assert "rotctld listener for rotator 6 (Stack)" in caplog.text
    assert "set_pos with 'abc 10': not two numbers" in caplog.text
    assert manager.view(6).online


@pytest.mark.asyncio
async def test_an_offline_rotator_answers_get_pos_and_turns_with_errors(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, _, _ = served
    port = manager.rotator(7).rotctld_port
    assert port is not None
    # -6, I/O error: the server cannot reach the rotator (not -5, nothing timed out)
    assert await exchange(port, b"p\n", 1) == ["RPRT -6\n"]
    assert await exchange(port, b"+P 10 0\n", 2) == ["set_pos: 10 0\n", "RPRT -6\n"]
    assert await exchange(port, b"M 16 50\n", 1) == ["RPRT -6\n"]


@pytest.mark.asyncio
async def test_park_turns_to_the_park_heading_or_says_it_cannot(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, "moas_gui")
    parking, plain = free_port(), free_port()
    recorder = Recorder(FakeClock())
    manager = RotatorManager(
        [listened_rotator(parking, park_heading=200),
         listened_rotator(plain, id=8, short_name="Plain")],
        on_change=recorder, timing=replace(FAST, clock=recorder.clock))
    await manager.start()
    listeners = await start_rotctld_servers(manager, manager_rotators(manager), "127.0.0.1")
    try:
        assert await exchange(parking, b"+K\n", 2) == ["park:\n", "RPRT 0\n"]
        assert manager.view(6).target == 200
        await recorder.wait_for(lambda v: v.id == 6 and v.heading == 200 and not v.moving)
        # Without a ParkHeading: -11, feature not available, and dump_caps says so.
        assert await exchange(plain, b"K\n", 1) == ["RPRT -11\n"]
        assert "has no ParkHeading" in caplog.text
        caps = await caps_of(plain)
        assert "Can Park:\t\tN\n" in caps and "Can Move:\t\tY\n" in caps
        assert "Can Park:\t\tY\n" in await caps_of(parking)
    finally:
        await close_all(listeners)
        await manager.close()


async def caps_of(port: int) -> str:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        writer.write(b"1\n")
        lines = []
        async with asyncio.timeout(2.0):
            while not lines or not lines[-1].startswith("RPRT"):
                lines.append((await reader.readline()).decode())
        assert lines[-1] == "RPRT 0\n"
        assert all(len(line) < 64 for line in lines)
        return "".join(lines)
    finally:
        writer.close()
        await writer.wait_closed()


@pytest.mark.asyncio
async def test_move_turns_that_way_never_through_the_stop_and_reset_stops(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, port, recorder = served  # stop at south, at the stop (heading 180) now
    assert await exchange(port, b"M 8 50\n", 1) == ["RPRT 0\n"]  # CCW: at the stop already
    assert not manager.view(6).moving
    assert await exchange(port, b"M 16 50\n", 1) == ["RPRT 0\n"]  # clockwise: west first
    assert manager.view(6).target == 359
    await recorder.wait_for(lambda v: v.id == 6 and v.heading is not None and v.heading > 181)
    assert await exchange(port, b"+\\reset 1\n", 2) == ["reset: 1\n", "RPRT 0\n"]
    assert not manager.view(6).moving
    assert await exchange(port, b"M CCW 5\n", 1) == ["RPRT 0\n"]  # names as rotctld takes them
    assert manager.view(6).target == 180
    assert await exchange(port, b"M 2 50\n", 1) == ["RPRT -11\n"]  # up: no elevation
    assert await exchange(port, b"M sideways 50\n", 1) == ["RPRT -1\n"]


@pytest.mark.asyncio
async def test_a_port_in_use_is_logged_and_the_rest_carries_on(
    caplog: pytest.LogCaptureFixture,
) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        manager = RotatorManager([listened_rotator(port)], timing=FAST)
        await manager.start()
        listeners = await start_rotctld_servers(manager, manager_rotators(manager), "127.0.0.1")
        try:
            assert listeners == []
            assert f"on 127.0.0.1:{port}: cannot listen" in caplog.text
            await manager.rotate(6, 181)
        finally:
            await manager.close()


# ---- the real rotctl ---------------------------------------------------------------------

async def rotctl(port: int, *commands: str) -> tuple[int, str]:
    assert ROTCTL is not None, "rotctl is missing: apt-get install libhamlib-utils"
    process = await asyncio.create_subprocess_exec(
        ROTCTL, "-m", "2", "-r", f"127.0.0.1:{port}", *commands,
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.STDOUT,
    )
    async with asyncio.timeout(20):
        out, _ = await process.communicate()
    assert process.returncode is not None
    return process.returncode, out.decode()


@pytest.mark.realtime  # the real rotctl
@pytest.mark.asyncio
async def test_real_rotctl_reads_turns_and_stops_the_rotator(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, port, recorder = served
    code, out = await rotctl(port, "p", "_")
    assert code == 0
    assert out.split("\n")[:3] == ["-180.00", "0.00", "MOAS Stack"]
    code, out = await rotctl(port, "P", "-176", "0")
    assert code == 0, out
    assert manager.view(6).target == 184
    await recorder.wait_for(lambda v: v.id == 6 and v.heading == 184 and not v.moving)
    code, out = await rotctl(port, "P", "270", "0", "S", "p")
    assert code == 0, out
    assert out.split("\n")[:2] == ["-176.00", "0.00"]  # stopped at once, where it was
    assert not manager.view(6).moving


@pytest.mark.realtime  # the real rotctl
@pytest.mark.asyncio
async def test_real_rotctl_may_send_plain_compass_bearings_to_a_south_stop_rotator(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, port, _ = served
    code, out = await rotctl(port, "P", "350", "0")
    assert code == 0, out
    assert manager.view(6).target == 350


@pytest.mark.realtime  # the real rotctl
@pytest.mark.asyncio
async def test_real_rotctl_sees_the_errors_of_an_offline_rotator(
    served: tuple[RotatorManager, int, Recorder],
) -> None:
    manager, _, _ = served
    port = manager.rotator(7).rotctld_port
    assert port is not None
    code, out = await rotctl(port, "p")
    assert code != 0 and "io error" in out.lower() and "timed out" not in out.lower(), out


@pytest.mark.realtime  # the real rotctl
@pytest.mark.asyncio
async def test_real_rotctl_parks_moves_and_resets(
    caplog: pytest.LogCaptureFixture,
) -> None:
    port = free_port()
    recorder = Recorder()
    manager = RotatorManager([listened_rotator(port, park_heading=190)], on_change=recorder,
                             timing=FAST)
    await manager.start()
    listeners = await start_rotctld_servers(manager, manager_rotators(manager), "127.0.0.1")
    try:
        code, out = await rotctl(port, "1")
        assert "Can Park:\t\tY" in out  # the client's own capabilities: it forwards K, M, R
        code, out = await rotctl(port, "K")
        assert code == 0, out
        assert manager.view(6).target == 190
        code, out = await rotctl(port, "M", "16", "20", "R", "1")
        assert code == 0, out
        assert manager.view(6).target is None and not manager.view(6).moving
    finally:
        await close_all(listeners)
        await manager.close()


# ---- park heading and move targets -------------------------------------------------------

def test_park_heading_is_read_from_the_configuration_and_checked() -> None:
    from config_support import text_of

    from moas_gui.config import parse_config

    rotator = {"ID": 0, "ShortName": "Tower", "Control": "Test", "RotctldPort": 4535}
    loaded = parse_config(text_of(Rotators=[{**rotator, "ParkHeading": 270}]), "t.moas")
    assert loaded.config is not None
    assert loaded.config.rotators[0].park_heading == 270
    refused = parse_config(text_of(Rotators=[{**rotator, "ParkHeading": 360}]), "t.moas")
    assert refused.config is None
    assert any("ParkHeading" in p.message for p in refused.errors)


def test_a_move_turns_up_to_179_degrees_never_past_the_end() -> None:
    south_stop = Travel(ccw_limit=180, rotation=360, has_stop=True)
    assert move_target(south_stop, 180, 0.0, clockwise=True) == 359
    assert move_target(south_stop, 170, 350.0, clockwise=True) == 180  # to the stop
    assert move_target(south_stop, 190, 10.0, clockwise=False) == 180
    free = Travel()
    assert move_target(free, 10, None, clockwise=False) == 191
    overlap = Travel(ccw_limit=0, rotation=450, has_stop=True)
    assert move_target(overlap, 30, 390.0, clockwise=False) == 211
    assert move_target(overlap, 30, 30.0, clockwise=True) == 209
    # Position unknown in the overlap: aim at the end of travel, reached turning that way
    # from either reading (30 or 390).
    assert move_target(overlap, 30, None, clockwise=True) == 90
    assert move_target(overlap, 200, None, clockwise=True) == 19  # 200 has one position


@given(st.floats(0, 450), st.booleans())
def test_a_move_never_goes_the_other_way(position: float, clockwise: bool) -> None:
    overlap = Travel(ccw_limit=20, rotation=450, has_stop=True)
    heading = overlap.heading_at(position)
    for known in (position, None):
        target = move_target(overlap, heading, known, clockwise)
        end = overlap.nearest_position(target, near=position)
        moved = end - position
        assert moved >= -1e-6 if clockwise else moved <= 1e-6
        assert abs(moved) <= 180 + 1e-6 or known is None
