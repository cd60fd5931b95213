"""``Address`` strings of the configuration: ``host``, ``host:port`` or ``[v6]:port``."""

from __future__ import annotations

import ipaddress

from .ascii import is_digits

LOCAL_NAMES = frozenset({"localhost", "localhost.localdomain"})


def split_address(address: str, default_port: int) -> tuple[str, int]:
    """``(host, port)`` from an Address; ``default_port`` when none is written.

    Raises ``ValueError`` with a sentence when the text is not an address.
    """
    text = address.strip()
    if not text:
        raise ValueError("the Address is empty")
    host, port_text = text, ""
    if text.startswith("["):
        closing = text.find("]")
        if closing < 0:
            raise ValueError(f"the Address {address!r} opens '[' without closing it")
        host, rest = text[1:closing], text[closing + 1:]
        if rest:
            if not rest.startswith(":"):
                raise ValueError(f"the Address {address!r} has {rest!r} after ']'")
            port_text = rest[1:]
    elif text.count(":") == 1:
        host, port_text = text.split(":")
    if not host or any(c.isspace() for c in host):
        raise ValueError(f"the Address {address!r} has no usable host name")
    if not port_text:
        return host, default_port
    if not is_digits(port_text) or not 0 < int(port_text) < 65536:
        raise ValueError(f"the port in the Address {address!r} must be a number 1-65535")
    return host, int(port_text)


def is_local(host: str) -> bool:
    """True for this computer: ``127.x.x.x``, ``::1`` or ``localhost``."""
    if host.lower() in LOCAL_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


__all__ = ["is_local", "split_address"]
