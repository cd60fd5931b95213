"""The streaming decoder for what a MOAS II sends: bytes in, messages out.

Feed it whatever the port gave, in any pieces (one byte at a time, or many
messages at once); it returns the complete messages found so far and keeps
the unfinished rest for the next call.

How it finds messages, in plain words:

* Bytes at or below space (``0x00``-``0x20``) are ignored wherever they are.
* ``;`` ends a message.  ``$`` throws away everything of the message so far.
* A message starts with one of the protocol's command or reply characters,
  which never occur inside a message.  So if one appears in the middle of a
  message, the text before it was garbage (or a message cut short), and the
  new message starts there: garbage costs at most the message it hit, never
  the next good one.
* Anything that does not read as a message comes out as a
  :class:`~.messages.Malformed` value with the bytes and the reason, for the
  caller to log; it never raises.
"""

from __future__ import annotations

import re

from .messages import BoxMessage, Malformed
from .replies import parse_reply

START_CHARS = b"!%&(~^[]/'\\|*\"_):@#.<>?"
"""Every command and reply character: the only bytes that start a message."""

MAX_MESSAGE = 80
"""Longest run without ``;`` kept while waiting for the end of a message."""

_IGNORED = bytes(range(0x21))
_LAST_START = re.compile(b"[" + re.escape(START_CHARS) + b"][^" + re.escape(START_CHARS) + b"]*\\Z")
_CACHE_SIZE = 2048

Decoded = BoxMessage | Malformed


class SwitchDecoder:
    """Turns the byte stream from one switch into messages."""

    __slots__ = ("_cache", "_partial")

    def __init__(self) -> None:
        self._partial = b""
        self._cache: dict[bytes, tuple[Decoded, ...]] = {}

    @property
    def pending(self) -> bytes:
        """Bytes held while waiting for the rest of a message."""
        return self._partial

    def feed(self, data: bytes) -> list[Decoded]:
        """The messages completed by ``data``, in order."""
        data = data.translate(None, _IGNORED)
        if not data:
            return []
        buf = self._partial + data if self._partial else data
        out: list[Decoded] = []
        if b";" in buf:
            chunks = buf.split(b";")
            tail = chunks.pop()
            cache = self._cache
            for chunk in chunks:
                found = cache.get(chunk)
                if found is None:
                    found = _decode_chunk(chunk)
                    if len(cache) >= _CACHE_SIZE:
                        cache.clear()
                    cache[chunk] = found
                out.extend(found)
        else:
            tail = buf
        self._partial = self._trim(tail, out)
        return out

    def reset(self) -> None:
        """Forget any unfinished message (after the port was reopened)."""
        self._partial = b""

    @staticmethod
    def _trim(tail: bytes, out: list[Decoded]) -> bytes:
        if b"$" in tail:
            tail = tail[tail.rfind(b"$") + 1 :]
        if len(tail) <= MAX_MESSAGE:
            return tail
        match = _LAST_START.search(tail)
        keep = match.group() if match is not None and len(match.group()) <= MAX_MESSAGE else b""
        out.append(Malformed(tail[: len(tail) - len(keep)], f"no ';' within {MAX_MESSAGE} bytes"))
        return keep


def _decode_chunk(chunk: bytes) -> tuple[Decoded, ...]:
    """What one ``;``-terminated piece (without the ``;``) holds."""
    found: list[Decoded] = []
    if b"$" in chunk:
        cut = chunk.rfind(b"$") + 1
        found.append(Malformed(chunk[:cut], "aborted with '$'"))
        chunk = chunk[cut:]
    if not chunk:
        return tuple(found)
    match = _LAST_START.search(chunk)
    if match is None:
        found.append(Malformed(chunk + b";", "no message starts here"))
        return tuple(found)
    if match.start():
        found.append(Malformed(chunk[: match.start()], "garbage before a message"))
    raw = match.group()
    try:
        found.append(parse_reply(raw.decode("ascii")))
    except (ValueError, IndexError) as exc:
        found.append(Malformed(raw + b";", str(exc)))
    return tuple(found)


__all__ = ["MAX_MESSAGE", "START_CHARS", "Decoded", "SwitchDecoder"]
