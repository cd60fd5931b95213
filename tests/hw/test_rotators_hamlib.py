"""Hamlib rotators: against the real rotctld (Debian's libhamlib-utils), on the real
clock, and a scripted stand-in for the answers a real daemon cannot be made to give,
on a fake clock (its timeouts and reconnections pass at once)."""

from __future__ import annotations

import asyncio
import contextlib
import logging
import shutil
from collections.abc import AsyncIterator, Callable
from dataclasses import replace

import pytest
import pytest_asyncio
from helpers import FakeClock, advance_until, free_port
from test_rotators_manager import Recorder

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorError, RotatorManager, Timing
from moas_gui.hw.rotators.hamlib import HamlibRotator
from moas_gui.hw.rotators.hamlib_codec import Limits, ReplyAssembler, error_text, limits_of

FAST = Timing(reconnect_min=0.05, reconnect_max=0.2, reply_timeout=0.4, connect_timeout=0.5,
              stall_min=2.0)
ROTCTLD = shutil.which("rotctld")


async def wait_listening(port: int, timeout: float = 5.0) -> None:
    async with asyncio.timeout(timeout):
        while True:
            try:
                _, writer = await asyncio.open_connection("127.0.0.1", port)
            except OSError:
                await asyncio.sleep(0.02)
                continue
            writer.close()
            await writer.wait_closed()
            return


class Rotctld:
    """The real daemon with its Dummy rotator (model 1), on loopback."""

    def __init__(self) -> None:
        self.port = free_port()
        self.process: asyncio.subprocess.Process | None = None

    async def start(self) -> None:
        assert ROTCTLD is not None, "rotctld is missing: apt-get install libhamlib-utils"
        self.process = await asyncio.create_subprocess_exec(
            ROTCTLD, "-m", "1", "-T", "127.0.0.1", "-t", str(self.port),
            stdout=asyncio.subprocess.DEVNULL, stderr=asyncio.subprocess.DEVNULL,
        )
        await wait_listening(self.port)

    async def stop(self) -> None:
        process, self.process = self.process, None
        if process is not None and process.returncode is None:
            process.kill()
            await process.wait()


@pytest_asyncio.fixture
async def rotctld() -> AsyncIterator[Rotctld]:
    daemon = Rotctld()
    await daemon.start()
    yield daemon
    await daemon.stop()


def hamlib_rotator(port: int, **fields: object) -> Rotator:
    base: dict[str, object] = {"id": 4, "short_name": "Dummy", "control": RotatorControl.HAMLIB,
                               "address": f"127.0.0.1:{port}", "poll": 100}
    base.update(fields)
    return Rotator(**base)  # type: ignore[arg-type]


async def running(rotator: Rotator, recorder: Recorder) -> RotatorManager:
    """A manager on the recorder's clock (the fake one, or the real one)."""
    timing = replace(FAST, clock=recorder.clock) if recorder.fake else FAST
    manager = RotatorManager([rotator], on_change=recorder, timing=timing)
    await manager.start()
    return manager


# ---- the real rotctld ---------------------------------------------------------------------

