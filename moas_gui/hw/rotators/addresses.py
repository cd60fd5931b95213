"""``Address`` strings of the configuration: ``host``, ``host:port`` or ``[v6]:port``."""

from __future__ import annotations

import ipaddress

from moas_gui.addresses import split_address

LOCAL_NAMES = frozenset({"localhost", "localhost.localdomain"})


def is_local(host: str) -> bool:
    """True for this computer: ``127.x.x.x``, ``::1`` or ``localhost``."""
    if host.lower() in LOCAL_NAMES:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


__all__ = ["is_local", "split_address"]
