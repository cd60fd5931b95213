"""Every kind of log line an outside party can cause outside the Antenna Genius front,
flooded through real sockets into a real ``moas-server --headless`` (at Debug, so that
even the Debug lines count): each kind writes one line at once and, when the server
stops, the last of the burst with its count; never one line per packet or request
(docs/security.md: one trouble line a minute per kind).

The floods: N1MM RadioInfo alternating ``ActiveRadioNr`` (issue 38: 542,010 "transmit
focus" lines in 45 s), a frequency for a radio the station does not have, datagrams that
are not XML from the logger's address and from 40 other addresses (not in N1MMLogger),
contacts dated 9999, N1MM rotor-window commands, and on the client port bad lines,
unknown commands, refused requests, hellos with wrong tokens and connections opened and
dropped."""

from __future__ import annotations

import asyncio
import contextlib
import json
import re
import socket
import time
from pathlib import Path

import pytest
from fault_harness import FAULT_MARKS, Station
from helpers import EXAMPLES, free_port, until

from moas_gui.net.server import CHATTER_BURST
from moas_gui.sources.log_bursts import CROWD_LINES
from moas_gui.sources.n1mm_contact import contact_packet
from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = [*FAULT_MARKS[:3], pytest.mark.timeout(180)]

PACKETS = 6_000
"""Datagrams of each UDP flood."""
CONNECTIONS = 300
"""Connections to the client port opened and dropped."""
HELLOS = 200
"""Hellos with a wrong token on the client port."""


async def send_all(port: int, packets: list[bytes], source: str = "127.0.0.1") -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind((source, 0))
        for number, packet in enumerate(packets):
            sock.sendto(packet, ("127.0.0.1", port))
            if number % 200 == 199:
                await asyncio.sleep(0.005)  # the server reads; a full buffer drops the rest


async def client_flood(port: int) -> int:
    """Bad lines, unknown commands and refused requests on one connection; how many
    answers came back."""
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    lines = []
    for number in range(300):
        lines += [b"this is not JSON\n",
                  json.dumps({"id": number, "cmd": "nonsense"}).encode() + b"\n",
                  json.dumps({"id": number, "cmd": "select", "station": 1, "radio": 1,
                              "antenna": 999}).encode() + b"\n"]
    writer.write(b"".join(lines))
    await writer.drain()
    answers = 0
    try:
        async with asyncio.timeout(30):
            while answers < len(lines) and await reader.readline():
                answers += 1
    finally:
        writer.close()
    return answers


async def wrong_hellos(port: int) -> list[str]:
    """Hellos with wrong tokens (made-up key ids, and strings that are no token at all),
    one after another, a new connection every 20 (each must say hello within 5 s); the
    message of each refusal."""
    said: list[str] = []
    for first in range(0, HELLOS, 20):
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        try:
            for number in range(first, first + 20):
                token = (f"moas1.{number:08x}.{'x' * 43}" if number % 2
                         else f"not a token {number}")
                writer.write(json.dumps({"id": number, "cmd": "hello", "client": "guess",
                                         "token": token}).encode() + b"\n")
                async with asyncio.timeout(30):
                    while (reply := json.loads(await reader.readline())).get("id") != number:
                        pass
                said.append(reply["error"]["message"])
        finally:
            writer.close()
    return said


def count(lines: list[str], pattern: str) -> tuple[int, list[str]]:
    found = [line for line in lines if re.search(pattern, line)]
    return len(found), found


