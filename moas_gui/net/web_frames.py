"""RFC 6455's rule that every frame from a client is masked, which aiohttp does not
enforce (its reader takes masked and unmasked frames alike).

:class:`MaskCheck` follows the frames a client sends, header by header (sans-IO: feed
it bytes, it says whether they are still fine), without reading their payload.
:func:`require_masking` puts it in front of the reader of one WebSocket: the first
frame without the mask bit fails the connection, as the RFC says (section 5.1): a
Close frame with status 1002 (protocol error) is sent, the connection closed, and the
frame is never read.  One Warning line a minute says so (:attr:`ClientServer.trouble`).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from typing import Any

log = logging.getLogger(__name__)

CLOSE_PROTOCOL_ERROR = b"\x88\x02\x03\xea"
"""A Close frame from the server with status 1002, protocol error."""


class MaskCheck:
    """Follows client frames; :meth:`feed` is ``False`` from the first unmasked one on."""

    def __init__(self) -> None:
        self._header = bytearray()
        self._need = 2
        """Header bytes needed before the frame's length is known."""
        self._skip = 0
        """Payload bytes of the present frame still to pass over."""
        self.unmasked = False

    def feed(self, data: bytes) -> bool:
        if self.unmasked:
            return False
        at, end = 0, len(data)
        while at < end:
            if self._skip:
                step = min(self._skip, end - at)
                self._skip -= step
                at += step
                continue
            step = min(self._need - len(self._header), end - at)
            self._header += data[at : at + step]
            at += step
            if len(self._header) < self._need:
                break
            if not self._header_done():
                return False
        return True

    def _header_done(self) -> bool:
        """Reads the header gathered so far; ``False`` for an unmasked frame."""
        head = self._header
        if not head[1] & 0x80:
            self.unmasked = True
            return False
        length = head[1] & 0x7F
        extra = 2 if length == 126 else 8 if length == 127 else 0
        full = 2 + extra + 4
        if len(head) < full:
            self._need = full
            return True
        if extra:
            length = int.from_bytes(head[2 : 2 + extra], "big")
        self._skip = length
        self._header = bytearray()
        self._need = 2
        return True


class _MaskedOnly:
    """A WebSocket reader behind a :class:`MaskCheck` (aiohttp calls ``feed_data`` and
    ``feed_eof`` on it)."""

    def __init__(self, inner: Any, fail: Callable[[], None]) -> None:
        self.inner = inner
        self.check = MaskCheck()
        self._fail = fail

    def feed_data(self, data: bytes) -> tuple[bool, bytes]:
        if not self.check.feed(bytes(data)):
            self._fail()
            return True, b""
        result: tuple[bool, bytes] = self.inner.feed_data(data)
        return result

    def feed_eof(self) -> None:
        self.inner.feed_eof()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def frames_arrived_early(protocol: Any) -> bool:
    """Whether a client sent bytes after its upgrade request before it was answered
    (they would reach the reader unchecked; RFC 6455 has the client wait)."""
    return bool(getattr(protocol, "_message_tail", b""))


def require_masking(
    protocol: Any, transport: asyncio.Transport | None, on_unmasked: Callable[[], None]
) -> bool:
    """Puts a :class:`MaskCheck` in front of the WebSocket reader of aiohttp's request
    handler ``protocol`` (call right after the handshake).  ``False`` when this aiohttp
    keeps its reader elsewhere (the check could not be put in)."""
    inner = getattr(protocol, "_payload_parser", None)
    if inner is None:
        return False

    def fail() -> None:
        on_unmasked()
        if transport is not None and not transport.is_closing():
            transport.write(CLOSE_PROTOCOL_ERROR)
            transport.close()

    protocol._payload_parser = _MaskedOnly(inner, fail)
    return True


__all__ = ["CLOSE_PROTOCOL_ERROR", "MaskCheck", "frames_arrived_early", "require_masking"]
