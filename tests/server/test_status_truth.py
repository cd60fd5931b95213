"""The title, status bar and tray say a configuration runs only once its ports listen:
a switch that answers while the rest still starts does not make the status "running"."""

from __future__ import annotations

import asyncio
import socket
from typing import Any

import pytest
from helpers import EXAMPLES, until

from moas_gui import app as app_module
from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.status import ServerState, ServerStatus

FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def _listens(address: tuple[str, int] | None) -> bool:
    if address is None:
        return False
    try:
        socket.create_connection(address, timeout=1).close()
    except OSError:
        return False
    return True


@pytest.mark.asyncio
async def test_running_is_shown_only_once_the_client_port_listens(
        monkeypatch: pytest.MonkeyPatch) -> None:
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     switch_timing=FAST))
    seen: list[tuple[ServerStatus, bool]] = []
    server.add_status_listener(lambda status: seen.append((status, _listens(
        server.client_address))))
    original = app_module.start_clients

    async def clients_after_the_switch_answers(run: Any, *args: Any) -> None:
        # the switch link reports "ok" while the client port is not yet open
        await until(lambda: set(run.switch_status.values()) == {"ok"}, what="the switch ok")
        await asyncio.sleep(0.3)
        await original(run, *args)

    monkeypatch.setattr(app_module, "start_clients", clients_after_the_switch_answers)
    try:
        assert (await server.open(EXAMPLES / "small-station.moas")).ok
        await until(lambda: server.status.state is ServerState.NORMAL)
    finally:
        await server.close()
    running = [listening for status, listening in seen if status.state is ServerState.NORMAL]
    assert running, seen
    assert all(running), [(s.state, listening) for s, listening in seen]
