"""The client tests' stand-in server (tests/client_support.py) comes back on its own port."""

from __future__ import annotations

import asyncio
from typing import Any

from client_support import LOOPBACK, LiveServer, run_on_qt


def test_live_server_restarts_on_the_same_port(qapp: Any) -> None:
    async def scenario() -> tuple[int, int]:
        live = LiveServer()
        await live.start()
        first = live.port
        await live.stop()
        await live.start()
        second = live.port
        reader, writer = await asyncio.open_connection(LOOPBACK, second)
        writer.write(b'{"id": 1, "cmd": "state"}\n')
        line = await reader.readline()
        writer.close()
        await live.stop()
        assert b'"ok":true' in line.replace(b" ", b"")
        return first, second

    first, second = run_on_qt(qapp, scenario())
    assert first == second != 0
