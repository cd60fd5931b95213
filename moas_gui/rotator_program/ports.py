"""Which ports a ``CONFIGURE`` may open: serial devices, and what the user allowed.

The MOAS Rotator program opens whatever port the server names, through pyserial,
which also opens URLs (``socket://host:port`` connects anywhere, ``loop://``) and
any file.  Whoever controls the program must not make it do that, so a port is
opened only when it is

* a serial device: ``COM3`` (``\\\\.\\COM12``) on Windows; elsewhere a path that is, or
  leads by links to, a terminal device: ``/dev/ttyUSB0``, ``/dev/ttyACM0``,
  ``/dev/ttyS0``, ``/dev/cu.usbserial-...``, ``/dev/rfcomm0``, a pseudo-terminal
  (``/dev/pts/3``, ``/dev/ttys004``), ``/dev/serial/by-id/...`` -- a path that
  exists must be a character device; one that does not exist yet (an adapter not
  plugged in) is opened when it appears;
* or allowed by the user: ``moas-rotator --allow PATTERN`` (repeatable; shell-style
  ``*`` and ``?``, e.g. ``socket://10.0.0.5:4001`` or ``socket://10.0.0.5:*``).  The
  server that starts the program allows the ``CommPort`` of each of its ``.moas``
  file's rotators, ``socket://`` ports included.

A speed suffix (``COM3@4800``) is not part of the name judged.
"""

from __future__ import annotations

import fnmatch
import os
import re
import stat
from collections.abc import Iterable

from .serial_link import split_port

_WINDOWS_PORT = re.compile(r"(\\\\\.\\)?COM\d{1,3}", re.IGNORECASE)
_DEVICE = re.compile(
    r"/dev/(tty(USB|ACM|S|AMA|THS|XRUSB|mxc|SAC|O|AP|GS)?\d+|ttys\d+|cu\.[^/]+|tty\.[^/]+"
    r"|pts/\d+|rfcomm\d+|serial/(by-id|by-path)/[^/]+)"
)
"""Terminal devices by name (the real path, after links)."""
_NOT_SERIAL = re.compile(r"/dev/tty\d+")
"""Virtual consoles: terminals, but not serial ports."""


def allowed_by(port: str, allow: Iterable[str]) -> bool:
    """Whether ``port`` (or its name without a speed) matches a pattern of ``allow``."""
    name = split_port(port)[0]
    return any(fnmatch.fnmatchcase(port, p) or fnmatch.fnmatchcase(name, p) for p in allow)


def _device_refusal(name: str) -> str | None:
    real = os.path.realpath(name)
    if _NOT_SERIAL.fullmatch(real) or not _DEVICE.fullmatch(real):
        shown = name if real == name else f"{name} (which leads to {real})"
        return f"{shown} is not a serial device"
    try:
        info = os.stat(real)
    except FileNotFoundError:
        return None  # an adapter not plugged in yet: the driver opens it when it appears
    except OSError as error:
        return f"{name} cannot be examined ({error.strerror or error})"
    if not stat.S_ISCHR(info.st_mode):
        return f"{name} is not a device"
    return None


def port_refusal(port: str, allow: Iterable[str] = ()) -> str | None:
    """Why ``CONFIGURE`` may not open ``port`` (one sentence), or ``None`` when it may."""
    if allowed_by(port, allow):
        return None
    name = split_port(port)[0]
    hint = "only serial devices, and what moas-rotator --allow names, may be opened"
    if "://" in name:
        return f"port {name!r} is a URL; {hint}"
    if _WINDOWS_PORT.fullmatch(name):
        return None
    if os.name == "nt" or not name.startswith("/"):
        return f"port {name!r} is not a serial port name such as COM3 or /dev/ttyUSB0; {hint}"
    refusal = _device_refusal(name)
    return None if refusal is None else f"port {refusal}; {hint}"


__all__ = ["allowed_by", "port_refusal"]
