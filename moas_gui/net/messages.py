"""Writing the server's lines: replies and events, sans-IO.

Every function returns one complete line (UTF-8 JSON and ``\\n``).  Text is
written as UTF-8 where it can be; a string holding a lone surrogate (which a
client can send as ``"\\ud800"``) is escaped instead, so the line is always
valid UTF-8.  A value that is not JSON (a set, NaN, an object nested beyond
what :mod:`json` writes) raises :class:`MessageEncodeError`, which says what could
not be written.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from moas_gui import __version__
from moas_gui.errors import ProtocolError

from .backend import ErrorCode

PROTOCOL_VERSION = 1
SERVER_NAME = "moas-gui"
EVENTS = ("state", "radio", "rotator", "switch", "layout", "log")


class MessageEncodeError(ProtocolError):
    """Something the server was about to send is not JSON."""


def encode(message: Mapping[str, Any]) -> bytes:
    """One message as a line."""
    try:
        text = json.dumps(message, ensure_ascii=False, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as e:
        raise MessageEncodeError(f"cannot write {type(message).__name__} as JSON: {e}") from None
    try:
        return text.encode("utf-8") + b"\n"
    except UnicodeEncodeError:
        return json.dumps(message, ensure_ascii=True).encode("ascii") + b"\n"


def hello_result(operator: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The hello's result; ``operator`` (``name``, ``role``, ``radios``) when the hello's
    token named one, so that a client offers only what its role allows."""
    result = {"server": SERVER_NAME, "version": __version__, "protocol": PROTOCOL_VERSION}
    if operator is not None:
        result["operator"] = dict(operator)
    return result


def reply_ok(request_id: Any, result: Any) -> bytes:
    return encode({"id": request_id, "ok": True, "result": result})


def reply_error(request_id: Any, code: ErrorCode, message: str) -> bytes:
    return encode(
        {"id": request_id, "ok": False, "error": {"code": code.value, "message": message}}
    )


def event(name: str, body: Mapping[str, Any]) -> bytes:
    """An event line: ``{"event": name, ...body}`` (an ``event`` key in ``body`` is ignored)."""
    if name not in EVENTS:
        raise MessageEncodeError(f"{name!r} is not an event of the client protocol")
    message: dict[str, Any] = {"event": name}
    for key, value in body.items():
        if key != "event":
            message[key] = value
    return encode(message)


__all__ = [
    "EVENTS",
    "PROTOCOL_VERSION",
    "SERVER_NAME",
    "MessageEncodeError",
    "encode",
    "event",
    "hello_result",
    "reply_error",
    "reply_ok",
]
