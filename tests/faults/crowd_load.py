"""The crowds of issue 31 against a real server process, and the clients measuring their
service meanwhile (``benchmarks/bench_hostile_load.py --scenario crowds``).

Three crowds at once, for ``hold`` seconds, each connection opened again a second after
the server closes it:

* **greeted**: ``per`` connections from each of 127.0.0.2-127.0.0.8 to the client port
  that say ``hello`` and then send a blank line a minute (within the keepalive);
* **silent**: connections from as many addresses (127.0.1.x) that never say hello,
  opened again at once when closed;
* **rotctld**: idle connections to a rotctld-compatible port from 250 addresses
  (127.0.2.x), sending nothing.

Every half second a legitimate client on :data:`LEGIT` (another loopback address) says
``hello`` on a new connection and loads the page on another; with a token, an operator
on :data:`OPERATOR` says hello with it too.  Each try is served or not, and timed.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import resource
import sys
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass, field

GREETED_FROM = tuple(f"127.0.0.{n}" for n in range(2, 9))
LEGIT = "127.0.0.9"
OPERATOR = "127.0.0.10"


def silent_from(index: int) -> str:
    return f"127.0.1.{index % 250 + 1}"


def rotctld_from(index: int) -> str:
    return f"127.0.2.{index % 250 + 1}"


@dataclass
class Crowds:
    """What the crowds did."""

    opened: int = 0
    closed_by_server: int = 0
    failed_to_open: int = 0


@dataclass
class Tries:
    """Seconds each try took, ``None`` when it failed."""

    hellos: list[float | None] = field(default_factory=list)
    pages: list[float | None] = field(default_factory=list)
    operator: list[float | None] = field(default_factory=list)
    failures: list[str] = field(default_factory=list)


async def _connect(
    port: int, source: str, crowds: Crowds, host: str = "127.0.0.1"
) -> tuple[asyncio.StreamReader, asyncio.StreamWriter] | None:
    try:
        opened = await asyncio.open_connection(host, port, local_addr=(source, 0))
    except OSError:
        crowds.failed_to_open += 1
        return None
    crowds.opened += 1
    return opened


async def _hold(
    port: int, source: str, until: float, crowds: Crowds, *, hello: bool, again: float
) -> None:
    loop = asyncio.get_running_loop()
    while loop.time() < until:
        opened = await _connect(port, source, crowds)
        if opened is None:
            await asyncio.sleep(1.0)
            continue
        reader, writer = opened
        try:
            if hello:
                writer.write(b'{"id": 1, "cmd": "hello", "client": "crowd"}\n')
            while loop.time() < until:
                try:
                    async with asyncio.timeout(min(60.0, max(until - loop.time(), 0.01))):
                        if not await reader.read(65536):
                            crowds.closed_by_server += 1
                            break
                except TimeoutError:
                    if hello:
                        writer.write(b"\n")  # a blank line a minute: within the keepalive
        except OSError:
            crowds.closed_by_server += 1
        finally:
            writer.close()
        await asyncio.sleep(again)


async def crowds_only(
    tcp: int, rotctld: int, *, per: int, silent: int, idle: int, hold: float
) -> Crowds:
    until = asyncio.get_running_loop().time() + hold
    crowds = Crowds()
    tasks = [
        _hold(tcp, source, until, crowds, hello=True, again=1.0)
        for source in GREETED_FROM
        for _ in range(per)
    ]
    tasks += [
        _hold(tcp, silent_from(i), until, crowds, hello=False, again=0.0) for i in range(silent)
    ]
    tasks += [
        _hold(rotctld, rotctld_from(i), until, crowds, hello=False, again=1.0) for i in range(idle)
    ]
    await asyncio.gather(*tasks)
    return crowds


async def _hello_once(port: int, source: str, token: str | None = None) -> float:
    started = time.perf_counter()
    reader, writer = await asyncio.open_connection("127.0.0.1", port, local_addr=(source, 0))
    try:
        hello: dict[str, object] = {"id": 1, "cmd": "hello", "client": "legit"}
        if token is not None:
            hello["token"] = token
        writer.write(json.dumps(hello).encode() + b"\n")
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


async def _page_once(port: int, source: str) -> float:
    started = time.perf_counter()
    reader, writer = await asyncio.open_connection("127.0.0.1", port, local_addr=(source, 0))
    try:
        writer.write(
            f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nConnection: close\r\n\r\n".encode()
        )
        data = await reader.read()
        if not data.startswith(b"HTTP/1.1 200") or b"</html>" not in data:
            raise ConnectionError(f"not the page: {data[:60]!r}")
        return time.perf_counter() - started
    finally:
        writer.close()


async def legit(
    tcp: int, web: int, hold: float, token: str | None = None, patience: float = 5.0
) -> Tries:
    """The legitimate client (and the operator, with ``token``) every half second."""
    loop = asyncio.get_running_loop()
    until = loop.time() + hold
    tries = Tries()

    async def timed(
        kind: str, attempt: Callable[[], Awaitable[float]], into: list[float | None]
    ) -> None:
        try:
            async with asyncio.timeout(patience):
                into.append(await attempt())
        except (OSError, TimeoutError, ValueError) as exc:
            into.append(None)
            tries.failures.append(f"{kind}: {type(exc).__name__}: {exc}")

    running: list[asyncio.Future[None]] = []
    while loop.time() < until:
        running.append(
            asyncio.ensure_future(timed("hello", lambda: _hello_once(tcp, LEGIT), tries.hellos))
        )
        running.append(
            asyncio.ensure_future(timed("page", lambda: _page_once(web, LEGIT), tries.pages))
        )
        if token is not None:
            running.append(
                asyncio.ensure_future(
                    timed("operator", lambda: _hello_once(tcp, OPERATOR, token), tries.operator)
                )
            )
        await asyncio.sleep(0.5)
    await asyncio.gather(*running)
    with contextlib.suppress(Exception):
        await asyncio.sleep(0)
    return tries


def main() -> None:
    """``python crowd_load.py TCP ROTCTLD PER SILENT IDLE HOLD``: the crowds alone, in a
    process of their own; prints what they did as one JSON line at the end."""
    tcp, rotctld, per, silent, idle = (int(arg) for arg in sys.argv[1:6])
    _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
    done = asyncio.run(
        crowds_only(tcp, rotctld, per=per, silent=silent, idle=idle, hold=float(sys.argv[6]))
    )
    print(json.dumps(done.__dict__))


__all__ = ["GREETED_FROM", "LEGIT", "OPERATOR", "Crowds", "Tries", "crowds_only", "legit"]


if __name__ == "__main__":
    main()
