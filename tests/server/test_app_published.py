"""What the app's one door says it did: ``act`` and ``apply_changes`` return the radios
whose entries went to the clients, and the sources' intake of one configuration ends with
it (a batch still waiting when the configuration closes changes nothing)."""

from __future__ import annotations

import asyncio

import pytest
from test_server_protocol import Peer, app, greeted, peers, run_example  # noqa: F401

from moas_gui.app import ServerApp
from moas_gui.engine import NotRunning
from moas_gui.engine.operations import SetFrequency
from moas_gui.sources.base import FrequencyReport


@pytest.mark.asyncio
async def test_act_returns_the_radios_it_published_and_the_clients_get_them(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    mark = peer.mark()
    published = app.act(SetFrequency(1, 2, 7025.0, None))
    assert (1, 2) in published and all(station == 1 for station, _ in published)
    event = await peer.event("radio", mark, where=lambda m: m["radio"] == 2)
    assert event["khz"] == 7025.0


@pytest.mark.asyncio
async def test_without_a_configuration_the_door_is_shut_and_nothing_is_published(
        app: ServerApp) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    engine = app.engine
    assert engine is not None
    changes = engine.set_frequency(1, 1, 14025.0)
    await app.close()
    assert app.apply_changes(changes) == set()
    with pytest.raises(NotRunning):
        app.act(SetFrequency(1, 1, 14025.0, None))
    assert app.latest_reports() == {}


@pytest.mark.asyncio
async def test_a_batch_waiting_when_the_configuration_closes_is_dropped(
        app: ServerApp) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    engine = app.engine
    assert engine is not None and app.sources is not None
    hub = app.sources.hub  # where every source's events go, on their way to the intake
    hub(FrequencyReport(1, 1, 14025.0, 14025.0, "test logger"))
    await asyncio.sleep(0)  # the loop's next turn decides the batch
    assert engine.radio_view(1, 1).khz == 14025.0
    hub(FrequencyReport(1, 1, 7025.0, 7025.0, "test logger"))
    await app.close()  # before the loop's next turn
    await asyncio.sleep(0)
    assert engine.radio_view(1, 1).khz == 14025.0
