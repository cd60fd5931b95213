"""The attacks of issue 38 on the server's new edges, one scenario at a time, in a process
of their own (so that the measuring client's times are the server's, not this
process's).  Every attack comes from 127.x addresses only, is bounded in count and
rate, and stops after ``hold`` seconds; it prints what it did as one JSON line.

    python benchmarks/edge_attacks.py SCENARIO SETTINGS-JSON

``SETTINGS-JSON`` has the ports (``tcp``, ``web``, ``udp``, ``ag``), ``hold`` (seconds),
``key_id`` (the operator's key id, which every operator knows of itself), ``viewer`` (a
``view`` operator's token) and ``scale`` (1.0: the counts of issue 38; a smoke run
gives less).  Scenarios (issue 38's words):

``tls-silent``
    8, then 50 silent TCP connections from one address (127.0.0.2), then 50 from each of
    ten (127.0.0.2 and 127.0.0.20-28: never the measuring clients' .1 and .10), to the TLS client port and the HTTPS page; each reopened when the
    server closes it.
``report-span``
    a ``contactinfo`` dated 9999-12-31 from the logger's address, then a plain ``GET
    /report`` from loopback; and a ``view`` operator's
    ``/report?from=1000-01-01&to=3000-01-01`` (its token as a Bearer) from 127.0.0.11.
``known-id-guess``
    hellos carrying a real operator's key id and random secrets, 80 a second from one
    LAN address (127.0.0.2).
``ag-guess``
    ``auth code=N`` guesses on the Antenna Genius port from 200 addresses
    (127.0.1.1-200), each reconnecting when refused, 200 guesses a second in all.
``ag-crowd``
    a crowd of 200 addresses (127.0.2.1-200) holding 4 silent AG connections each,
    reopened when closed.
``ag-slow-reader``
    16 AG connections from loopback that ``sub port all`` and never read, while the
    logger's radio changes band 50 times a second (pushes to every subscriber).
``contact-flood``
    ``contactinfo`` datagrams (new QSOs, dated now) at 2,000 a second.
``log-flood``
    logger packets alternating ``ActiveRadioNr`` 1 and 2 at 2,000 a second; on the AG
    port, 1 MiB of binary from 127.0.0.2 every 5 s and wrong codes from 127.0.0.3, 20 a
    second.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import secrets
import socket
import sys
import time
from collections.abc import Awaitable, Callable
from datetime import UTC, datetime
from typing import Any

HOST = "127.0.0.1"
SCENARIOS = ("tls-silent", "report-span", "known-id-guess", "ag-guess", "ag-crowd",
             "ag-slow-reader", "contact-flood", "log-flood")


class Tally:
    """What an attack did, printed as JSON at the end."""

    def __init__(self) -> None:
        self.counts: dict[str, int] = {}
        self.notes: list[str] = []

    def add(self, what: str, n: int = 1) -> None:
        self.counts[what] = self.counts.get(what, 0) + n


async def paced(rate: float, until: float, act: Callable[[int], Awaitable[None]],
                in_flight: int = 100) -> None:
    """Calls ``act(i)`` ``rate`` times a second until the loop's time ``until``, at most
    ``in_flight`` at once (a slow server slows the attack instead of piling it up)."""
    loop = asyncio.get_running_loop()
    gate = asyncio.Semaphore(in_flight)
    tasks: set[asyncio.Task[None]] = set()
    start, i = loop.time(), 0
    while loop.time() < until:
        due = start + i / rate
        if due > loop.time():
            await asyncio.sleep(due - loop.time())
        await gate.acquire()

        async def one(n: int) -> None:
            try:
                await act(n)
            finally:
                gate.release()

        task = asyncio.ensure_future(one(i))
        tasks.add(task)
        task.add_done_callback(tasks.discard)
        i += 1
    for task in list(tasks):
        task.cancel()
    await asyncio.gather(*tasks, return_exceptions=True)


async def hold_open(port: int, source: str, until: float, tally: Tally,
                    greeting: bool = False) -> None:
    """One connection from ``source`` that sends nothing, reopened when the server
    closes it, until ``until``."""
    loop = asyncio.get_running_loop()
    while loop.time() < until:
        try:
            reader, writer = await asyncio.open_connection(HOST, port, local_addr=(source, 0))
        except OSError:
            tally.add("failed to open")
            await asyncio.sleep(0.5)
            continue
        tally.add("opened")
        try:
            async with asyncio.timeout(max(0.0, until - loop.time())):
                while await reader.read(65536):
                    pass
            tally.add("closed by the server")
        except (TimeoutError, OSError):
            pass
        finally:
            writer.close()
        await asyncio.sleep(0.2)


async def tls_silent(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + s["hold"]
    each = max(1, round(50 * s["scale"]))
    phases = [(max(1, round(8 * s["scale"])), ["127.0.0.2"]), (each, ["127.0.0.2"]),
              (each, ["127.0.0.2", *(f"127.0.0.{n}" for n in range(20, 29))])]
    holders: list[asyncio.Task[None]] = []
    for number, (count, sources) in enumerate(phases):
        phase_end = loop.time() + s["hold"] / 3 if number < 2 else end
        holders += [asyncio.ensure_future(hold_open(port, source, phase_end, tally))
                    for source in sources for port in (s["tcp"], s["web"])
                    for _ in range(count)]
        await asyncio.sleep(max(0.0, phase_end - loop.time()))
    await asyncio.gather(*holders)


def contact_packet(when: str, call: str, ident: str) -> bytes:
    return (f'<?xml version="1.0" encoding="utf-8"?>\r\n<contactinfo><app>N1MM</app>'
            f"<contestname>CQWWCW</contestname><timestamp>{when}</timestamp>"
            f"<mycall>K1XX</mycall><band>14</band><rxfreq>1402500</rxfreq>"
            f"<txfreq>1402500</txfreq><operator>K1XX</operator><mode>CW</mode>"
            f"<call>{call}</call><radionr>1</radionr><NetworkedCompNr>0</NetworkedCompNr>"
            f"<IsOriginal>True</IsOriginal><NetBiosName>BENCH</NetBiosName>"
            f"<StationName>BENCH</StationName><ID>{ident}</ID>"
            f"<IsClaimedQso>True</IsClaimedQso></contactinfo>").encode()


def radio_packet(khz: float, active: int = 1, radio: int = 1) -> bytes:
    return (f'<?xml version="1.0" encoding="utf-8"?>\r\n<RadioInfo><app>N1MM</app>'
            f"<StationName>BENCH</StationName><RadioNr>{radio}</RadioNr>"
            f"<Freq>{round(khz * 100)}</Freq><TXFreq>{round(khz * 100)}</TXFreq>"
            f"<Mode>CW</Mode><OpCall>K1XX</OpCall><IsRunning>False</IsRunning>"
            f"<FocusRadioNr>1</FocusRadioNr><IsStereo>False</IsStereo>"
            f"<IsSplit>False</IsSplit><ActiveRadioNr>{active}</ActiveRadioNr>"
            f"<IsTransmitting>False</IsTransmitting></RadioInfo>").encode()


async def get(port: int, path: str, source: str, timeout: float,
              token: str | None = None) -> str:
    """``GET path`` over plain HTTP; the status line, or what went wrong."""
    started = time.perf_counter()
    try:
        async with asyncio.timeout(timeout):
            reader, writer = await asyncio.open_connection(HOST, port, local_addr=(source, 0))
            bearer = f"Authorization: Bearer {token}\r\n" if token else ""
            writer.write(f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n{bearer}"
                         "Connection: close\r\n\r\n".encode())
            head = (await reader.readline()).decode(errors="replace").strip()
            while await reader.read(1 << 16):
                pass
            writer.close()
            return f"{head or 'closed'} after {time.perf_counter() - started:.1f} s"
    except (OSError, TimeoutError) as exc:
        return f"{type(exc).__name__} after {time.perf_counter() - started:.1f} s"


async def report_span(s: dict[str, Any], tally: Tally) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.bind((HOST, 0))
        udp.sendto(contact_packet("9999-12-31 23:59:00", "K9FAR", secrets.token_hex(16)),
                   (HOST, s["udp"]))
    tally.add("datagrams")
    await asyncio.sleep(0.5)
    plain, span = await asyncio.gather(
        get(s["web"], "/report", HOST, s["hold"]),
        get(s["web"], "/report?from=1000-01-01&to=3000-01-01", "127.0.0.11", s["hold"],
            s["viewer"]))
    tally.notes += [f"GET /report from loopback: {plain}",
                    f"a view operator's 1000-3000 report: {span}"]


async def known_id_guess(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()

    async def guess(_: int) -> None:
        token = f"moas1.{s['key_id']}.{secrets.token_urlsafe(32)}"
        try:
            async with asyncio.timeout(10):
                reader, writer = await asyncio.open_connection(HOST, s["tcp"],
                                                               local_addr=("127.0.0.2", 0))
                writer.write(json.dumps({"id": 1, "cmd": "hello", "client": "guess",
                                         "token": token}).encode() + b"\n")
                while line := await reader.readline():
                    if json.loads(line).get("id") == 1:
                        break
                writer.close()
            tally.add("guesses answered")
        except (OSError, TimeoutError, ValueError):
            tally.add("guesses not answered")

    await paced(80 * s["scale"], loop.time() + s["hold"], guess)


async def ag_session(port: int, source: str) -> tuple[asyncio.StreamReader,
                                                      asyncio.StreamWriter]:
    reader, writer = await asyncio.open_connection(HOST, port, local_addr=(source, 0))
    await asyncio.wait_for(reader.readline(), 10)  # the greeting
    return reader, writer


async def ag_guess(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + s["hold"]
    addresses = max(1, round(200 * s["scale"]))
    rate_each = 200 * s["scale"] / addresses

    async def guesser(index: int) -> None:
        source = f"127.0.1.{index + 1}"
        code = index * 5000
        while loop.time() < end:
            try:
                reader, writer = await ag_session(s["ag"], source)
            except (OSError, TimeoutError):
                tally.add("refused at connect")
                await asyncio.sleep(1.0)
                continue
            try:
                while loop.time() < end:
                    code += 1
                    writer.write(f"C{code}|auth code={code % 1_000_000:06d}\r".encode())
                    answer = await asyncio.wait_for(reader.readline(), 10)
                    if not answer:
                        break
                    tally.add("guesses")
                    if b"|0|" in answer:
                        tally.add("codes accepted")
                    await asyncio.sleep(1.0 / rate_each)
            except (OSError, TimeoutError):
                pass
            finally:
                writer.close()
            tally.add("closed by the server")

    await asyncio.gather(*(guesser(i) for i in range(addresses)))


async def ag_crowd(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + s["hold"]
    addresses = max(1, round(200 * s["scale"]))
    await asyncio.gather(*(hold_open(s["ag"], f"127.0.2.{i + 1}", end, tally)
                           for i in range(addresses) for _ in range(4)))


async def ag_slow_reader(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + s["hold"]
    held = []
    for _ in range(16):
        reader, writer = await ag_session(s["ag"], HOST)
        sock = writer.get_extra_info("socket")
        with contextlib.suppress(OSError):
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        writer.write(b"C1|sub port all\r")
        held.append((reader, writer))
        tally.add("subscribers")
    reader_transports = [w.transport for _, w in held]
    for transport in reader_transports:
        transport.pause_reading()  # never read again
    bands = (14025.0, 21025.0, 7025.0, 28025.0)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.bind((HOST, 0))
        udp.setblocking(False)

        async def change(i: int) -> None:
            udp.sendto(radio_packet(bands[i % len(bands)]), (HOST, s["udp"]))
            tally.add("band changes")

        await paced(50 * s["scale"], end, change)
    for _, writer in held:
        writer.close()


async def contact_flood(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        udp.bind((HOST, 0))
        udp.setblocking(False)

        async def contact(i: int) -> None:
            now = datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S")
            with contextlib.suppress(BlockingIOError):
                udp.sendto(contact_packet(now, f"K{i % 10}A{i % 26:02d}", f"{i:032x}"),
                           (HOST, s["udp"]))
                tally.add("datagrams")

        await paced(2000 * s["scale"], loop.time() + s["hold"], contact)


async def log_flood(s: dict[str, Any], tally: Tally) -> None:
    loop = asyncio.get_running_loop()
    end = loop.time() + s["hold"]

    async def focus_flood() -> None:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
            udp.bind((HOST, 0))
            udp.setblocking(False)

            async def packet(i: int) -> None:
                with contextlib.suppress(BlockingIOError):
                    udp.sendto(radio_packet(14025.0, active=1 + i % 2), (HOST, s["udp"]))
                    tally.add("focus packets")

            await paced(2000 * s["scale"], end, packet)

    async def binary() -> None:
        while loop.time() < end:
            try:
                _, writer = await ag_session(s["ag"], "127.0.0.2")
                writer.write(os.urandom(1 << 20))
                await writer.drain()
                tally.add("binary MiB")
                writer.close()
            except (OSError, TimeoutError):
                tally.add("binary refused")
            await asyncio.sleep(5.0)

    async def wrong_codes() -> None:
        async def one(i: int) -> None:
            try:
                reader, writer = await ag_session(s["ag"], "127.0.0.3")
                writer.write(f"C1|auth code={i:06d}\r".encode())
                await asyncio.wait_for(reader.readline(), 10)
                writer.close()
                tally.add("wrong codes")
            except (OSError, TimeoutError):
                tally.add("wrong codes refused")

        await paced(20 * s["scale"], end, one)

    await asyncio.gather(focus_flood(), binary(), wrong_codes())


ATTACKS: dict[str, Callable[[dict[str, Any], Tally], Awaitable[None]]] = {
    "tls-silent": tls_silent, "report-span": report_span, "known-id-guess": known_id_guess,
    "ag-guess": ag_guess, "ag-crowd": ag_crowd, "ag-slow-reader": ag_slow_reader,
    "contact-flood": contact_flood, "log-flood": log_flood,
}


async def attack(scenario: str, settings: dict[str, Any]) -> Tally:
    tally = Tally()
    try:
        # a hard stop: whatever the server does, the attack ends
        async with asyncio.timeout(settings["hold"] * 2 + 10):
            await ATTACKS[scenario](settings, tally)
    except TimeoutError:
        tally.notes.append("stopped by the attack's own time limit")
    return tally


def main() -> None:
    scenario, settings = sys.argv[1], json.loads(sys.argv[2])
    tally = asyncio.run(attack(scenario, settings))
    print(json.dumps({"counts": tally.counts, "notes": tally.notes}))


if __name__ == "__main__":
    main()
