"""Serve the client protocol over the fake backend, for client authors and benchmarks.

``python -m moas_gui.testing.fake_server [--host 127.0.0.1] [--port 12059] [--max-per-address N]``
prints ``port N`` on its first line once it listens, then serves the
demonstration station of :mod:`moas_gui.testing.fake_station` until interrupted.
No switch, engine or configuration file is involved.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys

from moas_gui.aio import CleanStop, run_until_stopped
from moas_gui.edge.admission import DEFAULT_PER_ADDRESS
from moas_gui.net.server import DEFAULT_PORT, ClientServer

from .fake_backend import FakeBackend


async def serve(host: str, port: int, per_address: int = DEFAULT_PER_ADDRESS) -> None:
    backend = FakeBackend()
    server = ClientServer(backend, host=host, port=port, per_address=per_address)
    backend.attach(server)
    bound = await server.start()
    stop = asyncio.Event()
    with CleanStop(stop.set):  # before the port is told: a stop from then on is clean
        print(f"port {bound}", flush=True)
        try:
            await stop.wait()
        finally:
            await server.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT, help="TCP port (0: any)")
    parser.add_argument("--log", default="INFO", help="log level (DEBUG, INFO, WARNING)")
    parser.add_argument("--max-per-address", type=int, default=DEFAULT_PER_ADDRESS,
                        help="connections one address may hold (a benchmark's crowd of "
                             f"clients on one computer needs more than {DEFAULT_PER_ADDRESS})")
    args = parser.parse_args(argv)
    logging.basicConfig(level=args.log.upper(), stream=sys.stderr,
                        format="%(asctime)s %(levelname)s %(message)s")
    return run_until_stopped(serve(args.host, args.port, args.max_per_address))


if __name__ == "__main__":
    sys.exit(main())
