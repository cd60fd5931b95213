"""One client's connection as the server sees it: who it is, what it follows,
and its outgoing queue.

The outgoing queue is the transport's write buffer.  :meth:`Connection.send`
hands a line to it and returns at once (the operating system sends it when
the client reads); if the client stops reading, the buffer grows, and once it
holds more than ``max_pending`` bytes the connection is cut and the reason
logged.  Nothing ever waits for one client, so a stuck one cannot delay the
others or the code that published the event.
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from collections.abc import Awaitable, Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

from moas_gui.edge.admission import Ticket
from moas_gui.log_limit import held_text
from moas_gui.net.secrets import SecretVerdict

from .backend import ErrorCode
from .framing import request_framer
from .identity import Identity, Party
from .messages import MessageEncodeError, reply_error, reply_ok

log = logging.getLogger(__name__)

LayoutKey = tuple[int, int, int, int]
"""``(station, radio, rows, columns)`` as a client asked for a layout."""


@dataclass(frozen=True, slots=True)
class ClientInfo:
    """A connected client, for the server's window."""

    address: str
    name: str | None
    station: int | None
    radio: int | None
    log: bool
    layouts: int


class LineTransport(Protocol):
    """What a connection writes to: an asyncio transport, or a WebSocket's outlet."""

    def write(self, data: bytes) -> None: ...
    def is_closing(self) -> bool: ...
    def get_write_buffer_size(self) -> int: ...
    def abort(self) -> None: ...


class LineWriter(Protocol):
    """An :class:`asyncio.StreamWriter`, or anything else carrying lines the same way."""

    @property
    def transport(self) -> LineTransport: ...
    def close(self) -> None: ...


def clean_name(name: str, limit: int = 64) -> str:
    """A client's name made safe for a log line: printable, one line, short."""
    text = "".join(ch if ch.isprintable() else "?" for ch in name).strip()
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return text or "?"


