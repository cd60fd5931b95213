"""A band change passes through app.py once (issue 41): a logger's RadioInfo over real UDP,
its SO2R transmit focus moving to the other radio, into the running server (the small
example station on the built-in switch emulator), with a client connected and the antenna
log on, until the box reports the new antennas in use.  Every call into ``moas_gui/app.py``
or ``moas_gui/server_view.py`` from outside them is recorded meanwhile: the band change's
only one is ``ServerApp.act`` (the sources' intake calls the door; the clients' entries,
the switch's answer and the journal never climb back into the app)."""

from __future__ import annotations

import asyncio
import socket
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType

import pytest
from helpers import until
from test_server_protocol import Peer, app, greeted, peers, run_example  # noqa: F401

import moas_gui.app
import moas_gui.server_view
from moas_gui.app import ServerApp
from moas_gui.sources.n1mm_packet import radio_info_packet

APP_FILES = {Path(moas_gui.app.__file__).resolve(), Path(moas_gui.server_view.__file__).resolve()}
HERE = Path(__file__).resolve()
TICKER = "_tick"
"""The status refresh, resumed by the loop twice a second whatever else happens."""


@contextmanager
def entries_into_the_app() -> Iterator[list[str]]:
    """The names of the app's functions called from outside the app (this test's own
    reads aside) while the block runs, in order."""
    entered: list[str] = []
    known: dict[str, bool] = {}

    def inside(filename: str) -> bool:
        if filename not in known:
            known[filename] = Path(filename).resolve() in APP_FILES
        return known[filename]

    def profile(frame: FrameType, event: str, arg: object) -> None:
        if event != "call" or not inside(frame.f_code.co_filename):
            return
        caller = frame.f_back
        where = caller.f_code.co_filename if caller is not None else ""
        if not inside(where) and Path(where).resolve() != HERE:
            entered.append(frame.f_code.co_name)

    sys.setprofile(profile)
    try:
        yield entered
    finally:
        sys.setprofile(None)


def relays(server: ServerApp) -> frozenset[int]:
    return server.emulators()[1].view().relays


@pytest.mark.asyncio
async def test_a_loggers_band_change_enters_the_app_once_through_act(
        app: ServerApp, peers: list[Peer]) -> None:  # noqa: F811
    await run_example(app, "small-station.moas")
    assert app.antenna_journal is not None  # the journal is fed too
    peer = await greeted(app, peers)
    address = app.n1mm_address
    assert address is not None and app.engine is not None and app._run is not None
    link = app._run.links[1]
    logger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        logger.sendto(radio_info_packet(1, 14025.0), address)  # radio 1 transmits, on 20 m
        await until(lambda: app.engine.radio_view(1, 1).khz == 14025.0)  # type: ignore[union-attr]
        await until(lambda: link.seen is not None, what="the box's report")
        before, seen, mark = relays(app), link.seen, peer.mark()
        with entries_into_the_app() as entered:
            # radio 2 on 40 m, and the station's transmit focus moves to it
            logger.sendto(radio_info_packet(2, 7025.0, active_radio_nr=2), address)
            await peer.event("radio", mark, where=lambda m: m["radio"] == 2 and m["khz"] == 7025.0)
            await peer.event("radio", mark, where=lambda m: m["radio"] == 1 and not m["active"])
            await until(lambda: relays(app) != before, what="the box switched")
            await until(lambda: link.seen != seen, what="the box's report of it")
            await asyncio.sleep(0.05)  # whatever the report caused, done
    finally:
        logger.close()
    assert [name for name in entered if name != TICKER] == ["act"], entered


@pytest.mark.asyncio
async def test_a_loggers_band_change_is_decided_in_the_loop_turn_that_read_it(
        app: ServerApp) -> None:  # noqa: F811
    # issue 41: the sources' batch of a UDP burst is decided as the burst ends, inside the
    # callback that read the datagram, not in a later turn of the loop (each turn costs a
    # quiet server, and the first byte to the switch would wait for it)
    await run_example(app, "small-station.moas")
    address = app.n1mm_address
    assert address is not None and app._run is not None and app._run.sources is not None
    listener = app._run.sources.n1mm
    assert listener is not None
    engine = app.engine
    assert engine is not None
    read = listener.datagram_received
    when_read: list[float | None] = []

    def reading(data: bytes, addr: tuple[str | int, ...]) -> None:
        read(data, addr)
        when_read.append(engine.radio_view(1, 1).khz)  # as the callback ends

    listener.datagram_received = reading  # type: ignore[method-assign]
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as logger:
        logger.sendto(radio_info_packet(1, 14025.0), address)
        await until(lambda: when_read, what="the datagram read")
        logger.sendto(radio_info_packet(1, 7025.0), address)
        await until(lambda: len(when_read) == 2, what="the second datagram read")
    assert when_read == [14025.0, 7025.0]
