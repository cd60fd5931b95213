"""A FlexRadio stand-in on loopback, written from the public SmartSDR TCP/IP API text.

:class:`FlexRadio` serves the API on TCP (``V<version>`` and ``H<handle>`` on
connect, ``C<seq>|command`` answered ``R<seq>|<hex>|message``, statuses
``S<handle>|...`` pushed to the connections that subscribed) and sends the
radio's VITA-49 discovery datagrams over UDP (:meth:`FlexRadio.announce`).

Test hooks: :meth:`set_slice` / :meth:`remove_slice` (a slice tuned, moved to
transmit, closed), :meth:`set_interlock` (keyed, unkeyed), :meth:`drop` (every
connection cut: the radio rebooted), :meth:`stop` / :meth:`start` (the radio
gone and back on the same port), ``commands`` (every command each connection
sent, for asserting that nothing changed the radio), ``keepalive_timeout``
(a client that enabled keepalive and is silent this long is cut, as the radio
does), ``send_raw`` (any bytes to every connection: garbage, a malformed line).

``python -m moas_gui.testing.flex_radio [--port 4992]`` runs one with two slices
(A on 14.025 MHz transmitting, B on 21.025 MHz) and announces it every second.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import itertools
import logging
import socket
import struct
from dataclasses import dataclass, field

API_PORT = 4992
"""The API's TCP port, and the UDP port discovery datagrams go to."""
MAX_LINE = 8192

log = logging.getLogger(__name__)

ERROR_UNKNOWN: int = 0x50000015
"""The answer code the stand-in gives a command it does not know."""

_SLICE_ORDER = ("in_use", "RF_frequency", "mode", "tx", "active", "rxant", "txant",
                "index_letter", "client_handle")


@dataclass(slots=True)
class _Client:
    handle: int
    writer: asyncio.StreamWriter
    subs: set[str] = field(default_factory=set)
    keepalive: bool = False
    last_heard: float = 0.0


class FlexRadio:
    """The stand-in radio (see the module notes)."""

    def __init__(self, *, host: str = "127.0.0.1", port: int = 0, model: str = "FLEX-6600",
                 serial: str = "1234-5678-9012-3456", nickname: str = "Shack",
                 callsign: str = "W1AW", version: str = "1.4.0.0",
                 keepalive_timeout: float = 10.0) -> None:
        self.host = host
        self.port = port
        self.model = model
        self.serial = serial
        self.nickname = nickname
        self.callsign = callsign
        self.version = version
        self.keepalive_timeout = keepalive_timeout
        self.slices: dict[int, dict[str, str]] = {}
        self.interlock = "READY"
        self.gui_handle = 0x2A3B4C5D
        """The handle of the GUI client that owns the slices (a SmartSDR elsewhere)."""
        self.commands: list[str] = []
        """Every command received, in order, without ``C<seq>|``."""
        self.connections = 0
        self._clients: list[_Client] = []
        self._handles = itertools.count(0x10000001)
        self._server: asyncio.Server | None = None
        self._watch: asyncio.Task[None] | None = None

    # -- running ---------------------------------------------------------------------------
    async def start(self) -> int:
        self._server = await asyncio.start_server(self._serve, self.host, self.port)
        self.port = self._server.sockets[0].getsockname()[1]
        self._watch = asyncio.get_running_loop().create_task(self._keepalive())
        return self.port

    async def stop(self) -> None:
        """The radio is gone: no listener, every connection cut."""
        server, self._server = self._server, None
        if server is not None:
            server.close()
        self.drop()
        if server is not None:
            await server.wait_closed()
        if self._watch is not None:
            self._watch.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._watch
            self._watch = None

    def drop(self) -> None:
        for client in self._clients:
            client.writer.close()
        self._clients.clear()

    @property
    def client_count(self) -> int:
        return len(self._clients)

    # -- what a test changes ------------------------------------------------------------------
    def set_slice(self, index: int, **changes: object) -> None:
        """Slice ``index`` changes (``RF_frequency=7.0125``, ``tx=1``...); a new slice is in
        use with letter A, B... unless told; subscribers hear the change."""
        fields = {k: _text(v) for k, v in changes.items()}
        if index not in self.slices or self.slices[index].get("in_use") != "1":
            base = {"in_use": "1", "RF_frequency": "14.025000", "mode": "CW", "tx": "0",
                    "active": "0", "rxant": "ANT1", "txant": "ANT1",
                    "index_letter": chr(ord("A") + index),
                    "client_handle": f"0x{self.gui_handle:08X}"}
            base.update(fields)
            self.slices[index] = base
            fields = base
        else:
            self.slices[index].update(fields)
        if fields.get("tx") == "1":
            for other, values in self.slices.items():
                if other != index and values.get("tx") == "1":
                    values["tx"] = "0"
                    self._push("slice", f"slice {other} tx=0")
        self._push("slice", f"slice {index} " + _words(fields))

    def remove_slice(self, index: int) -> None:
        self.slices.pop(index, None)
        self._push("slice", f"slice {index} in_use=0")

    def set_interlock(self, state: str) -> None:
        self.interlock = state
        self._push("tx", self._interlock_text())

    def send_raw(self, data: bytes) -> None:
        for client in self._clients:
            client.writer.write(data)

    def announcement(self) -> dict[str, str]:
        return {"discovery_protocol_version": "3.0.0.2", "model": self.model,
                "serial": self.serial, "version": "3.4.35.141", "nickname": self.nickname,
                "callsign": self.callsign, "ip": self.host, "port": str(self.port),
                "status": "Available"}

    def announce(self, to: tuple[str, int]) -> None:
        """One discovery datagram to ``to`` (a radio broadcasts it every second)."""
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
            sock.sendto(discovery_datagram(self.announcement()), to)

    # -- the API --------------------------------------------------------------------------------
    def _interlock_text(self) -> str:
        tx = next((v["client_handle"] for v in self.slices.values() if v.get("tx") == "1"),
                  "0x00000000")
        return f"interlock tx_client_handle={tx} state={self.interlock} reason= source= " \
               "tx_allowed=1 amplifier="

    def _push(self, topic: str, text: str) -> None:
        for client in self._clients:
            if topic in client.subs:
                client.writer.write(f"S{client.handle:08X}|{text}\n".encode("ascii"))

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        loop = asyncio.get_running_loop()
        client = _Client(next(self._handles), writer, last_heard=loop.time())
        self._clients.append(client)
        self.connections += 1
        writer.write(f"V{self.version}\nH{client.handle:08X}\n".encode("ascii"))
        try:
            while True:
                raw = await reader.readline()
                if not raw or len(raw) > MAX_LINE:
                    break
                client.last_heard = loop.time()
                self._command(client, raw.decode("ascii", "replace").strip())
                await writer.drain()
        except (ConnectionError, asyncio.LimitOverrunError, ValueError):
            pass
        finally:
            if client in self._clients:
                self._clients.remove(client)
            writer.close()

    def _command(self, client: _Client, line: str) -> None:
        head, bar, text = line.partition("|")
        if not bar or not head.startswith("C") or not head[1:].lstrip("D").isdigit():
            return  # the radio ignores what is not a command
        seq = int(head[1:].lstrip("D"))
        self.commands.append(text)
        words = text.split()
        code, message = 0, ""
        if words[:2] == ["sub", "slice"]:
            client.subs.add("slice")
            for index, values in sorted(self.slices.items()):
                self._write(client, f"slice {index} " + _words(values))
        elif words[:2] == ["sub", "tx"]:
            client.subs.add("tx")
            self._write(client, self._interlock_text())
        elif words[:2] == ["keepalive", "enable"]:
            client.keepalive = True
        elif words[:1] == ["ping"] or words[:2] == ["client", "program"]:
            pass
        else:
            code, message = ERROR_UNKNOWN, "Unknown command"
        client.writer.write(f"R{seq}|{code:X}|{message}\n".encode("ascii"))

    def _write(self, client: _Client, text: str) -> None:
        client.writer.write(f"S{client.handle:08X}|{text}\n".encode("ascii"))

    async def _keepalive(self) -> None:
        loop = asyncio.get_running_loop()
        while True:
            await asyncio.sleep(min(1.0, self.keepalive_timeout / 4))
            now = loop.time()
            for client in list(self._clients):
                if client.keepalive and now - client.last_heard > self.keepalive_timeout:
                    log.info("test radio: client 0x%08X silent; cut", client.handle)
                    self._clients.remove(client)
                    client.writer.close()