@pytest.mark.realtime
@pytest.mark.asyncio
async def test_reads_and_turns_the_real_rotctld(rotctld: Rotctld) -> None:
    recorder = Recorder()
    manager = await running(hamlib_rotator(rotctld.port), recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 0)
        driver = manager.drivers[4]
        assert isinstance(driver, HamlibRotator)
        assert driver.limits == Limits(-180.0, 450.0)
        await manager.rotate(4, 4)
        assert manager.view(4).target == 4 and manager.view(4).moving
        done = await recorder.wait_for(lambda v: v.heading == 4 and not v.moving)
        assert done.target is None
    finally:
        await manager.close()


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_a_rotator_without_a_stop_turns_the_real_dummy_the_short_way(
    rotctld: Rotctld,
) -> None:
    recorder = Recorder()
    manager = await running(hamlib_rotator(rotctld.port), recorder)  # 360 degrees, no stop
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 0)
        await manager.rotate(4, 300)  # 60 degrees counterclockwise, not 300 clockwise
        assert manager.view(4).target == 300
        seen = len(recorder.views)
        await recorder.wait_for(
            lambda v: v.heading is not None and 300 < v.heading < 359, since=seen)
        assert all(v.heading is not None and (v.heading == 0 or v.heading > 300)
                   for v in recorder.views[seen:])
    finally:
        await manager.close()


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_stop_halts_the_real_rotctld(rotctld: Rotctld) -> None:
    recorder = Recorder()
    manager = await running(hamlib_rotator(rotctld.port), recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await manager.rotate(4, 90)
        await recorder.wait_for(lambda v: v.heading is not None and v.heading >= 1)
        await manager.stop(4)
        assert not manager.view(4).moving and manager.view(4).target is None
        await asyncio.sleep(0.3)
        first = manager.view(4).heading
        await asyncio.sleep(0.4)
        assert manager.view(4).heading == first and first is not None and first < 10
    finally:
        await manager.close()


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_rotctld_going_away_shows_offline_and_it_reconnects(
    rotctld: Rotctld, caplog: pytest.LogCaptureFixture
) -> None:
    recorder = Recorder()
    manager = await running(hamlib_rotator(rotctld.port), recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        await rotctld.stop()
        await recorder.wait_for(lambda v: not v.online)
        with pytest.raises(RotatorError) as caught:
            await manager.rotate(4, 10)
        assert caught.value.code == "unavailable"
        assert "rotator 4 (Dummy)" in caplog.text
        seen = len(recorder.views)
        await rotctld.start()
        await recorder.wait_for(lambda v: v.online, since=seen)
    finally:
        await manager.close()


# ---- a scripted daemon for the answers the real one will not give -----------------------------

Script = Callable[[str], bytes | None]


class ScriptedRotctld:
    """Answers each command line with ``script(line)``; ``None`` means silence."""

    def __init__(self, script: Script) -> None:
        self.script = script
        self.lines: list[str] = []
        self._server: asyncio.Server | None = None
        self.port = 0

    async def start(self) -> None:
        self._server = await asyncio.start_server(self._serve, "127.0.0.1", 0)
        self.port = self._server.sockets[0].getsockname()[1]

    async def close(self) -> None:
        assert self._server is not None
        self._server.close()
        await self._server.wait_closed()

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        with contextlib.suppress(ConnectionError):
            while line := await reader.readline():
                text = line.decode().strip()
                self.lines.append(text)
                answer = self.script(text)
                if answer is not None:
                    writer.write(answer)
        writer.close()


SOUTH_STOP_DUMP = (b"dump_state:\nrotctld Protocol Ver: 1\nRotor Model: 603\n"
                   b"Minimum Azimuth: -180.000000\nMaximum Azimuth: 180.000000\n"
                   b"Minimum Elevation: 0.000000\nMaximum Elevation: 90.000000\nSouth Zero: 0\n"
                   b"rot_type=Az\ndone\nRPRT 0\n")


def south_stop_daemon(azimuth: str = "-90.00", set_code: int = 0) -> Script:
    def script(line: str) -> bytes | None:
        if line == "+\\dump_state":
            return SOUTH_STOP_DUMP
        if line == "+p":
            return f"get_pos:\nAzimuth: {azimuth}\nElevation: 0.00\nRPRT 0\n".encode()
        if line.startswith("+P"):
            return f"set_pos: {line[3:]}\nRPRT {set_code}\n".encode()
        if line == "+S":
            return b"stop:\nRPRT 0\n"
        return None
    return script


@pytest_asyncio.fixture
async def scripted() -> AsyncIterator[Callable[[Script], ScriptedRotctld]]:
    servers: list[ScriptedRotctld] = []

    def make(script: Script) -> ScriptedRotctld:
        server = ScriptedRotctld(script)
        servers.append(server)
        return server

    yield make
    for server in servers:
        await server.close()


@pytest.mark.asyncio
async def test_positions_follow_the_daemons_south_stop_scale(
    scripted: Callable[[Script], ScriptedRotctld],
) -> None:
    daemon = scripted(south_stop_daemon("-90.00"))
    await daemon.start()
    recorder = Recorder(FakeClock())
    manager = await running(
        hamlib_rotator(daemon.port, ccw_limit=180, rotation=360, has_stop=True), recorder
    )
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 270)
        await manager.rotate(4, 90)
        await manager.rotate(4, 200)
        sets = [line for line in daemon.lines if line.startswith("+P")]
        assert sets == ["+P 90.00 0.00", "+P -160.00 0.00"]
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_refused_turn_is_unavailable_with_hamlibs_reason(
    scripted: Callable[[Script], ScriptedRotctld],
) -> None:
    daemon = scripted(south_stop_daemon(set_code=-1))
    await daemon.start()
    recorder = Recorder(FakeClock())
    manager = await running(hamlib_rotator(daemon.port), recorder)
    try:
        await recorder.wait_for(lambda v: v.online)
        with pytest.raises(RotatorError, match=r"RPRT -1 \(invalid parameter\)") as caught:
            await manager.rotate(4, 10)
        assert caught.value.code == "unavailable"
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_malformed_position_is_logged_naming_the_rotator_and_polling_carries_on(
    scripted: Callable[[Script], ScriptedRotctld], caplog: pytest.LogCaptureFixture
) -> None:
    answers = iter(["banana", "-90.00"])
    current = {"azimuth": next(answers)}

    def script(line: str) -> bytes | None:
        if line == "+p":
            reply = f"get_pos:\nAzimuth: {current['azimuth']}\nElevation: 0\nRPRT 0\n"
            current["azimuth"] = next(answers, "-90.00")
            return reply.encode()
        return south_stop_daemon()(line)

    daemon = scripted(script)
    await daemon.start()
    recorder = Recorder(FakeClock())
    manager = await running(hamlib_rotator(daemon.port, short_name="Stack"), recorder)
    try:
        await recorder.wait_for(lambda v: v.heading == 270)
        assert "rotator 4 (Stack): rotctld at 127.0.0.1" in caplog.text
        assert "without a usable Azimuth" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_silent_daemon_is_dropped_after_the_reply_timeout(
    scripted: Callable[[Script], ScriptedRotctld], caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, "moas_gui.hw.rotators")
    daemon = scripted(lambda line: None)
    await daemon.start()
    recorder = Recorder(FakeClock())
    manager = await running(hamlib_rotator(daemon.port), recorder)
    try:
        await advance_until(recorder.clock, lambda: "did not answer" in caplog.text, limit=0.6)
        assert "did not answer within 0.4 s; reconnecting" in caplog.text
        assert not manager.view(4).online
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_daemon_that_never_finishes_dump_state_is_used_without_its_limits(
    scripted: Callable[[Script], ScriptedRotctld], caplog: pytest.LogCaptureFixture
) -> None:
    def script(line: str) -> bytes | None:
        if line == "+\\dump_state":
            return b"dump_state:\n0\n1\n"  # an old daemon: no RPRT line
        return south_stop_daemon()(line)

    daemon = scripted(script)
    await daemon.start()
    recorder = Recorder(FakeClock())
    manager = await running(hamlib_rotator(daemon.port), recorder)
    try:
        await recorder.wait_for(lambda v: v.online and v.heading == 270)
        assert "gave no complete answer to dump_state" in caplog.text
        assert daemon.lines.count("+\\dump_state") == 1
    finally:
        await manager.close()


# ---- the codec ---------------------------------------------------------------------------

def test_extended_replies_are_framed_by_their_rprt_line() -> None:
    assembler = ReplyAssembler()
    replies = [assembler.add(line) for line in SOUTH_STOP_DUMP.decode().splitlines()]
    assert replies[:-1] == [None] * (len(replies) - 1)
    reply = replies[-1]
    assert reply is not None and reply.header == "dump_state" and reply.code == 0
    assert limits_of(reply) == Limits(-180.0, 180.0)
    assert reply.value("rot_type") == "Az"


def test_a_protocol_0_dump_state_has_no_limits_we_can_trust() -> None:
    assembler = ReplyAssembler()
    for line in ["dump_state:", "0", "2"]:
        assert assembler.add(line) is None
    reply = assembler.add("RPRT 0")
    assert reply is not None and limits_of(reply) is None


def test_error_text_names_the_hamlib_error() -> None:
    assert error_text(-5) == "RPRT -5 (communication timed out)"
    assert error_text(-99) == "RPRT -99 (unknown error)"
