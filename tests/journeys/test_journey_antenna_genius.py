"""Journey (issue 32): a station run by ``moas-server --headless --ag-port``, its switch
emulated on a real pseudo-terminal.  The logger tunes radio 1 to 20 m; an Antenna
Genius client (AetherSDR, say) sees the band and the antenna pushed, then picks another
antenna with ``port set``: the box's relays follow, and the logger's client sees it."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import socket
import sys
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_asyncio
from ag_client import AgClient, fields
from helpers import free_port, until
from switch_support import Cable

from moas_gui.config import load_config
from moas_gui.sources.n1mm_packet import radio_info_packet

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest_asyncio.fixture
async def station(tmp_path: Path) -> AsyncIterator[tuple[Cable, Path]]:
    cable = Cable(tmp_path / "moas1")
    cable.plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(cable.link)
    data["UseN1MMLogger"] = True
    data["N1MMLogger"] = [{"Address": "127.0.0.1", "Station": 1}]
    config = tmp_path / "station.moas"
    config.write_text(json.dumps(data, indent=2))
    yield cable, config
    if cable.endpoint is not None:
        cable.endpoint.close()


def relays_for(config_path: Path, antenna_id: int, khz: float) -> frozenset[int]:
    config = load_config(config_path).unwrap()
    antenna = config.antenna(antenna_id)
    assert antenna is not None
    return next(e.relays for c in antenna.control if c.range.contains(khz)
                for e in c.stations if e.applies_to(1, 1))


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_logger_band_then_an_antenna_genius_press_move_the_boxs_relays(
        station: tuple[Cable, Path]) -> None:
    cable, config_path = station
    tcp, udp, ag_port = free_port(), free_port(socket.SOCK_DGRAM), free_port()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as discovery:
        discovery.bind(("127.0.0.1", 0))
        discovery.setblocking(False)
        process = await asyncio.create_subprocess_exec(
            sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config_path),
            "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", str(udp),
            "--ag-port", str(ag_port),
            "--ag-discovery", f"127.0.0.1:{discovery.getsockname()[1]}",
            "--no-rotator-program", "--new-instance", "--log-level", "info",
            stderr=asyncio.subprocess.PIPE, env=dict(os.environ, PYTHONUNBUFFERED="1"))
        log: list[str] = []

        async def collect() -> None:
            assert process.stderr is not None
            async for line in process.stderr:
                log.append(line.decode(errors="replace"))

        collector = asyncio.create_task(collect())
        ag: AgClient | None = None
        try:
            # the station announces itself where --ag-discovery said
            loop = asyncio.get_running_loop()
            heard = await asyncio.wait_for(loop.sock_recv(discovery, 1024), 30)
            assert fields(heard.decode())["port"] == str(ag_port), heard
            ag = await AgClient.connect(ag_port)
            assert ag.greeting.startswith("V4") and "AG" in ag.greeting
            assert (await ag.ask("sub port all")).code == 0
            box = cable.box
            assert box is not None
            await until(lambda: box.view().active, timeout=30, what="the box loaded")

            # the logger tunes radio 1 to 20 m: the tribander (AG antenna 1), pushed
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
                sender.sendto(radio_info_packet(1, 14025.0), ("127.0.0.1", udp))
            said = fields(await ag.status("port 1 ", timeout=20))
            while said["band"] != "6":
                said = fields(await ag.status("port 1 ", timeout=20))
            assert said["txant"] == "1" and said["rxant"] == "1"
            await until(lambda: box.view().relays == relays_for(config_path, 0, 14025.0))

            # the AG client picks the vertical (AG antenna 4, ID 3): a press
            assert (await ag.ask("port set 1 rxant=4 txant=4")).code == 0
            said = fields(await ag.status("port 1 "))
            assert said["txant"] == "4"
            await until(lambda: box.view().relays == relays_for(config_path, 3, 14025.0),
                        what="the vertical's relays on the box")

            # a press the engine refuses: the 80 m dipole on 20 m; the box keeps its relays
            refused = await ag.ask("port set 1 rxant=3 txant=3")
            assert refused.code != 0 and "does not cover" in refused.message
            assert box.view().relays == relays_for(config_path, 3, 14025.0)

            await ag.close()
            process.send_signal(signal.SIGTERM)
            assert await asyncio.wait_for(process.wait(), 15) == 0
            assert box.view().relays == relays_for(config_path, 3, 14025.0)
            assert any("Antenna Genius device 1" in line for line in log), "".join(log)
        finally:
            if ag is not None:
                await ag.close()
            if process.returncode is None:
                process.kill()
                await process.wait()
            await collector
