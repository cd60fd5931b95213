"""Serial port names written for another system.

A ``.moas`` file made on a Windows station names ``"COM8"``; run on a Linux tower
computer, the switch would never answer, and the only clue would be a port that cannot
be opened.  :func:`check_port_names` warns at the name itself and says what this system
calls such a port.  The names are only looked at, never opened (the configuration does
no I/O); the system is a parameter, so every combination is tested on any one.
"""

from __future__ import annotations

import re
import sys
from typing import Final

from .model import Config
from .reading import Reading

_WINDOWS: Final = re.compile(r"(\\\\\.\\)?COM[1-9][0-9]*", re.IGNORECASE)
_LINUX: Final = re.compile(r"/dev/(tty(USB|ACM|S|AMA)[0-9]+|serial/.+|ttyTHS[0-9]+)")
_MACOS: Final = re.compile(r"/dev/(cu|tty)\.[A-Za-z].*")

_SYSTEM_NAMES: Final = {"win32": "Windows", "darwin": "macOS", "linux": "Linux"}

WHAT_IT_IS_CALLED: Final = {
    "win32": "Windows calls serial ports COM1, COM2 ... (Device Manager, under "
             "\"Ports (COM & LPT)\")",
    "darwin": "macOS calls them /dev/cu.usbserial-XXXX or /dev/cu.usbmodemXXXX "
              "(list them with: ls /dev/cu.*)",
    "linux": "Linux calls them /dev/ttyUSB0, /dev/ttyACM0 or /dev/ttyS0, and "
             "/dev/serial/by-id/... names them for good (list them with: "
             "ls -l /dev/serial/by-id/)",
}
LOOPBACK: Final = frozenset({"127.0.0.1", "localhost", "::1", ""})


def system_of(port: str) -> str | None:
    """The system whose device name ``port`` is ("win32", "linux", "darwin"), or None
    for anything else ("emulator", a name this module does not know)."""
    name = port.strip()
    if _WINDOWS.fullmatch(name):
        return "win32"
    if _LINUX.fullmatch(name):
        return "linux"
    if _MACOS.fullmatch(name):
        return "darwin"
    return None


def _family(platform: str) -> str:
    return "linux" if platform.startswith(("linux", "freebsd", "openbsd", "netbsd")) \
        else platform


def foreign_port(port: str, platform: str = sys.platform) -> str | None:
    """What to tell when ``port`` is another system's name on ``platform``, or None."""
    owner = system_of(port)
    here = _family(platform)
    if owner is None or owner == here or here not in WHAT_IT_IS_CALLED:
        return None
    return (f"\"{port.strip()}\" is a {_SYSTEM_NAMES[owner]} port name, and this computer "
            f"runs {_SYSTEM_NAMES[here]}: {WHAT_IT_IS_CALLED[here]}. Was this file made on "
            "another computer?")


def check_port_names(config: Config, reading: Reading, platform: str = sys.platform) -> None:
    """Warn at every port of ``config`` this computer would open that is named for another
    system: the switches' ``Port``, the OTRSP entries' ``Port`` and the ``CommPort`` of a
    serial rotator whose MOAS Rotator program runs on this computer."""
    for switch in config.switches:
        told = foreign_port(switch.port, platform)
        if told:
            reading.warning(reading.at(switch, "Port"), f"switch {switch.id}: {told}")
    for entry in config.otrsp:
        told = foreign_port(entry.port, platform)
        if told:
            reading.warning(reading.at(entry, "Port"), f"the OTRSP entry: {told}")
    for rotator in config.rotators:
        if rotator.comm_port and rotator.address.strip().casefold() in LOOPBACK:
            told = foreign_port(rotator.comm_port, platform)
            if told:
                reading.warning(reading.at(rotator, "CommPort"),
                                f"rotator {rotator.id} (its MOAS Rotator runs on this "
                                f"computer): {told}")


__all__ = ["WHAT_IT_IS_CALLED", "check_port_names", "foreign_port", "system_of"]
