"""The status refresh (twice a second, a timer that arms itself again): the number of
clients shows in the status without any other change, and closing the configuration
ends the refresh."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from helpers import until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


@pytest.mark.asyncio
async def test_the_status_counts_a_client_and_the_refresh_ends_with_the_configuration() -> None:
    app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                  udp_bind="127.0.0.1", start_rotator_program=False,
                                  switch_timing=FAST))
    try:
        assert (await app.open(EXAMPLES / "small-station.moas")).ok
        await until(lambda: app.status.state is ServerState.NORMAL)
        run = app._run
        assert run is not None and app.status.clients == 0
        address = app.client_address
        assert address is not None
        _, writer = await asyncio.open_connection(*address)
        try:
            await until(lambda: app.status.clients == 1, timeout=10)
        finally:
            writer.close()
        await until(lambda: app.status.clients == 0, timeout=10)
        ticker = run.ticker
        assert ticker is not None and not ticker.cancelled()
        await app.close()
        assert run.ticker is not None and run.ticker.cancelled()
        assert app._run is None
    finally:
        await app.close()
