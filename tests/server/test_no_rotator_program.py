"""``--no-rotator-program`` means no MOAS Rotator program at all: none is started, none
is connected to (a real listener on its port is never knocked on), and the rotators
that go through one are offline, a request saying why; one log line says so."""

from __future__ import annotations

import asyncio
import logging
from pathlib import Path

import pytest

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.hw.rotators.base import Timing

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


@pytest.mark.asyncio
async def test_no_rotator_program_is_started_or_asked(caplog: pytest.LogCaptureFixture) -> None:
    knocks: list[str] = []

    async def answer(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        knocks.append("a connection")
        writer.close()

    program = await asyncio.start_server(answer, "127.0.0.1", 0)
    port = program.sockets[0].getsockname()[1]
    quick = Timing(reconnect_min=0.01, reconnect_max=0.01)
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", use_rotator_program=False,
                                  rotator_program_port=port, switch_timing=FAST,
                                  rotator_timing=quick))
    caplog.set_level(logging.DEBUG, logger="moas_gui")
    try:
        assert (await app.open(EXAMPLES / "big-station.moas")).ok
        manager = app.rotator_manager
        assert manager is not None
        views = {v.id: v for v in manager.views()}
        serial = [r.id for r in app.config.rotators if r.control.value == "Serial"]  # type: ignore[union-attr]
        assert serial and all(not views[i].online for i in serial)
        await asyncio.sleep(0.3)  # many reconnect pauses of a link, were there one
        assert knocks == [], "the MOAS Rotator program's port was knocked on"
        with pytest.raises(Exception, match="--no-rotator-program leaves out"):
            manager.start_rotate(serial[0], 90.0)
        said = [r.getMessage() for r in caplog.records]
        assert sum("No MOAS Rotator program" in line for line in said) == 1
        assert not any("cannot connect" in line or "MOAS Rotator at" in line for line in said)
    finally:
        await app.close()
        program.close()
        await program.wait_closed()
