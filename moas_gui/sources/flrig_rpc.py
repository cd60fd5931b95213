"""flrig's XML-RPC, without I/O: method calls out as HTTP requests, answers in.

flrig (W1HKJ's rig control program) serves XML-RPC over HTTP, on TCP port
12345 unless changed in its server settings (the same default Hamlib's flrig
backend connects to).  The methods this source asks,
as flrig documents them (w1hkj.com/flrig-help/xmlrpc_commands.html; flrig's
src/server/xml_server.cxx):

=================  ========================================================
``rig.get_vfo``    the active VFO's frequency in Hz, as a string
``rig.get_split``  ``1`` when split, else ``0``
``rig.get_AB``     which VFO is active, ``"A"`` or ``"B"``
``rig.get_vfoA``   VFO A's frequency in Hz (``rig.get_vfoB`` for B)
``rig.get_ptt``    ``1`` while transmitting, else ``0``
=================  ========================================================

:func:`request` writes one call (HTTP/1.1, kept alive); :class:`ResponseParser`
reads answers as bytes come and returns each answer's value.  Anything that
is not an XML-RPC answer -- a bad status, a missing or huge length, a
document with a DOCTYPE or entities, a fault -- raises :class:`FlrigReplyError`.
"""

from __future__ import annotations

import math
import xmlrpc.client
from typing import Final
from xml.parsers.expat import ExpatError

from moas_gui.config.rigs import FLRIG_PORT
from moas_gui.errors import ProtocolError

DEFAULT_PORT: Final = FLRIG_PORT
PATH: Final = "/RPC2"
MAX_HEADER: Final = 8192
MAX_BODY: Final = 65536
MAX_HZ: Final = 300_000_000_000


class FlrigReplyError(ProtocolError, ValueError):
    """Not an answer flrig sends; ``reason`` is a short key for counting."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


def request(method: str, host: str, port: int) -> bytes:
    """The HTTP request that calls ``method`` with no arguments."""
    body = xmlrpc.client.dumps((), methodname=method).encode("ascii")
    head = (f"POST {PATH} HTTP/1.1\r\nHost: {host}:{port}\r\nUser-Agent: moas-gui\r\n"
            f"Content-Type: text/xml\r\nContent-Length: {len(body)}\r\n\r\n")
    return head.encode("ascii") + body


class ResponseParser:
    """HTTP responses in, each one's XML-RPC value out (and whether the server closes)."""

    def __init__(self) -> None:
        self._buffer = b""
        self.closing = False
        """The last answer said ``Connection: close``."""

    def feed(self, data: bytes) -> list[object]:
        self._buffer += data
        values: list[object] = []
        while True:
            end = self._buffer.find(b"\r\n\r\n")
            if end < 0:
                if len(self._buffer) > MAX_HEADER:
                    raise FlrigReplyError("too_long", f"an HTTP head longer than {MAX_HEADER} "
                                          "bytes")
                return values
            length, self.closing = _head(self._buffer[:end])
            start = end + 4
            if len(self._buffer) < start + length:
                return values
            body, self._buffer = self._buffer[start:start + length], self._buffer[start + length:]
            values.append(_value(body))


def _head(raw: bytes) -> tuple[int, bool]:
    if len(raw) > MAX_HEADER:
        raise FlrigReplyError("too_long", f"an HTTP head longer than {MAX_HEADER} bytes")
    lines = raw.decode("latin-1").split("\r\n")
    status = lines[0].split(" ", 2)
    if len(status) < 2 or not status[0].startswith("HTTP/1."):
        raise FlrigReplyError("not_http", f"{lines[0][:60]!r} is not an HTTP status line")
    if status[1] != "200":
        raise FlrigReplyError("http_status", f"the server answered HTTP {status[1][:3]}")
    headers = {}
    for line in lines[1:]:
        name, colon, value = line.partition(":")
        if colon:
            headers[name.strip().lower()] = value.strip()
    text = headers.get("content-length")
    if text is None or not text.isdigit():
        raise FlrigReplyError("no_length", "the answer has no Content-Length")
    length = int(text)
    if length > MAX_BODY:
        raise FlrigReplyError("too_long", f"an answer of {length} bytes")
    closing = headers.get("connection", "").lower() == "close" or lines[0].startswith("HTTP/1.0")
    return length, closing


def _value(body: bytes) -> object:
    if b"<!DOCTYPE" in body.upper() or b"<!ENTITY" in body.upper():
        raise FlrigReplyError("entities", "an answer with a DOCTYPE or entities")
    try:
        params, _ = xmlrpc.client.loads(body)
    except xmlrpc.client.Fault as fault:
        raise FlrigReplyError("fault", f"flrig refused the call: {fault.faultString[:80]}") \
            from None
    except (ExpatError, ValueError, TypeError, IndexError) as exc:
        raise FlrigReplyError("not_xmlrpc", f"the answer is not XML-RPC: {exc}") from None
    if len(params) != 1:
        raise FlrigReplyError("not_xmlrpc", "the answer has no value")
    return params[0]


def hz(value: object, what: str) -> int:
    """A frequency as flrig gives it (a string of Hz; an int or double in some versions)."""
    if isinstance(value, bool):
        raise FlrigReplyError("bad_value", f"{what} is a boolean")
    try:
        number = float(value.strip()) if isinstance(value, str) else float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise FlrigReplyError("bad_value", f"{what} {str(value)[:40]!r} is not a number") \
            from None
    if math.isnan(number) or not 1 <= number <= MAX_HZ:
        raise FlrigReplyError("absurd", f"{what} of {str(value)[:40]} Hz is absurd")
    return int(number)


def flag(value: object, what: str) -> bool:
    """``0``/``1`` (int, bool or string) as flrig gives split and PTT."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.strip() in ("0", "1"):
        return value.strip() == "1"
    raise FlrigReplyError("bad_value", f"{what} {str(value)[:40]!r} is not 0 or 1")


__all__ = ["DEFAULT_PORT", "FlrigReplyError", "ResponseParser", "flag", "hz", "request"]
