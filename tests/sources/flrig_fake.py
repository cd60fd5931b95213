"""A small stand-in for flrig's XML-RPC server, over real HTTP on loopback.

flrig itself is a window program; this answers the methods the flrig source
asks (see moas_gui/sources/flrig_rpc.py) from a dictionary the test changes,
the values typed as flrig's own server types them (frequencies as strings of
Hz, split and PTT as integers, the active VFO as "A" or "B").  ``close_each``
makes it answer ``Connection: close`` and close, as an HTTP/1.0 server would;
``garbage`` replaces every answer by those bytes.
"""

from __future__ import annotations

import asyncio
import xmlrpc.client


class FakeFlrig:
    def __init__(self) -> None:
        self.rig: dict[str, object] = {"vfoA": 14070000, "vfoB": 14075000, "AB": "A",
                                       "split": 0, "ptt": 0}
        self.calls: list[str] = []
        self.close_each = False
        self.garbage: bytes | None = None
        self.connections = 0
        self._server: asyncio.Server | None = None
        self.port = 0
        self._writers: set[asyncio.StreamWriter] = set()

    def answer(self, method: str) -> object:
        rig = self.rig
        active = rig["vfoA"] if rig["AB"] == "A" else rig["vfoB"]
        table: dict[str, object] = {
            "rig.get_vfo": str(active), "rig.get_vfoA": str(rig["vfoA"]),
            "rig.get_vfoB": str(rig["vfoB"]), "rig.get_AB": rig["AB"],
            "rig.get_split": rig["split"], "rig.get_ptt": rig["ptt"],
        }
        if method not in table:
            raise xmlrpc.client.Fault(1, f"unknown method {method}")
        return table[method]

    async def start(self, port: int = 0) -> int:
        self._server = await asyncio.start_server(self._serve, "127.0.0.1", port)
        self.port = int(self._server.sockets[0].getsockname()[1])
        return self.port

    async def close(self) -> None:
        if self._server is not None:
            self._server.close()
            for writer in list(self._writers):
                writer.close()
            await self._server.wait_closed()
            self._server = None

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        self.connections += 1
        self._writers.add(writer)
        try:
            while True:
                head = await reader.readuntil(b"\r\n\r\n")
                length = 0
                for line in head.decode("latin-1").split("\r\n"):
                    if line.lower().startswith("content-length:"):
                        length = int(line.split(":", 1)[1])
                _, method = xmlrpc.client.loads(await reader.readexactly(length))
                self.calls.append(str(method))
                if self.garbage is not None:
                    writer.write(self.garbage)
                    await writer.drain()
                    continue
                try:
                    body = xmlrpc.client.dumps((self.answer(str(method)),), methodresponse=True)
                except xmlrpc.client.Fault as fault:
                    body = xmlrpc.client.dumps(fault, methodresponse=True)
                data = body.encode()
                close = "Connection: close\r\n" if self.close_each else ""
                writer.write(f"HTTP/1.1 200 OK\r\nServer: XMLRPC++ 0.8\r\n{close}"
                             f"Content-Type: text/xml\r\nContent-length: {len(data)}\r\n\r\n"
                             .encode() + data)
                await writer.drain()
                if self.close_each:
                    break
        except (asyncio.IncompleteReadError, ConnectionError):
            pass
        finally:
            self._writers.discard(writer)
            writer.close()
