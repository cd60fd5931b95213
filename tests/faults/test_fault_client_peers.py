"""The client port's peers misbehaving while a band change is in flight, against the
real server process: a client that never reads, one that sends garbage, one that sends
half a line and vanishes, one that resets its connection; an N1MM Logger packet changes
band in the middle of it all.  The band change still reaches the switch, a well-behaved
client is told it, and each misbehaving client that is dropped costs one Info line in
the log (the client's fault, not the server's: nothing at Warning)."""

from __future__ import annotations

import asyncio
import json
import socket
import struct
from pathlib import Path

from fault_harness import (
    FAULT_MARKS,
    QUICK_SAVES,
    Client,
    ScriptedSwitch,
    Station,
    holds_what_the_engine_says,
)
from helpers import EXAMPLES, until

from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = FAULT_MARKS


def raw(port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", port))
    return sock


async def test_misbehaving_clients_do_not_stop_a_band_change(tmp_path: Path) -> None:
    switch = ScriptedSwitch(tmp_path / "moas1").plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(switch.link)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    station = Station.make(tmp_path, data, save_delay=QUICK_SAVES)
    server = await station.server("--no-rotator-program")
    sockets: list[socket.socket] = []
    try:
        client = await Client.connect(station.tcp, server)
        station.logger(radio_info_packet(1, 14025.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        mark, told = len(server.lines), len(client.told)

        deaf = raw(station.tcp)  # asks for everything, never reads a byte
        deaf.sendall(b'{"cmd": "hello", "client": "deaf"}\n' + b'{"cmd": "state"}\n' * 2000)
        sockets.append(deaf)
        noisy = raw(station.tcp)
        sockets.append(noisy)
        half = raw(station.tcp)
        sockets.append(half)
        reset = raw(station.tcp)
        sockets.append(reset)
        sock_port = {id(sock): sock.getsockname()[1] for sock in sockets}
        await asyncio.sleep(0.1)

        # the band change goes out while the peers misbehave
        station.logger(radio_info_packet(1, 7020.0))
        noisy.sendall(b"\x00\xff garbage {not json\n" + b'{"cmd": 12}\n' + b"]]]]\n" * 5)
        half.sendall(b'{"id": 1, "cmd": "sel')  # half a request ...
        half.close()  # ... and gone
        reset.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        reset.sendall(b'{"id": 1, "cmd": "state"}\n')
        reset.close()  # a reset, not a goodbye
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        await until(lambda: any(m["khz"] == 7020.0 for m in client.events("radio", told)),
                    what="the well-behaved client told of the band change")
        # ... and the next band change too, with the deaf client still there
        station.logger(radio_info_packet(1, 21030.0))
        await holds_what_the_engine_says(station, client, lambda: switch.relays)
        assert (await client.state())["switches"] == [{"id": 1, "status": "ok"}]

        after = server.lines[mark:]
        assert server.problems(mark) == [], server.text(mark)  # the clients' fault, not ours
        assert not any("Traceback" in line for line in after)
        for sock, why in ((noisy, "bad lines in a row"), (half, "disconnected"),
                          (reset, "connection lost")):
            said = [line for line in after
                    if f":{sock_port[id(sock)]} " in line and "connected from" not in line]
            assert len(said) == 1 and why in said[0], (why, said)
        await client.close()
    finally:
        for sock in sockets:
            sock.close()
        await server.end()
        switch.unplug()
