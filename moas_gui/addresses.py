"""``HOST[:PORT]`` as people write it: ``shack-pc``, ``10.0.0.5:12060``,
``[fe80::1]:12059`` or a bare IPv6 address ``::1``.  Used for the
configuration's rotator ``Address`` and for ``moas-client HOST[:PORT]``."""

from __future__ import annotations

import sys
from dataclasses import dataclass


def split_address(text: str, default_port: int) -> tuple[str, int]:
    """``(host, port)`` from ``text``, ``default_port`` when none is written.

    Raises ``ValueError`` with a sentence naming what is wrong.
    """
    text = text.strip()
    if not text:
        raise ValueError("the address is empty")
    host, port_text, port_written = text, "", False
    if text.startswith("["):
        closing = text.find("]")
        if closing < 0:
            raise ValueError(f"{text!r}: the '[' of an IPv6 address has no ']'")
        host, rest = text[1:closing], text[closing + 1:]
        if rest:
            if not rest.startswith(":"):
                raise ValueError(f"{text!r}: expected ':PORT' after ']', found {rest!r}")
            port_text, port_written = rest[1:], True
    elif text.count(":") == 1:
        host, port_text = text.split(":")
        port_written = True
    if not host or any(c.isspace() for c in host):
        raise ValueError(f"{text!r}: the host name is empty or has spaces")
    if not port_written:
        return host, default_port
    if not port_text:
        raise ValueError(f"{text!r}: the port after ':' is empty")
    if not (port_text.isascii() and port_text.isdigit()) or not 0 < int(port_text) < 65536:
        raise ValueError(f"{text!r}: the port {port_text!r} is not a number from 1 to 65535")
    return host, int(port_text)


__all__ = ["ANY_ADDRESS", "WebPage", "interface_addresses", "listen_addresses", "network_address",
           "reachable_addresses", "split_address"]


def network_address() -> str:
    """This computer's address on its network, as another computer there would reach it
    (the one the system would send from towards a private address; nothing is sent), or
    ``127.0.0.1`` when it has none."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.connect(("10.255.255.255", 9))
            address = str(probe.getsockname()[0])
        except OSError:
            return "127.0.0.1"
    return address if address != "0.0.0.0" else "127.0.0.1"


ANY_ADDRESS = ("0.0.0.0", "", "::")
"""The bind addresses that mean every interface."""


def _linux_ipv4(names: list[str]) -> list[str]:
    """Each named interface's IPv4 address (Linux's SIOCGIFADDR), those that have one."""
    if sys.platform != "linux":
        return []
    import fcntl
    import socket
    import struct

    found: list[str] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        for name in names:
            request = struct.pack("256s", name.encode()[:15])
            try:
                answer = fcntl.ioctl(probe.fileno(), 0x8915, request)  # SIOCGIFADDR
            except OSError:  # no IPv4 address on it
                continue
            found.append(socket.inet_ntoa(answer[20:24]))
    return found


def _linux_ipv6() -> list[str]:
    """The IPv6 addresses of /proc/net/if_inet6 (link-local ones left out)."""
    import ipaddress
    from pathlib import Path

    try:
        lines = Path("/proc/net/if_inet6").read_text(encoding="ascii").splitlines()
    except OSError:
        return []
    found = []
    for line in lines:
        hex_digits = line.split()[0] if line.split() else ""
        try:
            address = ipaddress.IPv6Address(int(hex_digits, 16))
        except ValueError:
            continue
        if not address.is_link_local:
            found.append(str(address))
    return found


def interface_addresses() -> list[str]:
    """This computer's addresses, every interface's (loopback ones included), IPv4 first:
    what a server listening on every interface (``0.0.0.0``) can be reached at."""
    import socket

    found: list[str] = ["127.0.0.1"]
    if sys.platform == "linux":
        found += _linux_ipv4([name for _index, name in socket.if_nameindex()])
        found += _linux_ipv6()
    else:  # elsewhere: what the host name resolves to, and the routed address
        try:
            infos = socket.getaddrinfo(socket.gethostname(), None)
        except OSError:
            infos = []
        found += [str(info[4][0]).split("%")[0] for info in infos]
        found.append(network_address())
    unique = list(dict.fromkeys(found))
    return sorted(unique, key=lambda a: ":" in a)


def listen_addresses(bind: str) -> list[str]:
    """The addresses a server bound to ``bind`` listens on: every interface's IPv4
    address for ``0.0.0.0``, every address for ``::`` (and ``""``), else ``bind``."""
    if bind == "0.0.0.0":  # IPv4's every interface
        return [a for a in interface_addresses() if ":" not in a]
    return interface_addresses() if bind in ANY_ADDRESS else [bind]


def reachable_addresses(bind: str) -> list[str]:
    """Of :func:`listen_addresses`, those another computer (a phone) can reach: no
    loopback, no link-local address."""
    import ipaddress

    reachable = []
    for text in listen_addresses(bind):
        try:
            address = ipaddress.ip_address(text)
        except ValueError:  # a host name given as the bind address: others may resolve it
            reachable.append(text)
            continue
        if not (address.is_loopback or address.is_link_local or address.is_unspecified):
            reachable.append(text)
    return reachable


@dataclass(frozen=True, slots=True)
class WebPage:
    """The browser page as served: the address it is bound to, its port, whether over TLS,
    and its certificate's SHA-256 fingerprint (None without TLS)."""

    bind: str
    port: int
    tls: bool
    fingerprint: str | None = None

    @property
    def reachable(self) -> list[str]:
        """The addresses a phone on the station's network can open it at (none when it
        listens on loopback only)."""
        return reachable_addresses(self.bind)
