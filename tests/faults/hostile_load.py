"""A hostile load against a real server process, and a legitimate client measuring its
service meanwhile: shared by ``test_fault_hostile_load.py`` (small counts, a few
seconds) and ``benchmarks/bench_hostile_load.py`` (the full figures of issue 20).

The attacker uses the source addresses 127.0.0.2 to 127.0.0.4 in turn; the legitimate
client is on 127.0.0.1.  Three kinds of attack run at once for ``hold`` seconds:

* **idle**: connections to the client port that never send a byte; each one the server
  closes is opened again a second later;
* **slowloris**: connections to the web port that send half an HTTP request, then one
  more header line every two seconds, never the blank line that ends it; reopened
  likewise;
* **malformed**: HTTP requests the parser refuses (no Host, two Host headers, a URL
  over 8 KB, ``*`` as the URL), spread over the hold.

Every half second the legitimate client connects to the client port, says ``hello``
and waits for the reply, and loads the page on a connection of its own; each try is
served or not, and its time is kept (:class:`Service`).
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import os
import re
import resource
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field

ATTACKERS = ("127.0.0.2", "127.0.0.3", "127.0.0.4")
LEGIT = "127.0.0.1"
MALFORMED = (
    b"GET / HTTP/1.1\r\n\r\n",
    b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: 127.0.0.1\r\n\r\n",
    b"GET /" + b"a" * 8300 + b" HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
    b"GET * HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
)


def limit_files(count: int) -> Callable[[], None]:
    """A ``preexec_fn`` giving a child process ``count`` file handles, soft and hard
    (so that the server cannot raise its own limit)."""
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, (count, count))
    return apply


def open_files(pid: int) -> int:
    return len(os.listdir(f"/proc/{pid}/fd"))


def resident_mb(pid: int) -> float:
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


@dataclass
class Service:
    """The legitimate client's tries: the seconds each took, None when it failed."""

    hellos: list[float | None] = field(default_factory=list)
    pages: list[float | None] = field(default_factory=list)
    failures: list[str] = field(default_factory=list)

    @staticmethod
    def served(tries: list[float | None], within: float = float("inf")) -> float:
        """The share of ``tries`` that succeeded (within ``within`` seconds)."""
        good = [t for t in tries if t is not None and t <= within]
        return len(good) / len(tries) if tries else 0.0

    @staticmethod
    def slowest(tries: list[float | None]) -> float:
        times = [t for t in tries if t is not None]
        return max(times) if times else float("nan")


@dataclass
class Attack:
    """Counts of what the attacker did."""

    opened: int = 0
    refused_or_closed: int = 0
    failed_to_open: int = 0
    malformed_sent: int = 0


async def _hold_idle(port: int, source: str, until: float, attack: Attack) -> None:
    loop = asyncio.get_running_loop()
    while loop.time() < until:
        try:
            reader, writer = await asyncio.open_connection(LEGIT, port, local_addr=(source, 0))
        except OSError:
            attack.failed_to_open += 1
            await asyncio.sleep(1.0)
            continue
        attack.opened += 1
        try:
            with contextlib.suppress(OSError, TimeoutError):
                async with asyncio.timeout(max(until - loop.time(), 0)):
                    await reader.read()  # nothing is ever sent; this ends when the server closes
            if loop.time() < until:
                attack.refused_or_closed += 1
        finally:
            writer.transport.abort()
        await asyncio.sleep(1.0)


