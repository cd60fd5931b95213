"""The emulator's control socket under the project's one admission policy: a cap on
connections, refused ones told why in the control's own words; once the crowd has gone
a connection that sends commands is served."""

from __future__ import annotations

import asyncio
import contextlib

import pytest

from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.control import CONTROL_CONNECTIONS, Control, serve_control


@pytest.mark.asyncio
async def test_a_crowd_of_silent_control_connections_is_capped() -> None:
    box = EmulatedBox(loop=asyncio.get_running_loop())
    server, where = await serve_control(Control(box), "0")
    host, port = where.rsplit(":", 1)
    held: list[asyncio.StreamWriter] = []
    try:
        for _ in range(CONTROL_CONNECTIONS):
            held.append((await asyncio.open_connection(host, int(port)))[1])
        await asyncio.sleep(0)
        reader, writer = await asyncio.open_connection(host, int(port))
        async with asyncio.timeout(5):
            refused = await reader.read()
        assert (
            refused.startswith(b"error ") and b"connections from that address are open" in refused
        )
        writer.close()
        for silent in held:  # the silent ones go; a talking one is served
            silent.close()
        await asyncio.sleep(0.1)
        reader, writer = await asyncio.open_connection(host, int(port))
        writer.write(b"relays\n")
        async with asyncio.timeout(5):
            assert (await reader.readline()).startswith(b"relays ")
        writer.close()
        await writer.wait_closed()
        async with asyncio.timeout(5):
            while server.admission.count:
                await asyncio.sleep(0.01)
    finally:
        for writer in held:
            with contextlib.suppress(Exception):
                writer.close()
        await server.close()
        box.close()
