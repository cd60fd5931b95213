"""Helpers for ``scripts/screenshots.sh``: the server to photograph, and a logger to feed it.

``serve ARGS``     runs ``moas-server ARGS`` with the N1MM Logger socket bound to the
                   ``--bind`` address (127.0.0.1) instead of every address.
``n1mm PORT``      plays N1MM Logger on 127.0.0.1: station 1's radio tunes across a few
                   bands, so the server logs antenna changes.
``client PORT SECONDS``  a client on 127.0.0.1:PORT that says hello, then stays connected
                   for SECONDS (the status bar counts it).
``free-port KIND [PORT]``  prints PORT when that ``udp`` or ``tcp`` port of 127.0.0.1 is
                   free, or else any free one.
``geometry NAME``  prints ``X Y W H`` of the largest visible window whose title contains
                   NAME (``geometry-class NAME``: whose class is NAME), using xdotool.
``tray-menu``      prints ``X Y W H`` of the server's open tray menu.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import socket
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def serve(argv: list[str]) -> int:
    from moas_gui.cli import server as cli

    original = cli._options

    def loopback_options(args: argparse.Namespace) -> object:
        return dataclasses.replace(original(args), udp_bind=args.bind)  # type: ignore[type-var]

    cli._options = loopback_options  # type: ignore[assignment]
    return cli.main(argv)


def n1mm(port: int) -> int:
    from moas_gui.sources.n1mm_packet import radio_info_packet

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for khz in (14025.0, 7012.0, 21030.0, 14210.0):
            udp.sendto(radio_info_packet(1, khz, station_name="RUN-PC"), ("127.0.0.1", port))
            time.sleep(0.4)
    return 0


def client(port: int, seconds: float) -> int:
    """A client that says hello as the station's button box would, then stays a while."""
    hello = {"id": 1, "cmd": "hello", "client": "button box", "station": 2, "radio": 1}
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall((json.dumps(hello) + "\n").encode())
        conn.settimeout(0.2)
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                if not conn.recv(65536):
                    break
            except TimeoutError:
                continue
    return 0


def free_port(kind: str, preferred: int = 0) -> int:
    family = socket.SOCK_DGRAM if kind == "udp" else socket.SOCK_STREAM
    for port in dict.fromkeys((preferred, 0)):
        with socket.socket(socket.AF_INET, family) as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                continue
            print(probe.getsockname()[1])
            return 0
    return 1


def _windows(how: str, name: str) -> list[tuple[str, tuple[int, int, int, int]]]:
    """(title, (X, Y, W, H)) of every visible window matching NAME (``--name`` or ``--class``)."""
    found = subprocess.run(["xdotool", "search", "--onlyvisible", how, name],
                           capture_output=True, text=True, check=False).stdout.split()
    windows = []
    for window in found:
        shape = subprocess.run(["xdotool", "getwindowgeometry", "--shell", window],
                               capture_output=True, text=True, check=False).stdout
        values = dict(line.split("=", 1) for line in shape.split() if "=" in line)
        title = subprocess.run(["xdotool", "getwindowname", window],
                               capture_output=True, text=True, check=False).stdout.strip()
        if {"X", "Y", "WIDTH", "HEIGHT"} <= values.keys():
            box = (int(values["X"]), int(values["Y"]), int(values["WIDTH"]), int(values["HEIGHT"]))
            windows.append((title, box))
    return windows


def geometry(how: str, name: str) -> int:
    """Print ``X Y W H`` of the largest visible window matching NAME."""
    shapes = [box for _, box in _windows(how, name)]
    if not shapes:
        print(f"screenshot_tray: no visible window with {how[2:]} {name!r}", file=sys.stderr)
        return 1
    print(*max(shapes, key=lambda s: s[2] * s[3]))
    return 0


def tray_menu() -> int:
    """Print ``X Y W H`` of the server's open pop-up menu (its windows minus the main one and
    the tray icon, which is no taller than the tray)."""
    shapes = [box for title, box in _windows("--class", "moas-server")
              if "MOAS Server" not in title and box[3] > 40]
    if not shapes:
        print("screenshot_tray: the tray menu is not open", file=sys.stderr)
        return 1
    print(*max(shapes, key=lambda s: s[2] * s[3]))
    return 0


def main() -> int:
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    command, rest = sys.argv[1], sys.argv[2:]
    if command == "serve":
        return serve(rest)
    if command == "n1mm" and rest:
        return n1mm(int(rest[0]))
    if command == "client" and len(rest) == 2:
        return client(int(rest[0]), float(rest[1]))
    if command == "free-port" and rest and rest[0] in ("udp", "tcp"):
        return free_port(rest[0], int(rest[1]) if len(rest) > 1 else 0)
    if command == "geometry" and rest:
        return geometry("--name", rest[0])
    if command == "geometry-class" and rest:
        return geometry("--class", rest[0])
    if command == "tray-menu":
        return tray_menu()
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
