"""What an operating computer's sources say, told to the server in the client protocol.

:class:`Forwarder` is the sink of ``moas-client``'s sources (docs/client.md,
"Headless"): a frequency becomes ``frequency``, a transmit or receive focus
``active`` or ``focus``, an OTRSP antenna choice ``select`` (exclusive).  It
keeps only the **newest** value per radio (or per station for the focus),
sends one request at a time, focus first, and when the server comes back
after a lost connection it sends the newest of everything again, since the
sources only report changes.  A refusal (no such radio...) is logged once per
kind and radio a minute; nothing is retried until that value changes.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from typing import Any

from moas_gui.client.connection import (
    ClientConnection,
    ConnectionLost,
    NotConnected,
    RequestTimeout,
    ServerError,
)
from moas_gui.client.events import LinkChanged, LinkState
from moas_gui.log_limit import LogLimiter, held_text
from moas_gui.sources.base import ActiveRadio, FocusRadio, FrequencyReport, event_key

log = logging.getLogger(__name__)


def _key(event: Any) -> tuple[object, ...]:
    if isinstance(event, ActiveRadio | FocusRadio | FrequencyReport):
        return event_key(event)
    return (type(event).__name__, getattr(event, "station", None), getattr(event, "radio", None))


class Forwarder:
    """A source sink that tells the server; :meth:`start` once, :meth:`aclose` once."""

    def __init__(self, connection: ClientConnection) -> None:
        self.connection = connection
        self._latest: dict[tuple[object, ...], Any] = {}
        self._dirty: dict[tuple[object, ...], None] = {}
        self._wake = asyncio.Event()
        self._task: asyncio.Task[None] | None = None
        self._closing = False
        self._limiter = LogLimiter()
        self.sent = 0
        self.refused = 0
        self._unsubscribe = connection.subscribe(self._on_client_event)

    def __call__(self, event: Any) -> None:
        key = _key(event)
        self._latest[key] = event
        self._dirty[key] = None
        self._wake.set()

    def _on_client_event(self, event: object) -> None:
        if isinstance(event, LinkChanged) and event.state is LinkState.CONNECTED:
            for key in self._latest:
                self._dirty[key] = None
            self._wake.set()

    def start(self) -> None:
        if self._task is None:
            self._task = asyncio.get_running_loop().create_task(self._run(), name="forwarder")

    async def aclose(self) -> None:
        self._unsubscribe()
        # the flag ends the loop even when the cancellation is lost: on Python 3.11 a
        # request's wait_for returns its reply instead when both happen at once
        self._closing = True
        self._wake.set()
        task, self._task = self._task, None
        if task is not None:
            task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await task

    def _next(self) -> tuple[object, ...]:
        for key in self._dirty:
            if key[0] in ("ActiveRadio", "FocusRadio"):
                return key
        return next(iter(self._dirty))

    async def _run(self) -> None:
        while not self._closing:
            await self._wake.wait()
            self._wake.clear()
            while self._dirty and self.connection.link is LinkState.CONNECTED \
                    and not self._closing:
                key = self._next()
                del self._dirty[key]
                event = self._latest[key]
                try:
                    await self._send(event)
                except ServerError as exc:
                    self.refused += 1
                    held = self._limiter.allow((exc.code, key))
                    if held is not None:
                        log.warning("The server refused %s: %s%s", exc.cmd, exc.message,
                                    held_text(held))
                except (NotConnected, ConnectionLost, RequestTimeout):
                    self._dirty[key] = None  # sent again once connected
                    break
                else:
                    self.sent += 1

    async def _send(self, event: Any) -> None:
        c = self.connection
        if isinstance(event, FrequencyReport):
            tx = None if event.tx_khz == event.rx_khz else event.tx_khz
            await c.frequency(event.station, event.radio, event.rx_khz, tx)
        elif isinstance(event, ActiveRadio):
            await c.active(event.station, event.radio)
        elif isinstance(event, FocusRadio):
            await c.focus(event.station, event.radio)
        elif hasattr(event, "antenna"):
            await c.select(event.station, event.radio, event.antenna, exclusive=True)


__all__ = ["Forwarder"]
