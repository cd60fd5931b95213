"""``HOST[:PORT]`` as an operator types it: ``shack-pc``, ``10.0.0.5:12060``,
``[fe80::1]:12059`` or a bare IPv6 address ``::1``."""

from __future__ import annotations

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "parse_address"]

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 12059
"""The protocol's default TCP port (configuration ``TCPPort``)."""


def parse_address(text: str | None) -> tuple[str, int]:
    """``(host, port)`` from ``text``; raises ValueError with a sentence when it cannot."""
    if text is None or not text.strip():
        return DEFAULT_HOST, DEFAULT_PORT
    text = text.strip()
    host, port_text = text, ""
    if text.startswith("["):
        close = text.find("]")
        if close < 0:
            raise ValueError(f"{text!r}: the '[' of an IPv6 address has no ']'")
        host, rest = text[1:close], text[close + 1:]
        if rest:
            if not rest.startswith(":"):
                raise ValueError(f"{text!r}: expected ':PORT' after ']', found {rest!r}")
            port_text = rest[1:]
    elif text.count(":") == 1:
        host, port_text = text.split(":")
    if not host:
        raise ValueError(f"{text!r}: the host name is empty")
    if port_text == "" and (text.endswith(":")):
        raise ValueError(f"{text!r}: the port after ':' is empty")
    if not port_text:
        return host, DEFAULT_PORT
    if not port_text.isdigit():
        raise ValueError(f"{text!r}: the port {port_text!r} is not a number")
    port = int(port_text)
    if not 1 <= port <= 65535:
        raise ValueError(f"{text!r}: the port {port} is not between 1 and 65535")
    return host, port
