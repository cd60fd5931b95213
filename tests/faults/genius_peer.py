"""A Rotator Genius in a process of its own (the project's emulator on 127.0.0.1),
so a fault test can kill it and start it again: ``python genius_peer.py PORT``."""

from __future__ import annotations

import asyncio
import sys

from moas_gui.testing.genius_server import GeniusModel, GeniusServer


async def serve(port: int) -> None:
    server = GeniusServer(GeniusModel(speed=60.0), port=port)
    await server.start()
    print(f"Rotator Genius emulator on 127.0.0.1:{server.port}", file=sys.stderr, flush=True)
    await asyncio.Event().wait()


if __name__ == "__main__":
    asyncio.run(serve(int(sys.argv[1])))
