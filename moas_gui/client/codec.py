"""The client side of the protocol's framing, without any I/O.

Like a sans-IO codec, :class:`ClientCodec` is fed the bytes that arrive and
hands back what they mean; it is asked for the bytes of a request and never
touches a socket::

    bytes from the server --feed()-->  Reply | Event | Garbled
    request(cmd, args)   --encode()--> one JSON line, and the id it carries

Every server line is one JSON object ended by ``\\n`` (``\\r\\n`` accepted),
cut out of the stream by :mod:`moas_gui.line_framer` as every line protocol is.  An
object with ``"event"`` is an :class:`Event`; one with ``"ok"`` is a
:class:`Reply`.  Anything else (not JSON, not an object, neither shape, a line
longer than :data:`MAX_LINE`) becomes a :class:`Garbled` item that says what
was wrong, and the codec carries on with the next line.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from moas_gui.line_framer import LineEnd, LineFramer, LongLine

__all__ = ["MAX_LINE", "ClientCodec", "Event", "Garbled", "Incoming", "Reply"]

MAX_LINE = 16 * 1024 * 1024
"""The longest server line accepted, in bytes (a snapshot of a large station is
far below this; a peer that is not a moas-gui server may send anything)."""


@dataclass(frozen=True, slots=True)
class Reply:
    """The server's answer to one request."""

    id: Any
    ok: bool
    result: Mapping[str, Any]
    code: str = ""
    message: str = ""


@dataclass(frozen=True, slots=True)
class Event:
    """A change the server pushed: ``name`` is ``state``, ``radio``, ``layout``..."""

    name: str
    body: Mapping[str, Any]


@dataclass(frozen=True, slots=True)
class Garbled:
    """A line that could not be understood, and why."""

    reason: str


Incoming = Reply | Event | Garbled


class ClientCodec:
    """Splits the server's byte stream into messages and numbers the requests."""

    def __init__(self, max_line: int = MAX_LINE) -> None:
        self._lines = LineFramer(max_line, LineEnd.LF)
        self._max_line = max_line
        self._next_id = 1
        self.line_number = 0
        """Lines received so far (for messages that say where)."""

    def encode(self, cmd: str, args: Mapping[str, Any] | None = None) -> tuple[int, bytes]:
        """A request line for ``cmd`` with ``args``, and the id it carries."""
        request_id = self._next_id
        self._next_id += 1
        message: dict[str, Any] = {"id": request_id, "cmd": cmd}
        if args:
            message.update(args)
        data = json.dumps(message, separators=(",", ":"), allow_nan=False) + "\n"
        return request_id, data.encode("utf-8")

    def feed(self, data: bytes) -> list[Incoming]:
        """Everything the bytes in ``data`` complete (lines may arrive in pieces)."""
        out: list[Incoming] = []
        for line in self._lines.feed(data):
            self.line_number += 1
            if isinstance(line, LongLine):
                out.append(Garbled(
                    f"line {self.line_number} is longer than {self._max_line} bytes; skipped"))
                continue
            item = self._decode(line.data)
            if item is not None:
                out.append(item)
        return out

    def _decode(self, line: bytes) -> Incoming | None:
        if not line.strip():
            return None
        where = f"line {self.line_number}"
        try:
            obj = json.loads(line.decode("utf-8"))
        except UnicodeDecodeError as exc:
            return Garbled(f"{where} is not UTF-8 (byte {exc.start})")
        except json.JSONDecodeError as exc:
            return Garbled(f"{where} is not JSON: {exc.msg} at column {exc.colno}")
        except RecursionError:
            return Garbled(f"{where} is nested too deeply to read")
        if not isinstance(obj, dict):
            return Garbled(f"{where} is a JSON {type(obj).__name__}, not an object")
        if "event" in obj:
            name = obj["event"]
            if not isinstance(name, str):
                return Garbled(f"{where}: 'event' is not a string")
            return Event(name, obj)
        if "ok" in obj:
            return _reply(obj, where)
        return Garbled(f"{where} is neither a reply (no 'ok') nor an event (no 'event')")


def _reply(obj: dict[str, Any], where: str) -> Reply | Garbled:
    ok = obj["ok"]
    if not isinstance(ok, bool):
        return Garbled(f"{where}: 'ok' is not true or false")
    request_id = obj.get("id")
    if ok:
        result = obj.get("result", {})
        if result is None:
            result = {}
        if not isinstance(result, dict):
            return Garbled(f"{where}: 'result' of reply {request_id!r} is not an object")
        return Reply(request_id, True, result)
    error = obj.get("error")
    if not isinstance(error, dict):
        return Reply(request_id, False, {}, "internal", "the server refused without saying why")
    code = error.get("code")
    message = error.get("message")
    return Reply(
        request_id, False, {},
        code if isinstance(code, str) else "internal",
        message if isinstance(message, str) else "the server refused without saying why",
    )
