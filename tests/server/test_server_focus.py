"""Transmit and receive focus in the real server: the ``active`` and ``focus`` commands over
TCP on 127.0.0.1, the ``active``/``focus`` fields of radio entries, and the rule that a
station's active radio is decided first when both radios report together (docs/engine.md)."""

from __future__ import annotations

import asyncio
import socket

import pytest
from helpers import until
from test_server_protocol import Peer, app, greeted, peers, run_example  # noqa: F401

from moas_gui.app import ServerApp
from moas_gui.sources.base import ActiveRadio, FocusRadio, FrequencyReport
from moas_gui.sources.n1mm_packet import radio_info_packet


@pytest.mark.asyncio
async def test_active_and_focus_reach_every_client_in_the_radio_entries(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    state = peer.events("state")[-1]
    assert all(r["active"] is False and r["focus"] is False for r in state["radios"])
    mark = peer.mark()
    assert await peer.ok("active", station=1, radio=2) == {}
    event = await peer.event("radio", mark, where=lambda m: m["radio"] == 2)
    assert (event["active"], event["focus"]) == (True, False)
    mark = peer.mark()
    await peer.ok("active", station=1, radio=1)
    await peer.event("radio", mark, where=lambda m: m["radio"] == 2 and not m["active"])
    await peer.event("radio", mark, where=lambda m: m["radio"] == 1 and m["active"])
    await peer.ok("focus", station=1, radio=2)
    snapshot = await peer.ok("state")
    entries = {r["radio"]: (r["active"], r["focus"]) for r in snapshot["radios"]}
    assert entries == {1: (True, False), 2: (False, True)}


@pytest.mark.asyncio
async def test_focus_for_a_radio_that_does_not_exist_is_not_found(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    code, _ = await peer.refused("active", station=1, radio=7)
    assert code == "not_found"
    code, message = await peer.refused("focus", station=1)
    assert code == "bad_request" and "radio" in message


@pytest.mark.asyncio
async def test_the_active_radio_gets_the_only_antenna_when_both_report_together(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    # small-station: on 160 m only antenna 3 serves either radio
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    await peer.ok("frequency", station=1, radio=1, khz=7025)
    await peer.ok("frequency", station=1, radio=2, khz=3525)
    assert app.sources is not None
    hub = app.sources.hub  # where every source's events go, on their way to the intake
    for active, other in ((2, 1), (1, 2)):
        hub(ActiveRadio(1, active, "test logger"))
        hub(FocusRadio(1, other, "test logger"))
        for radio, khz in ((other, 7025.0), (active, 3525.0)):  # apart again
            hub(FrequencyReport(1, radio, khz, khz, "test logger"))
        await asyncio.sleep(0.05)
        # both radios of the SO2R station to 160 m in one packet burst, the other radio's first
        for radio in (other, active):
            hub(FrequencyReport(1, radio, 1830.0, 1830.0, "test logger"))

        await until(lambda r=active: app.engine.radio_view(1, r).tx == 3,  # type: ignore[union-attr,misc]
                    what=f"antenna 3 on the active radio {active}")
        assert app.engine.radio_view(1, other).tx != 3  # type: ignore[union-attr]


@pytest.mark.asyncio
async def test_an_n1mm_packet_gives_one_radio_event_with_frequency_and_focus(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    peer = await greeted(app, peers)
    sources = app.sources
    assert sources is not None and sources.n1mm is not None
    mark = peer.mark()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.sendto(radio_info_packet(2, 7025.0, active_radio_nr=2, focus_radio_nr=2),
                      ("127.0.0.1", sources.n1mm.port))
    event = await peer.event("radio", mark)
    assert (event["radio"], event["khz"], event["active"], event["focus"]) == (2, 7025.0,
                                                                                True, True)
    await asyncio.sleep(0.1)
    assert len(peer.events("radio", mark)) == 1
