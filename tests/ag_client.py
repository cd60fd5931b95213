"""A small Antenna Genius client for the tests, written from 4O3A's public description
of the protocol (docs/antenna-genius.md): it reads the greeting, sends ``C<seq>|...``
lines with the line ending a test chooses, collects ``R<seq>|...`` answers (a list up
to its empty terminator) and keeps every ``S0|...`` status line that arrives."""

from __future__ import annotations

import asyncio
from dataclasses import dataclass, field


@dataclass
class Answer:
    code: int
    lines: list[str] = field(default_factory=list)
    """The messages of every ``R`` line of the answer (a list's terminator not included)."""

    @property
    def message(self) -> str:
        return self.lines[0] if self.lines else ""


def fields(line: str) -> dict[str, str]:
    """``key=value`` words of a line."""
    return dict(w.split("=", 1) for w in line.split() if "=" in w)


class AgClient:
    def __init__(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                 greeting: str) -> None:
        self.reader, self.writer = reader, writer
        self.greeting = greeting
        self.seq = 0
        self.statuses: list[str] = []
        self._pending: list[str] = []

    @classmethod
    async def connect(cls, port: int, host: str = "127.0.0.1",
                      local: str | None = None) -> AgClient:
        """``local``: the address to connect from (``127.0.0.2`` plays a LAN computer)."""
        reader, writer = await asyncio.open_connection(
            host, port, local_addr=None if local is None else (local, 0))
        greeting = (await asyncio.wait_for(reader.readline(), 10)).decode().strip()
        return cls(reader, writer, greeting)

    async def line(self, timeout: float = 10.0) -> str:
        raw = await asyncio.wait_for(self.reader.readline(), timeout)
        if not raw:
            raise ConnectionError("the server closed the connection")
        return raw.decode().rstrip("\r\n")

    async def send(self, command: str, ending: bytes = b"\r") -> int:
        self.seq += 1
        self.writer.write(f"C{self.seq}|{command}".encode() + ending)
        await self.writer.drain()
        return self.seq

    async def reply(self, seq: int, listing: bool = False) -> Answer:
        """The answer to ``seq``: one ``R`` line, or (``listing``) every line up to the
        empty terminator; status lines met meanwhile are kept in :attr:`statuses`."""
        answer: Answer | None = None
        while True:
            text = await self.line()
            if text.startswith("S0|"):
                self.statuses.append(text[3:])
                continue
            head, _, message = text.partition("|")
            code, _, message = message.partition("|")
            assert head == f"R{seq}", f"expected R{seq}, got {text!r}"
            if answer is None:
                answer = Answer(int(code, 16))
            if not listing or answer.code != 0:  # an error is one line, with no terminator
                answer.lines.append(message)
                return answer
            if message == "":
                return answer
            answer.lines.append(message)

    async def ask(self, command: str, listing: bool = False, ending: bytes = b"\r") -> Answer:
        return await self.reply(await self.send(command, ending), listing)

    async def status(self, prefix: str, timeout: float = 10.0) -> str:
        """The next status line starting with ``prefix`` (those kept count first)."""
        loop = asyncio.get_running_loop()
        end = loop.time() + timeout
        while True:
            for i, text in enumerate(self.statuses):
                if text.startswith(prefix):
                    del self.statuses[i]
                    return text
            text = await self.line(max(0.05, end - loop.time()))
            assert text.startswith("S0|"), f"unexpected {text!r}"
            self.statuses.append(text[3:])

    async def closed(self, timeout: float = 10.0) -> bool:
        """True once the server has closed the connection (lines meanwhile are dropped)."""
        try:
            while await asyncio.wait_for(self.reader.readline(), timeout):
                pass
        except TimeoutError:
            return False
        except ConnectionError:
            return True
        return True

    async def close(self) -> None:
        self.writer.close()
        try:
            await self.writer.wait_closed()
        except (ConnectionError, OSError):
            pass
