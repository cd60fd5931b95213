"""``moas-client --headless``: sources in, client protocol out, no window, no Qt.

Every source runs on this asyncio loop and hands its events through one
:class:`~moas_gui.sources.base.SourceHub` (newest wins, two sources for one
radio logged once) to a :class:`~moas_gui.sources.forwarder.Forwarder`, which
tells the server.  The server may come and go; so may the sources.  SIGINT or
SIGTERM ends it cleanly (exit status 0); with ``quit_after`` it ends by itself
and returns 3 if the server was never reached.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections.abc import Sequence
from typing import Any

from moas_gui.aio import CleanStop
from moas_gui.client.connection import ClientConnection
from moas_gui.sources.base import Source, SourceHub
from moas_gui.sources.forwarder import Forwarder
from moas_gui.sources.spec import SourceSpec, make_source

log = logging.getLogger(__name__)

EXIT_NEVER_CONNECTED = 3


async def serve(host: str, port: int, station: int, specs: Sequence[SourceSpec], *,
                name: str, quit_after: float | None = None,
                security: dict[str, Any] | None = None) -> int:
    """``security``: the connection's ``token``, ``tls``, ``pin``, ``trust``
    (:class:`~moas_gui.client.connection.ClientConnection`)."""
    connection = ClientConnection(host, port, name=name, station=station, **(security or {}))
    forwarder = Forwarder(connection)
    hub = SourceHub(forwarder, logging.getLogger("moas_gui.sources"))
    sources: list[Source] = []
    done = asyncio.Event()
    loop = asyncio.get_running_loop()
    stopping = CleanStop(done.set).install()
    connection.start()
    forwarder.start()
    try:
        for spec in specs:
            source = make_source(spec, station, hub)
            try:
                await source.start()
            except OSError as exc:
                log.error("%s cannot be read: %s", spec.text(), exc)
                continue
            sources.append(source)
            log.info("Reading %s for station %d", spec.text(), station)
        log.info("Telling the server at %s", connection.address)
        if quit_after is not None:
            loop.call_later(quit_after, done.set)
        await done.wait()
    finally:
        for source in sources:
            with contextlib.suppress(Exception):
                await source.close()
        await forwarder.aclose()
        await connection.aclose()
        stopping.remove()
    if quit_after is not None and connection.connects == 0:
        log.error("could not reach the server at %s", connection.address)
        return EXIT_NEVER_CONNECTED
    return 0


__all__ = ["EXIT_NEVER_CONNECTED", "serve"]
