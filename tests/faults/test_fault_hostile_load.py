"""A hostile load against the real server process with 1,024 file handles: from
127.0.0.2-127.0.0.4, idle connections to the client port, slowloris connections and
malformed requests to the web port (tests/faults/hostile_load.py), with smaller counts and
a shorter hold than the benchmark (benchmarks/bench_hostile_load.py has the full figures).
Meanwhile a client on 127.0.0.1 says hello and loads the page every half second, and is
served every time; each kind of trouble writes at most one log line (the test is shorter
than a minute); the server's file handles return to where they were."""

from __future__ import annotations

import asyncio
import json
import sys
from pathlib import Path

import pytest
from fault_harness import FAULT_MARKS, Station
from helpers import EXAMPLES, free_port, until
from hostile_load import attack, limit_files, open_files, trouble_kinds

pytestmark = [*FAULT_MARKS[:3], pytest.mark.timeout(120),
              pytest.mark.skipif(not sys.platform.startswith("linux"),
                                 reason="counts the server's files in /proc")]

HOLD = 7.0
"""Seconds of attack: longer than the hello and request deadlines (5 s), so that the
connections the server admitted are closed by them while the test looks on."""


async def test_a_hostile_crowd_from_other_addresses_does_not_deny_service(
        tmp_path: Path) -> None:
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(tmp_path / "no-switch")
    station = Station.make(tmp_path, data)
    web = free_port()
    # 64 per address, 16 of them waiting to say who they are: each attacking address gets
    # some of both ports, so that both deadlines act, and is refused the rest
    server = await station.server("--no-rotator-program", "--web-port", str(web),
                                  "--max-per-address", "64",
                                  preexec=limit_files(1024))
    try:
        await until(lambda: "Serving the browser client" in server.text(), 15,
                    "the web port")
        pid = server.process.pid
        await asyncio.sleep(0.5)
        files_before = open_files(pid)
        mark = len(server.lines)

        service, done = await attack(station.tcp, web, idle=150, slow=110, malformed=30,
                                     hold=HOLD)

        assert len(service.hellos) >= 10 and len(service.pages) >= 10
        assert service.failures == []  # every hello answered, every page loaded
        assert done.malformed_sent == 30 and done.opened > 260
        assert done.refused_or_closed > 0  # the per-address limit and the deadlines acted
        after = server.lines[mark:]
        assert not any("Traceback" in line for line in after), "\n".join(after)
        kinds = trouble_kinds(after)
        assert kinds and all(count == 1 for count in kinds.values()), kinds
        text = "\n".join(after)
        # each address's reserve for connections that have not said who they are (16, both
        # ports together) refuses the rest of the crowd before the per-address limit is
        # reached (the half requests are refused with the idle ones when those took the
        # reserve first, in the same line a minute; the request deadline itself:
        # tests/net/test_net_fairness.py)
        for said in ("have not said who they are yet", "no hello within",
                     "Error handling request"):
            assert said in text, text
        # everything the attack held is given back
        await until(lambda: open_files(pid) <= files_before, 15,
                    f"the server's files back to {files_before}")
        assert server.process.returncode is None
    finally:
        await server.end()
