"""Checking ``ClientAllow``: every entry an address or network, none open to the internet.

A station's clients sit on its own computers and its own network.  An entry
that reaches beyond the private networks, such as ``"127.0.0.1/0"`` (a typo
that means *every* address), lets anyone who can reach the port switch the
station's antennas; it is allowed (a remote operator may need it) but warned
about.  A single public address (one remote computer) is not warned about.
"""

from __future__ import annotations

import ipaddress

from . import model as m
from .reading import Reading

PRIVATE_NETWORKS = tuple(ipaddress.ip_network(text) for text in (
    "127.0.0.0/8", "10.0.0.0/8", "172.16.0.0/12", "192.168.0.0/16", "169.254.0.0/16",
    "100.64.0.0/10", "::1/128", "fe80::/10", "fc00::/7",
))
"""Loopback, private (RFC 1918, RFC 6598 shared, IPv6 unique-local) and link-local."""


def _is_private(network: ipaddress.IPv4Network | ipaddress.IPv6Network) -> bool:
    return any(network.version == private.version and network.subnet_of(private)  # type: ignore[arg-type]
               for private in PRIVATE_NETWORKS)


def allow_problems(config: m.Config, reading: Reading) -> None:
    """Errors for entries that are not networks, warnings for entries open to the internet."""
    for allowed in config.client_allow or ():
        where = reading.at(config, "ClientAllow", allowed)
        try:
            network = ipaddress.ip_network(allowed, strict=False)
        except ValueError:
            reading.error(where, f"\"ClientAllow\" has \"{allowed}\", which is not an address "
                                 "or network such as 192.168.1.0/24")
            continue
        if network.num_addresses == 1 or _is_private(network):
            continue
        reach = ("every address of the internet" if network.prefixlen == 0 else
                 f"{network.num_addresses:,} addresses outside the private networks")
        host = allowed.split("/")[0]
        hint = ""
        if "/" in allowed and ipaddress.ip_address(host) != network.network_address:
            hint = f" (for one computer write \"{host}\")"
        reading.warning(where, f"\"ClientAllow\" has \"{allowed}\", which lets in {reach} "
                               f"({network}){hint}; anyone who reaches the port can switch "
                               "antennas: allow single addresses or a private network such "
                               "as 192.168.1.0/24")


__all__ = ["PRIVATE_NETWORKS", "allow_problems"]
