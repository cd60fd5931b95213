"""Once a configuration opens, the server freezes what is alive out of the cyclic
collector's later full collections (``ServerOptions.settle_garbage``, which
``moas-server`` sets), and a configuration opened again frees the one before."""

from __future__ import annotations

import gc
import weakref
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.cli import server as program
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.status import ServerState

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def options(settle: bool) -> ServerOptions:
    return ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0, udp_bind="127.0.0.1",
                         start_rotator_program=False, switch_timing=FAST,
                         settle_garbage=settle)


@pytest_asyncio.fixture
async def settling() -> AsyncIterator[ServerApp]:
    server = ServerApp(options(True))
    yield server
    await server.close()


def collected_by_the_cyclic_collector(thing: object) -> bool:
    """Whether ``thing`` is in a generation the collector scans (not frozen)."""
    return any(found is thing for found in gc.get_objects())


@pytest.mark.asyncio
async def test_what_a_configuration_opened_is_frozen_out_of_full_collections(
        settling: ServerApp) -> None:
    assert (await settling.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: settling.status.state is ServerState.NORMAL)
    run = settling._run
    assert run is not None
    assert not collected_by_the_cyclic_collector(run)
    assert not collected_by_the_cyclic_collector(run.engine)


@pytest.mark.asyncio
async def test_without_the_option_nothing_is_frozen() -> None:
    server = ServerApp(options(False))
    try:
        assert (await server.open(EXAMPLES / "small-station.moas")).ok
        assert server._run is not None
        assert collected_by_the_cyclic_collector(server._run)
    finally:
        await server.close()


@pytest.mark.asyncio
async def test_a_configuration_opened_again_frees_the_one_before(settling: ServerApp) -> None:
    assert (await settling.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: settling.status.state is ServerState.NORMAL)
    before = weakref.ref(settling._run)  # type: ignore[arg-type]
    assert (await settling.open(EXAMPLES / "small-station.moas")).ok
    await until(lambda: settling.status.state is ServerState.NORMAL)
    gc.collect()
    assert before() is None, "the closed configuration is kept by the freeze"


def test_the_server_program_settles_its_garbage() -> None:
    args = program._parser().parse_args([str(EXAMPLES / "small-station.moas"), "--headless"])
    assert program._options(args).settle_garbage
