"""``moas-server --headless`` started with few file handles (``ulimit -n``), as many
desktops start programs, and sent more idle client connections than it can hold:
loopback only, a bounded number of connections, a real process and a switch
emulated on a pseudo-terminal."""

from __future__ import annotations

import asyncio
import json
import os
import resource
import socket
import sys
from collections.abc import AsyncIterator, Callable
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import EXAMPLES, free_port, until
from switch_support import Cable

pytestmark = [
    pytest.mark.realtime,
    pytest.mark.skipif(sys.platform != "linux", reason="reads /proc/PID/limits"),
]


class Server:
    def __init__(self, process: asyncio.subprocess.Process, port: int) -> None:
        self.process, self.port = process, port
        self.lines: list[str] = []
        self._collector = asyncio.create_task(self._collect())

    async def _collect(self) -> None:
        assert self.process.stderr is not None
        async for line in self.process.stderr:
            self.lines.append(line.decode(errors="replace"))

    async def hello(self) -> dict[str, object]:
        reader, writer = await asyncio.open_connection("127.0.0.1", self.port)
        try:
            writer.write(b'{"id": 1, "cmd": "hello", "client": "test"}\n')
            async with asyncio.timeout(10):
                return json.loads(await reader.readline())  # type: ignore[no-any-return]
        finally:
            writer.close()

    def open_files_soft_limit(self) -> int:
        for line in Path(f"/proc/{self.process.pid}/limits").read_text().splitlines():
            if line.startswith("Max open files"):
                return int(line.split()[3])
        raise AssertionError("no open-file limit in /proc")

    async def stop(self) -> None:
        if self.process.returncode is None:
            self.process.terminate()
            try:
                await asyncio.wait_for(self.process.wait(), 15)
            except TimeoutError:
                self.process.kill()
                await self.process.wait()
        await self._collector


async def start(config: Path, limits: tuple[int, int], *extra: str) -> Server:
    tcp = free_port(socket.SOCK_STREAM)

    def limit_files() -> None:
        resource.setrlimit(resource.RLIMIT_NOFILE, limits)

    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.server", "--headless", str(config),
        "--bind", "127.0.0.1", "--tcp-port", str(tcp), "--udp-port", "0",
        "--no-rotator-program", "--new-instance", *extra,
        stderr=asyncio.subprocess.PIPE, preexec_fn=limit_files,
        env=dict(os.environ, PYTHONUNBUFFERED="1"))
    server = Server(process, tcp)
    for _ in range(150):
        try:
            await server.hello()
            return server
        except OSError:
            await asyncio.sleep(0.1)
    await server.stop()
    raise AssertionError("the server never listened:\n" + "".join(server.lines))


@pytest_asyncio.fixture
async def config(tmp_path: Path) -> AsyncIterator[Path]:
    cable = Cable(tmp_path / "moas1")
    cable.plug()
    data = json.loads((EXAMPLES / "small-station.moas").read_text())
    data["Switches"][0]["Port"] = str(cable.link)
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(data, indent=2))
    yield path
    cable.unplug()


async def idle_connections(
    port: int, count: int,
) -> tuple[list[asyncio.StreamReader], list[asyncio.StreamWriter]]:
    readers, writers = [], []
    for _ in range(count):
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        readers.append(reader)
        writers.append(writer)
    return readers, writers


def count(lines: list[str], predicate: Callable[[str], bool]) -> int:
    return sum(1 for line in lines if predicate(line))


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_more_idle_clients_than_file_handles_neither_flood_the_log_nor_stop_the_server(
    config: Path,
) -> None:
    # a hard limit: nothing to raise (and every client on one address, on purpose)
    server = await start(config, (128, 128), "--max-per-address", "1000")
    writers: list[asyncio.StreamWriter] = []
    try:
        assert server.open_files_soft_limit() == 128
        readers, writers = await idle_connections(server.port, 150)
        # every connection past the 64 the limit allows is answered and closed: the
        # refusal repeats 86 times and the log still says it once
        ended = [asyncio.ensure_future(reader.read()) for reader in readers]
        await until(lambda: sum(task.done() for task in ended) >= 150 - 64, timeout=30,
                    what="the connections over the limit refused")
        for task in ended:
            task.cancel()
        text = "".join(server.lines)
        assert "Traceback" not in text and " ERROR " not in text, text[-3000:]
        assert count(server.lines, lambda s: "At most 64 clients at once" in s) == 1
        assert count(server.lines, lambda s: "Refused a client" in s) == 1, text[-3000:]
        assert count(server.lines, lambda s: "out of system resource" in s) == 0
        assert len(text) < 20_000, f"{len(text):,} characters of log for 150 connections"
        for writer in writers:
            writer.close()
        writers = []
        for _ in range(100):  # the idle ones are noticed gone, then a client is served
            reply = await server.hello()
            if reply.get("ok"):
                break
            await asyncio.sleep(0.1)
        assert reply == {"id": 1, "ok": True, "result": reply["result"]}
    finally:
        for writer in writers:
            writer.close()
        await server.stop()


@pytest.mark.asyncio
@pytest.mark.timeout(90)
async def test_the_soft_limit_is_raised_at_start_and_max_clients_caps_connections(
    config: Path,
) -> None:
    server = await start(config, (128, 4096), "--max-clients", "5")
    writers: list[asyncio.StreamWriter] = []
    try:
        assert server.open_files_soft_limit() == 4096
        _readers, writers = await idle_connections(server.port, 5)
        refused = await server.hello()
        assert refused["id"] is None and refused["ok"] is False
        assert "already serves 5 clients" in refused["error"]["message"]  # type: ignore[index]
    finally:
        for writer in writers:
            writer.close()
        await server.stop()


@pytest.mark.parametrize("value", ["0", "-3", "many"])
def test_max_clients_must_be_a_positive_whole_number(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from moas_gui.cli.server import main

    with pytest.raises(SystemExit) as ended:
        main(["--headless", "x.moas", "--max-clients", value])
    assert ended.value.code == 2
    assert "--max-clients" in capsys.readouterr().err
