"""A small asyncio client for the client protocol: for client windows, scripts,
tests and the benchmark.

::

    client = await ProtocolClient.connect("127.0.0.1", 12059)
    await client.request("hello", client="my script")      # the result, or RequestError
    state = await client.next_event("state")
    await client.request("select", station=1, radio=1, antenna=3)
    await client.close()

Each :meth:`ProtocolClient.request` gets a fresh integer ``id`` and waits for
the reply carrying it.  Events go to :attr:`ProtocolClient.events` (no bound:
read them, or they pile up); replies nobody waits for -- those with
``"id": null`` that answer a bad line -- go to :attr:`ProtocolClient.stray`.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import logging
from typing import Any

from moas_gui.errors import MoasError
from moas_gui.log_limit import LogLimiter, held_text

from .backend import ErrorCode, JSONObject, RequestError
from .framing import Line, request_framer
from .messages import encode

log = logging.getLogger(__name__)


class ConnectionClosed(MoasError, ConnectionError):
    """The server closed the connection."""


class ProtocolClient:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.reader, self.writer = reader, writer
        self.events: asyncio.Queue[JSONObject] = asyncio.Queue()
        self.stray: asyncio.Queue[JSONObject] = asyncio.Queue()
        self._pending: dict[Any, asyncio.Future[JSONObject]] = {}
        self._ids = itertools.count(1)
        self.closed = asyncio.Event()
        self._trouble = LogLimiter()
        """Lines about what the server sent wrong: one a minute per kind, with a count."""
        self._task = asyncio.create_task(self._read(), name="client protocol reader")

    @classmethod
    async def connect(cls, host: str, port: int, *, local_host: str | None = None,
                      ssl: Any = None) -> ProtocolClient:
        """``local_host``: the address to connect from (``127.0.0.2`` plays another
        computer); ``ssl``: an :class:`ssl.SSLContext` for a server with TLS."""
        reader, writer = await asyncio.open_connection(
            host, port, local_addr=None if local_host is None else (local_host, 0), ssl=ssl,
            server_hostname=None if ssl is None else host)
        return cls(reader, writer)

    # ---- sending --------------------------------------------------------------------

    def send_raw(self, data: bytes) -> None:
        """Writes bytes as they are (tests: garbage, huge lines)."""
        self.writer.write(data)

    def send(self, message: JSONObject) -> None:
        self.writer.write(encode(message))

    async def call(self, cmd: str, **args: Any) -> JSONObject:
        """Sends a request and returns its whole reply (``ok``, ``result`` or ``error``)."""
        if self.closed.is_set():
            raise ConnectionClosed("the server closed the connection")
        request_id = next(self._ids)
        future: asyncio.Future[JSONObject] = asyncio.get_running_loop().create_future()
        self._pending[request_id] = future
        self.send({"id": request_id, "cmd": cmd, **args})
        try:
            return await future
        finally:
            self._pending.pop(request_id, None)

    async def request(self, cmd: str, **args: Any) -> Any:
        """Sends a request; returns its result, or raises :class:`RequestError`."""
        reply = await self.call(cmd, **args)
        if reply.get("ok"):
            return reply.get("result")
        error = reply.get("error") or {}
        code, message = str(error.get("code", "internal")), str(error.get("message", ""))
        if code not in {c.value for c in ErrorCode}:  # a code from a later protocol version
            code, message = ErrorCode.INTERNAL, f"{code}: {message}"
        raise RequestError(code, message)

    # ---- receiving ------------------------------------------------------------------

    async def next_event(self, name: str | None = None, timeout: float = 5.0) -> JSONObject:
        """The next event (of that name: others before it are dropped)."""
        async with asyncio.timeout(timeout):
            while True:
                message = await self.events.get()
                if name is None or message.get("event") == name:
                    return message

    async def _read(self) -> None:
        splitter = request_framer(limit=1 << 24)
        try:
            while True:
                data = await self.reader.read(1 << 16)
                if not data:
                    break
                for item in splitter.feed(data):
                    if isinstance(item, Line) and item.data.strip():
                        self._take(item.data)
        except (ConnectionError, OSError):
            pass
        finally:
            self.closed.set()
            for future in self._pending.values():
                if not future.done():
                    future.set_exception(ConnectionClosed("the server closed the connection"))

    def _take(self, line: bytes) -> None:
        try:
            message = json.loads(line)
        except (ValueError, RecursionError) as e:
            held = self._trouble.allow("not JSON")  # the server decides how many
            if held is not None:
                log.warning("The server sent a line that is not JSON (%s); skipped%s", e,
                            held_text(held))
            return
        if not isinstance(message, dict):
            held = self._trouble.allow("not an object")
            if held is not None:
                log.warning("The server sent JSON that is not an object; skipped%s",
                            held_text(held))
            return
        self._dispatch(message)

    def _dispatch(self, message: JSONObject) -> None:
        if "event" in message and "ok" not in message:
            self.events.put_nowait(message)
            return
        request_id = message.get("id")
        future = self._pending.get(request_id) if type(request_id) is int else None
        if future is not None and not future.done():
            future.set_result(message)
        else:
            self.stray.put_nowait(message)

    async def close(self) -> None:
        self._task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await self._task
        self.writer.close()
        with contextlib.suppress(Exception):
            await self.writer.wait_closed()


__all__ = ["ConnectionClosed", "ProtocolClient"]
