"""The two halves together: the server's manager starts the real ``moas-rotator``
program (``python -m moas_gui.cli.rotator``), which drives an emulated
controller on a pseudo-terminal.  A check that both ends read appendix B alike."""

from __future__ import annotations

import asyncio
import sys
from collections.abc import AsyncIterator

import pytest
import pytest_asyncio
from helpers import free_port
from test_rotators_manager import Recorder

from moas_gui.config.model import Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorManager, Timing

pytestmark = pytest.mark.realtime


@pytest_asyncio.fixture
async def yaesu_pty() -> AsyncIterator[str]:
    """An emulated GS-232B at azimuth 340 turning 120 degrees a second (a real one: about
    6); yields its pty path."""
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.rotator", "--emulate", "Yaesu", "--speed", "120",
        "--azimuth", "340",
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.DEVNULL,
    )
    assert process.stdout is not None
    try:
        async with asyncio.timeout(10):
            path = (await process.stdout.readline()).decode().strip()
        assert path.startswith("/dev/"), path
        yield path
    finally:
        process.terminate()
        await process.wait()


@pytest.mark.asyncio
async def test_manager_starts_moas_rotator_and_turns_an_emulated_yaesu_into_the_overlap(
    yaesu_pty: str,
) -> None:
    port = free_port()
    command = [sys.executable, "-m", "moas_gui.cli.rotator", "--bind", "127.0.0.1",
               "--port", str(port)]
    rotator = Rotator(id=1, short_name="Stack", control=RotatorControl.SERIAL, model="Yaesu",
                      comm_port=yaesu_pty, poll=200, ccw_limit=0, rotation=450, has_stop=True)
    recorder = Recorder()
    manager = RotatorManager([rotator], on_change=recorder, moas_rotator_port=port,
                             moas_rotator_command=command,
                             timing=Timing(reconnect_min=0.05, reconnect_max=0.2))
    await manager.start()
    try:
        assert manager.local_program is not None and manager.local_program.process is not None
        await recorder.wait_for(lambda v: v.online and v.heading == 340, timeout=15)
        await manager.rotate(1, 20)  # clockwise past north into the overlap: position 380
        await recorder.wait_for(lambda v: v.heading == 20 and not v.moving, timeout=15)
        driver = manager.drivers[1]
        assert driver.tracker.position == pytest.approx(380, abs=2)  # type: ignore[attr-defined]
        process = manager.local_program.process
    finally:
        await manager.close()
    assert process.returncode is not None
