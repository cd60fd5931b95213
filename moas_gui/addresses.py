"""``HOST[:PORT]`` as people write it: ``shack-pc``, ``10.0.0.5:12060``,
``[fe80::1]:12059`` or a bare IPv6 address ``::1``.  Used for the
configuration's rotator ``Address`` and for ``moas-client HOST[:PORT]``."""

from __future__ import annotations


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


__all__ = ["network_address", "split_address"]


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
