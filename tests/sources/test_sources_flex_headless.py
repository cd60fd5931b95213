"""``moas-server --headless --flex`` as a station runs it: a separate process reading the test
FlexRadio over TCP on 127.0.0.1, the switch emulated on a real pseudo-terminal here; a
slice's band change moves the relays, the radio gone is said in words and followed again
when it is back."""

from __future__ import annotations

import asyncio
import json
import os
import signal
import socket
import sys
from pathlib import Path

import pytest
from helpers import free_port, until
from switch_support import Cable

from moas_gui.config import load_config
from moas_gui.testing.flex_radio import FlexRadio

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX"),
]

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def relays_for(config_path: Path, antenna_id: int, khz: float) -> frozenset[int]:
    config = load_config(config_path).unwrap()
    antenna = config.antenna(antenna_id)
    assert antenna is not None
    return next(e.relays for c in antenna.control if c.range.contains(khz)
                for e in c.stations if e.applies_to(1, 1))


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_the_headless_server_follows_a_flexradio_given_on_its_command_line(
        tmp_path: Path) -> None:
    cable = Cable(tmp_path / "moas1")
    box = cable.plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(cable.link)
    data["UseN1MMLogger"] = False
    config_path = tmp_path / "station.moas"
    config_path.write_text(json.dumps(data, indent=2))
    radio = FlexRadio()
    await radio.start()
    radio.set_slice(0, RF_frequency=14.025, tx=1)
    env = dict(os.environ, PYTHONUNBUFFERED="1", XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"), XDG_DATA_HOME=str(tmp_path / "data"))
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config_path),
        "--bind", "127.0.0.1", "--tcp-port", str(free_port(socket.SOCK_STREAM)),
        "--udp-port", str(free_port(socket.SOCK_DGRAM)), "--flex",
        f"127.0.0.1:{radio.port}", "--flex-radios", "A=1/1", "--no-rotator-program",
        "--new-instance", "--no-antenna-log", "--log-level", "info",
        stderr=asyncio.subprocess.PIPE, env=env)
    lines: list[str] = []

    async def collect() -> None:
        assert process.stderr is not None
        async for line in process.stderr:
            lines.append(line.decode(errors="replace"))

    collector = asyncio.create_task(collect())
    try:
        tribander_20m = relays_for(config_path, 0, 14025.0)
        dipole_80m = relays_for(config_path, 2, 3525.0)
        await until(lambda: box.view().relays == tribander_20m, timeout=30,
                    what="slice A's 20 m antenna on the relays\n" + "".join(lines))
        assert any("Following FlexRadio 127.0.0.1:" in line for line in lines)
        assert radio.commands[:4] == ["client program moas-gui", "sub slice all",
                                      "sub tx all", "keepalive enable"]
        radio.set_slice(0, RF_frequency=3.525)
        await until(lambda: box.view().relays == dipole_80m, timeout=30,
                    what="slice A's 80 m antenna on the relays")
        port = radio.port
        await radio.stop()
        await until(lambda: any("offline: station 1 radio 1 frequency unknown" in line
                                for line in lines), timeout=30, what="the radio said offline")
        assert box.view().relays == dipole_80m  # nothing guessed while it is away
        radio = FlexRadio(port=port)
        radio.set_slice(0, RF_frequency=21.025, tx=1)
        await radio.start()
        await until(lambda: box.view().relays == relays_for(config_path, 0, 21025.0),
                    timeout=30, what="the radio back on 15 m")
        assert any("is back" in line for line in lines)
        assert not any(c.startswith(("slice set", "client gui")) for c in radio.commands)
        process.send_signal(signal.SIGTERM)
        assert await asyncio.wait_for(process.wait(), 15) == 0
    finally:
        if process.returncode is None:
            process.kill()
            await process.wait()
        collector.cancel()
        await radio.stop()
        cable.unplug()