class Connection:
    """State of one connected client; the server drives it."""

    def __init__(
        self,
        writer: LineWriter,
        address: str,
        *,
        max_pending: int,
        max_layouts: int,
        on_queued: Callable[[int], None] | None = None,
    ) -> None:
        self.writer = writer
        self._on_queued = on_queued
        """Told the size of every line queued (the server bounds the sum over all clients)."""
        self.address = address
        self.max_pending = max_pending
        self.max_layouts = max_layouts
        self.splitter = request_framer()
        self.name: str | None = None
        self.station: int | None = None
        self.radio: int | None = None
        self.greeted = False
        """Said hello: receives change events."""
        self.wants_log = False
        self.bad_lines = 0
        """Bad lines in a row; three close the connection."""
        self.layouts: OrderedDict[LayoutKey, Any] = OrderedDict()
        """Layouts this connection follows, with the last one it was sent."""
        self.closed = False
        self.close_reason: str | None = None
        self.identity = Identity(Party.LAN, address)
        """Who this connection is (:mod:`.identity`): set by the server when it is made,
        changed by a hello with a token.  :attr:`Identity.is_operator` tells the admission
        policy an authenticated operator holds it."""
        self.identified: Callable[[Identity], None] | None = None
        """Told the new identity when a hello's token makes this connection an operator
        (the admission policy may move it to the operators' own capacity then)."""
        self.authenticate: Callable[[str], Awaitable[SecretVerdict]] | None = None
        """Checks a hello's token off the loop (:meth:`~moas_gui.net.secrets.SecretGuard.
        check_token`: the operator, or why not); None here when this server has no
        operators."""
        self.chatter: Callable[[], int | None] | None = None
        """Asked before each Info line about this client (its hello, its leaving): None
        to stay quiet, else how many were left out -- all clients together have a share
        of the log, so that programs connecting in a loop cannot flood it."""
        self.ticket: Ticket | None = None
        """Its place in the admission policy (:mod:`moas_gui.edge.admission`): the hook
        that :func:`~.dispatch.answer` greets after a valid ``hello``, and that makes it
        an operator once a token has said so (:meth:`Ticket.operator`)."""

    def note(self, message: str, *args: object) -> None:
        """An Info line about this client, within its address's share of the log."""
        held = self.chatter() if self.chatter is not None else 0
        if held is None:
            return
        if held:
            message += "%s"
            args = (*args, held_text(held, "more lines about clients connecting and leaving"))
        log.info(message, *args)

    def __str__(self) -> str:
        if self.identity.is_operator:
            return f'operator "{self.identity.name}" at {self.address}'
        if self.name is None:
            return f"client at {self.address}"
        return f'client "{self.name}" at {self.address}'

    def info(self) -> ClientInfo:
        return ClientInfo(
            self.address, self.name, self.station, self.radio, self.wants_log, len(self.layouts)
        )

    def follow(self, key: LayoutKey, layout: Any) -> None:
        """Remember ``layout`` as sent for ``key``; the oldest followed layout is
        forgotten when there would be more than ``max_layouts``."""
        self.layouts[key] = layout
        self.layouts.move_to_end(key)
        while len(self.layouts) > self.max_layouts:
            self.layouts.popitem(last=False)

    @property
    def pending(self) -> int:
        """Bytes queued and not yet taken by the client (0 once cut off)."""
        return int(self.writer.transport.get_write_buffer_size())

    def send(self, line: bytes) -> bool:
        """Queues ``line``; cuts the connection when its queue overflows.
        Returns whether the line was queued."""
        if self.closed:
            return False
        transport = self.writer.transport
        if transport.is_closing():
            return False
        transport.write(line)
        pending = transport.get_write_buffer_size()
        if pending > self.max_pending:
            self.abort(f"it stopped reading ({pending:,} bytes waiting to be sent)")
            return False
        if self._on_queued is not None:
            self._on_queued(len(line))
        return not self.closed

    def reply(self, request_id: Any, cmd: str, result: Any) -> None:
        """Queues the reply to a request; a result that is not JSON becomes an
        ``internal`` error reply and an Error log line."""
        try:
            line = reply_ok(request_id, result)
        except MessageEncodeError as e:
            log.error("The reply to %s from %s is not JSON: %s", cmd, self, e)
            self.reply_error(request_id, ErrorCode.INTERNAL, f"the server's reply to {cmd} "
                             "could not be written; the server's log says why")
            return
        self.send(line)

    def reply_error(self, request_id: Any, code: ErrorCode, message: str) -> None:
        try:
            line = reply_error(request_id, code, message)
        except MessageEncodeError:  # the id itself cannot be written back
            line = reply_error(None, code, message)
        self.send(line)

    def close(self, reason: str) -> None:
        """Closes after what is queued has been sent."""
        if not self.closed:
            self.closed, self.close_reason = True, reason
            self.writer.close()

    def abort(self, reason: str) -> None:
        """Closes at once, dropping what is queued."""
        if not self.closed:
            self.closed, self.close_reason = True, reason
            log.warning("Disconnecting %s: %s", self, reason)
            self.writer.transport.abort()


def cut_slowest(connections: Iterable[Connection], limit: int) -> None:
    """When the output waiting for all ``connections`` is over ``limit`` bytes,
    cuts those with the most waiting (the ones that do not read) until it is not."""
    sizes = [(conn.pending, conn) for conn in connections if not conn.closed]
    total = sum(size for size, _conn in sizes)
    if total <= limit:
        return
    sizes.sort(key=lambda pair: pair[0], reverse=True)
    for size, conn in sizes:
        if total <= limit:
            break
        conn.abort(f"the output waiting for all clients reached {total:,} bytes, over "
                   f"the {limit:,}-byte limit, and it had the most waiting ({size:,} bytes)")
        total -= size


__all__ = [
    "ClientInfo", "Connection", "LayoutKey", "LineTransport", "LineWriter", "clean_name",
    "cut_slowest",
]
