"""Where the example run can be seen working: the web page's address and the client command.

    python scripts/example_addresses.py FILE.moas [server options...]

Prints on standard output the options scripts/run-example.sh adds so that the browser
page is served (``--web-port 8080`` when neither the options nor the file name a web
port), one a line; prints on standard error, for the person who started the run, the
page's address and the command that opens the desktop client, with the address the
server listens on (``--bind``; 127.0.0.1 reaches this computer only, and the message
says how to let a phone in).
"""

from __future__ import annotations

import argparse
import socket
import sys

from moas_gui.config import load_config

DEFAULT_WEB_PORT = 8080


def _addresses() -> list[str]:
    """This computer's own IPv4 addresses other than loopback, as far as it can tell."""
    found: list[str] = []
    try:
        infos = socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)
    except OSError:
        return found
    for info in infos:
        address = str(info[4][0])
        if not address.startswith("127.") and address not in found:
            found.append(address)
    return found


def notice(bind: str, tcp_port: int, web_port: int, tls: bool) -> list[str]:
    scheme = "https" if tls else "http"
    if bind in ("0.0.0.0", "::", ""):
        hosts = _addresses() or ["<this computer's address>"]
    else:
        hosts = [bind]
    lines = ["run-example: the station can be seen working:"]
    for host in hosts:
        lines.append(f"  web page:        {scheme}://{host}:{web_port}/  (open it in a browser)")
    tls_option = " --tls" if tls else ""
    lines.append(f"  desktop client:  .venv/bin/moas-client{tls_option} {hosts[0]}:{tcp_port}")
    if bind.startswith("127.") or bind in ("localhost", "::1"):
        lines.append("  (this computer only; to let phones and other computers in, run it again "
                     "with --bind 0.0.0.0, and see docs/security.md)")
    return lines


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(add_help=False)
    parser.add_argument("file")
    parser.add_argument("--bind", default="0.0.0.0")
    parser.add_argument("--tcp-port", type=int)
    parser.add_argument("--web-port", type=int)
    parser.add_argument("--tls", action="store_true")
    args, _rest = parser.parse_known_args(argv)
    config = load_config(args.file).config
    tcp_port = args.tcp_port or (config.tcp_port if config is not None else 12059)
    web_port = args.web_port or (config.web_port if config is not None else None)
    if web_port is None:
        web_port = DEFAULT_WEB_PORT
        print("--web-port")
        print(DEFAULT_WEB_PORT)
    for line in notice(args.bind, tcp_port, web_port, args.tls):
        print(line, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