async def _slowloris(port: int, source: str, until: float, attack: Attack) -> None:
    loop = asyncio.get_running_loop()
    while loop.time() < until:
        try:
            reader, writer = await asyncio.open_connection(LEGIT, port, local_addr=(source, 0))
        except OSError:
            attack.failed_to_open += 1
            await asyncio.sleep(1.0)
            continue
        attack.opened += 1
        try:
            writer.write(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n")
            for n in itertools.count():
                if loop.time() >= until:
                    break
                with contextlib.suppress(TimeoutError):
                    async with asyncio.timeout(2.0):
                        if not await reader.read(65536):
                            attack.refused_or_closed += 1
                            break
                        continue
                writer.write(f"X-Slow-{n}: {n}\r\n".encode())
        except OSError:
            attack.refused_or_closed += 1
        finally:
            writer.transport.abort()
        await asyncio.sleep(1.0)


async def _malformed(port: int, count: int, until: float, attack: Attack) -> None:
    loop = asyncio.get_running_loop()
    spacing = max(until - loop.time(), 0.1) / max(count, 1) * 0.8

    async def one(index: int) -> None:
        source = ATTACKERS[index % len(ATTACKERS)]
        with contextlib.suppress(OSError, TimeoutError):
            reader, writer = await asyncio.open_connection(LEGIT, port, local_addr=(source, 0))
            try:
                writer.write(MALFORMED[index % len(MALFORMED)])
                attack.malformed_sent += 1
                async with asyncio.timeout(5.0):
                    await reader.read()
            finally:
                writer.transport.abort()

    tasks = []
    for index in range(count):
        tasks.append(asyncio.ensure_future(one(index)))
        await asyncio.sleep(spacing)
    await asyncio.gather(*tasks)


async def _hello_once(port: int) -> float:
    started = time.perf_counter()
    reader, writer = await asyncio.open_connection(LEGIT, port)
    try:
        writer.write(b'{"id": 1, "cmd": "hello", "client": "legit"}\n')
        while True:
            line = await reader.readline()
            if not line:
                raise ConnectionError("closed before the hello reply")
            message = json.loads(line)
            if message.get("id") == 1 and "event" not in message:
                if not message.get("ok"):
                    raise ConnectionError(f"refused: {message}")
                return time.perf_counter() - started
    finally:
        writer.close()
        with contextlib.suppress(OSError, TimeoutError):
            async with asyncio.timeout(1.0):
                await writer.wait_closed()


async def _page_once(port: int) -> float:
    started = time.perf_counter()
    reader, writer = await asyncio.open_connection(LEGIT, port)
    try:
        writer.write(f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n"
                     .encode())
        data = await reader.read()
        if not data.startswith(b"HTTP/1.1 200") or b"</html>" not in data:
            raise ConnectionError(f"not the page: {data[:60]!r}")
        return time.perf_counter() - started
    finally:
        writer.close()
        with contextlib.suppress(OSError, TimeoutError):
            async with asyncio.timeout(1.0):
                await writer.wait_closed()


async def _legit(tcp: int, web: int, until: float, service: Service, patience: float) -> None:
    loop = asyncio.get_running_loop()

    async def timed(kind: str, attempt: Callable[[], object], into: list[float | None]) -> None:
        try:
            async with asyncio.timeout(patience):
                into.append(await attempt())  # type: ignore[misc]
        except (OSError, TimeoutError, ValueError) as exc:
            into.append(None)
            service.failures.append(f"{kind}: {type(exc).__name__}: {exc}")

    running: list[asyncio.Future[None]] = []
    while loop.time() < until:
        running.append(asyncio.ensure_future(timed("hello", lambda: _hello_once(tcp),
                                                    service.hellos)))
        running.append(asyncio.ensure_future(timed("page", lambda: _page_once(web),
                                                    service.pages)))
        await asyncio.sleep(0.5)
    await asyncio.gather(*running)


async def attack_only(tcp: int, web: int, *, idle: int, slow: int, malformed: int,
                      hold: float) -> Attack:
    """The attack alone, for ``hold`` seconds."""
    until = asyncio.get_running_loop().time() + hold
    done = Attack()
    tasks = [asyncio.ensure_future(_hold_idle(tcp, ATTACKERS[i % 3], until, done))
             for i in range(idle)]
    tasks += [asyncio.ensure_future(_slowloris(web, ATTACKERS[i % 3], until, done))
              for i in range(slow)]
    tasks.append(asyncio.ensure_future(_malformed(web, malformed, until, done)))
    await asyncio.gather(*tasks)
    return done


async def legit_only(tcp: int, web: int, hold: float, patience: float = 10.0) -> Service:
    """The legitimate client alone, for ``hold`` seconds."""
    service = Service()
    await _legit(tcp, web, asyncio.get_running_loop().time() + hold, service, patience)
    return service


async def attack(tcp: int, web: int, *, idle: int, slow: int, malformed: int, hold: float,
                 patience: float = 10.0) -> tuple[Service, Attack]:
    """Runs the attack for ``hold`` seconds with the legitimate client beside it, both in
    this process (the benchmark runs the attack in a process of its own instead, so that
    the legitimate client's times are the server's, not the attacker's loop's)."""
    attacking = asyncio.ensure_future(
        attack_only(tcp, web, idle=idle, slow=slow, malformed=malformed, hold=hold))
    await asyncio.sleep(0.5)  # the crowd arrives first
    service = await legit_only(tcp, web, hold - 0.5, patience)
    return service, await attacking


def main() -> None:
    """``python hostile_load.py TCP WEB IDLE SLOW MALFORMED HOLD``: the attack alone, in a
    process of its own; prints what it did as one JSON line at the end."""
    tcp, web, idle, slow, malformed = (int(arg) for arg in sys.argv[1:6])
    _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    done = asyncio.run(attack_only(tcp, web, idle=idle, slow=slow, malformed=malformed,
                                   hold=float(sys.argv[6])))
    print(json.dumps(done.__dict__))


_PARTICULARS = re.compile(r'\d+(\.\d+)*|"[^"]*"')
_STAMP = re.compile(r"^\d\d:\d\d:\d\d \w+ +(.*)$")


def trouble_kinds(lines: list[str]) -> dict[str, int]:
    """The server's log lines that are not about the legitimate client, by kind (numbers,
    addresses and names blanked out), with how many lines each kind wrote."""
    kinds: dict[str, int] = {}
    for line in lines:
        if '"legit"' in line or f"{LEGIT}:" in line:
            continue
        stamped = _STAMP.match(line)
        message = stamped.group(1) if stamped else line
        kind = _PARTICULARS.sub("#", message)[:120]
        kinds[kind] = kinds.get(kind, 0) + 1
    return kinds


__all__ = ["ATTACKERS", "LEGIT", "Attack", "Service", "attack", "attack_only", "legit_only",
           "limit_files", "open_files", "resident_mb", "trouble_kinds"]


if __name__ == "__main__":
    main()
