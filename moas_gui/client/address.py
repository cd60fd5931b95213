"""``HOST[:PORT]`` as an operator types it: ``shack-pc``, ``10.0.0.5:12060``,
``[fe80::1]:12059`` or a bare IPv6 address ``::1``."""

from __future__ import annotations

from moas_gui.addresses import split_address

__all__ = ["DEFAULT_HOST", "DEFAULT_PORT", "parse_address"]

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 12059
"""The protocol's default TCP port (configuration ``TCPPort``)."""


def parse_address(text: str | None) -> tuple[str, int]:
    """``(host, port)`` from ``text`` (the local server when empty); raises ValueError
    with a sentence when it cannot."""
    if text is None or not text.strip():
        return DEFAULT_HOST, DEFAULT_PORT
    return split_address(text, DEFAULT_PORT)
