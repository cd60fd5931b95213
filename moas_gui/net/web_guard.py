"""Who may load the browser client and drive the switch through it: pure functions.

Two checks come on top of ``ClientAllow`` (which the web server applies to
every request, as the client server does to every connection):

the Host header
    must name this computer: an IP address, ``localhost``, or the computer's
    own name (as the operating system reports it, with or without its domain,
    or with ``.local``).  A page on another site that makes its own name point
    at a station computer (DNS rebinding) sends that other name and is refused.
the Origin header of a WebSocket
    a browser always sends the page's origin with a WebSocket; it must be
    exactly an origin the page is served from: ``http://`` (the server serves
    no ``https``), the host and port of the Host header (the port 80 may be
    left out of either), nothing more, and one Origin header only.  A page
    from anywhere else on the network is refused:
    browsers let any page open a WebSocket to any address, so without this a
    web page read on the shack computer could press buttons.  A connection
    without an Origin is not a browser, and is judged by ``ClientAllow`` alone,
    as a TCP client is.
"""

from __future__ import annotations

import ipaddress
import socket
from collections.abc import Sequence
from urllib.parse import urlsplit

__all__ = ["host_allowed", "local_names", "origin_complaint", "split_host"]


def local_names() -> frozenset[str]:
    """The names this computer answers to, lower case."""
    names = {"localhost"}
    for name in (socket.gethostname(), socket.getfqdn()):
        name = name.strip().lower().rstrip(".")
        if name:
            names.add(name)
            short = name.split(".", 1)[0]
            names.add(short)
            names.add(short + ".local")
    return frozenset(names)


def split_host(host: str) -> tuple[str, str]:
    """``(name, port)`` of a Host header value (``[::1]:8080`` -> ``("::1", "8080")``);
    the port is ``""`` when absent."""
    host = host.strip().lower()
    if host.startswith("["):
        end = host.find("]")
        if end < 0:
            return host, ""
        rest = host[end + 1 :]
        return host[1:end], rest[1:] if rest.startswith(":") else ""
    if host.count(":") == 1:
        name, port = host.split(":")
        return name, port
    return host, ""


def host_allowed(host: str | None, names: frozenset[str]) -> bool:
    """Whether a request's Host header names this computer (see the module notes)."""
    if not host:
        return False
    name, port = split_host(host)
    if port and not port.isdigit():
        return False
    name = name.rstrip(".")
    try:
        ipaddress.ip_address(name.split("%", 1)[0])
        return True
    except ValueError:
        return name in names


def _with_port(host: str, scheme: str = "http") -> tuple[str, str]:
    name, port = split_host(host)
    return name.rstrip("."), port or ("443" if scheme == "https" else "80")


def origin_complaint(origins: str | Sequence[str] | None, host: str | None,
                     scheme: str = "http") -> str | None:
    """Why a WebSocket with these Origin headers (a request's every Origin header, or
    the one) may not use this server, or ``None`` when it may.  ``scheme``: what the
    server serves, ``http`` or (with TLS) ``https``."""
    if origins is None:
        return None
    if not isinstance(origins, str):
        if not origins:
            return None
        if len(origins) > 1:
            return f"it sent {len(origins)} Origin headers; a browser sends one"
        origins = origins[0]
    origin = origins
    shown = origin if len(origin) <= 80 else origin[:77] + "..."
    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        return f"its Origin {shown!r} is not an address"
    if parts.scheme != scheme or not parts.netloc or parts.path or parts.query \
            or parts.fragment or "@" in parts.netloc:
        return (f"its Origin {shown!r} is not a web page of this server (it serves "
                f"{scheme}:// only)")
    if host is None or _with_port(parts.netloc, scheme) != _with_port(host, scheme):
        return (f"it comes from a page of another site ({shown}); only the page this server "
                "serves may use it")
    return None
