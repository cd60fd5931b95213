"""What the switch links say, as the server handles it (moas_gui/switch_events.py): a
switch that stops answering is one alert for the window, a ``switch`` event for the
clients and the status; its return is no alert; a closing link's late events change
nothing.  The small example station on the built-in switch emulator, a real client over
TCP."""

from __future__ import annotations

import pytest
from helpers import until
from test_server_protocol import Peer, app, greeted, peers, run_example  # noqa: F401

from moas_gui.app import ServerApp
from moas_gui.hw.moas2.link import LinkStatus


@pytest.mark.asyncio
async def test_a_switch_that_stops_answering_is_one_alert_and_its_return_none(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    alerts: list[tuple[str, str]] = []
    app.add_alert_listener(lambda title, text: alerts.append((title, text)))
    peer = await greeted(app, peers)
    mark = peer.mark()
    box = app.emulators()[1]
    box.attach(None)  # the box hears but its answers are lost, as with a cut receive line
    await peer.event("switch", mark, where=lambda m: m["status"] == "unresponsive")
    await until(lambda: dict(app.status.switches).get(1) == "unresponsive",
                what="the status saying so")
    assert alerts == [("MOAS switch lost", "Switch 1 stopped responding.")]
    mark = peer.mark()
    # the link connects again (a new session, which attaches the box's output again)
    await peer.event("switch", mark, where=lambda m: m["status"] == "ok", timeout=15)
    assert alerts == [("MOAS switch lost", "Switch 1 stopped responding.")]


@pytest.mark.asyncio
async def test_a_closing_links_late_events_change_nothing(app: ServerApp) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    alerts: list[tuple[str, str]] = []
    app.add_alert_listener(lambda title, text: alerts.append((title, text)))
    engine, events = app.engine, app.switch_events
    assert engine is not None
    await app.close()
    # what a link being closed may still say: none of it reaches an engine or the window
    events.status(1, LinkStatus.UNRESPONSIVE)
    events.transmitting(1, 1, True)  # the door would refuse (no configuration): not asked
    events.adopt(1, {1: (2, 2, 0)})
    events.seen(1, 1, (2, 2, 0))
    assert alerts == [] and not engine.radio_view(1, 1).transmitting