def discovery_datagram(fields: dict[str, str], count: int = 0) -> bytes:
    """A discovery datagram as the radio sends it: a VITA-49 extension packet with a
    stream id (0x800) and a class id (OUI 0x001C2D, information class 0x534C, packet
    class 0xFFFF), both timestamps, then the ``key=value`` words padded with NULs to a
    whole 32-bit word; big-endian, its size in words in the header."""
    payload = " ".join(f"{k}={v}" for k, v in fields.items()).encode("ascii")
    payload += bytes(-len(payload) % 4)
    header = struct.pack(">BBH", 0x38, 0x50 | (count & 0x0F), (28 + len(payload)) // 4)
    ids = struct.pack(">IIIIQ", 0x800, 0x001C2D, 0x534CFFFF, 0, 0)
    return header + ids + payload


def _text(value: object) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return f"{value:.6f}"
    return str(value)


def _words(fields: dict[str, str]) -> str:
    keys = [k for k in _SLICE_ORDER if k in fields] + [k for k in fields if k not in _SLICE_ORDER]
    return " ".join(f"{k}={fields[k]}" for k in keys)


async def _main(port: int, every: float) -> None:
    radio = FlexRadio(host="127.0.0.1", port=port)
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1, active=1)
    radio.set_slice(1, RF_frequency=21.025)
    print(f"test FlexRadio on 127.0.0.1:{radio.port}; Ctrl+C ends it", flush=True)
    while True:
        radio.announce(("127.255.255.255", API_PORT))
        await asyncio.sleep(every)


def main() -> None:
    parser = argparse.ArgumentParser(prog="python -m moas_gui.testing.flex_radio")
    parser.add_argument("--port", type=int, default=API_PORT)
    parser.add_argument("--every", type=float, default=1.0,
                        help="seconds between two discovery datagrams")
    args = parser.parse_args()
    with contextlib.suppress(KeyboardInterrupt):
        asyncio.run(_main(args.port, args.every))


if __name__ == "__main__":
    main()
