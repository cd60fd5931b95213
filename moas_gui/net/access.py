"""Who may connect to the client protocol server: pure functions, no sockets.

Without a ``ClientAllow`` key the server accepts the networks a station's own
computers live on and nothing else (:data:`DEFAULT_ALLOW`): loopback,
the private IPv4 ranges of RFC 1918, IPv4 link-local, IPv6 link-local and
unique-local addresses.  A ``ClientAllow`` list (addresses such as
``"203.0.113.7"`` or networks such as ``"192.168.1.0/24"``) replaces that
default entirely; an empty list lets nobody in.

A peer address is compared as the operating system reports it, after two
normalisations: an IPv6 zone (``fe80::1%eth0``) is dropped, and an
IPv4-mapped IPv6 address (``::ffff:192.168.1.20``, what a dual-stack socket
reports for an IPv4 client) is compared as the IPv4 address it carries.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable

IPNetwork = ipaddress.IPv4Network | ipaddress.IPv6Network
IPAddress = ipaddress.IPv4Address | ipaddress.IPv6Address

DEFAULT_ALLOW_TEXT: tuple[str, ...] = (
    "127.0.0.0/8",  # IPv4 loopback
    "::1/128",  # IPv6 loopback
    "10.0.0.0/8",  # RFC 1918
    "172.16.0.0/12",  # RFC 1918
    "192.168.0.0/16",  # RFC 1918
    "169.254.0.0/16",  # IPv4 link-local
    "fe80::/10",  # IPv6 link-local
    "fc00::/7",  # IPv6 unique local addresses
)
"""The networks accepted when the configuration has no ``ClientAllow``."""


def parse_allow_list(entries: Iterable[str]) -> tuple[IPNetwork, ...]:
    """Networks from address or network strings; a bare address is a network of one.

    Host bits are forgiven (``"192.168.1.7/24"`` means ``192.168.1.0/24``).
    Raises :class:`ValueError` naming the first entry that is neither
    (:class:`TypeError` for an entry that is not even a string).
    """
    networks: list[IPNetwork] = []
    for entry in entries:
        if not isinstance(entry, str):
            raise TypeError(f"ClientAllow entry {entry!r} is not a string")
        try:
            networks.append(ipaddress.ip_network(entry.strip(), strict=False))
        except ValueError:
            raise ValueError(
                f"ClientAllow entry {entry!r} is not an address or network "
                "such as 192.168.1.0/24"
            ) from None
    return tuple(networks)


DEFAULT_ALLOW: tuple[IPNetwork, ...] = parse_allow_list(DEFAULT_ALLOW_TEXT)


def allowed_networks(client_allow: Iterable[str] | None) -> tuple[IPNetwork, ...]:
    """The configuration's ``ClientAllow`` as networks; ``None`` gives :data:`DEFAULT_ALLOW`."""
    return DEFAULT_ALLOW if client_allow is None else parse_allow_list(client_allow)


def peer_address(address: str) -> IPAddress | None:
    """The address to judge for a peer as a socket reports it, or ``None`` when
    it is not an IP address at all."""
    try:
        parsed = ipaddress.ip_address(address.strip())
    except ValueError:
        return None
    if isinstance(parsed, ipaddress.IPv6Address):
        if parsed.ipv4_mapped is not None:
            return parsed.ipv4_mapped
        if parsed.scope_id is not None:
            return ipaddress.IPv6Address(int(parsed))
    return parsed


def is_allowed(address: str, allowed: Iterable[IPNetwork] = DEFAULT_ALLOW) -> bool:
    """Whether a peer at ``address`` may connect; something that is not an IP
    address never may."""
    parsed = peer_address(address)
    if parsed is None:
        return False
    return any(parsed.version == net.version and parsed in net for net in allowed)


__all__ = [
    "DEFAULT_ALLOW",
    "DEFAULT_ALLOW_TEXT",
    "IPAddress",
    "IPNetwork",
    "allowed_networks",
    "is_allowed",
    "parse_allow_list",
    "peer_address",
]