async def test_every_outside_log_kind_is_one_line_and_a_count(tmp_path: Path) -> None:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["UseN1MMRotor"] = True
    station = Station.make(tmp_path, data)
    rotor = free_port(socket.SOCK_DGRAM)
    server = await station.server("--no-rotator-program", "--no-antenna-log",
                                  "--n1mm-rotor-port", str(rotor), "--log-level", "debug")
    began = time.monotonic()
    try:
        await until(lambda: "Serving " in server.text(), 30, "the server serving")
        focus = [radio_info_packet(1, 14025.0, active_radio_nr=1 + n % 2, focus_radio_nr=1)
                 for n in range(PACKETS)]
        await send_all(station.udp, focus)
        await send_all(station.udp, [radio_info_packet(9, 7025.0 + n % 50)
                                     for n in range(PACKETS // 4)])
        await send_all(station.udp, [b"not XML %d" % n for n in range(PACKETS // 4)])
        # 20 from each of 40 other addresses, at once: on a busy machine the receive
        # buffer, still full of the flood before, may drop every one of them, so the
        # crowd comes again (at most five times) until the server has read some of it
        crowd = re.compile(r"packet from 127\.0\.0\.\d+ ignored: that address is not in")
        for _ in range(5):
            for host in range(2, 42):
                await send_all(station.udp, [b"not XML"] * 20, f"127.0.0.{host}")
            with contextlib.suppress(AssertionError):
                await until(lambda: crowd.search(server.text()) is not None, 2,
                            "a line about the crowd")
                break
        far = contact_packet("contactinfo", "ab12", 0.0, "DL1ABC").replace(
            b"1970-01-01 00:00:00", b"9999-12-31 23:59:59")
        await send_all(station.udp, [far.replace(b"ab12", b"ab%d" % n)
                                     for n in range(PACKETS // 4)])
        await send_all(rotor, [b"<N1MMRotor><rotor>Tribander</rotor><goazi>%d.0</goazi>"
                               b"<offset>0.0</offset></N1MMRotor>" % (n % 360)
                               for n in range(PACKETS // 4)])
        answers = await client_flood(station.tcp)
        assert answers == 900  # every line answered: the server read them all
        refusals = await wrong_hellos(station.tcp)
        assert len(refusals) == HELLOS and all(
            "not one of this station's operators" in m or "too many wrong tokens" in m
            for m in refusals), refusals[:5]
        for _ in range(CONNECTIONS):  # connections opened and dropped, one after another
            _reader, writer = await asyncio.open_connection("127.0.0.1", station.tcp)
            writer.close()
            await writer.wait_closed()
        await until(lambda: "transmit focus on radio" in server.text(), 20)
        await asyncio.sleep(1.0)  # the last datagrams are read
    finally:
        assert await server.end() == 0, server.text()[-3000:]
    minutes = int((time.monotonic() - began) // 60)
    lines = server.lines
    # one line at once per kind, and (at the stop, or each minute) the last with its count
    most = 2 + minutes
    for pattern in (r"Station 1: transmit focus on radio \d", r"Logger says: ActiveRadio",
                    r"Logger frequency for station 1 radio 9 ignored",
                    r"N1MM rotor window \(127\.0\.0\.1\): turn Tribander",
                    r"Bad line from ", r"Refused a request from ", r"Refused select from "):
        seen, found = count(lines, pattern)
        assert 1 <= seen <= most, (pattern, found[:5])
    seen, found = count(lines, r"Station 1: transmit focus on radio \d.*the last of "
                               r"([\d,]+) such lines")
    assert seen >= 1, found
    held = int(re.findall(r"the last of ([\d,]+) such", found[-1])[0].replace(",", ""))
    assert held >= 100, found  # the burst was counted, not written
    # about one sender: a line a minute each, CROWD_LINES a minute for all senders
    for pattern in (r"packet from 127\.0\.0\.1 \(station 1\) ignored: .*not",
                    r"contact packet from 127\.0\.0\.1 ignored: contactinfo .* refused"):
        seen, found = count(lines, pattern)
        assert 1 <= seen <= 1 + minutes, (pattern, found[:5])
    seen, found = count(lines, r"Client connected from ")
    assert 1 <= seen <= CHATTER_BURST * (1 + minutes) + 1 < CONNECTIONS, found[-3:]
    # a refused hello: one line a minute per kind (a wrong token, one refused while its
    # address waits its back-off), not one per hello
    for pattern in (r"Refused the hello of .*not one of this station's operators",
                    r"Refused the hello of .*too many wrong tokens"):
        seen, found = count(lines, pattern)
        assert 1 <= seen <= 1 + minutes, (pattern, found[:5])
    seen, found = count(lines, r"left before hello|never said hello")
    assert seen <= 1 + minutes, found[:5]
    seen, found = count(lines, r"packet from 127\.0\.0\.\d+ ignored: that address is not in")
    assert 1 <= seen <= CROWD_LINES * (1 + minutes), found[:12]
    assert len(lines) < 400, "\n".join(lines[-50:])  # 25,000 datagrams and 900 lines later
