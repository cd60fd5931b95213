"""``moas-client HOST[:PORT]`` as a program of its own."""

from __future__ import annotations

import asyncio
import os
import sys
from collections.abc import Callable

import pytest
from client_support import LiveServer
from helpers import until

from moas_gui.cli.client import EXIT_NEVER_CONNECTED, main

pytestmark = pytest.mark.realtime


async def run_client(*args: str, stop_when: Callable[[], object] | None = None,
                     ) -> tuple[int, str]:
    """Runs ``moas-client`` until it ends; with ``stop_when``, it is sent SIGTERM (as
    closing its window) once that is true."""
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen")
    process = await asyncio.create_subprocess_exec(
        sys.executable, "-m", "moas_gui.cli.client", *args, env=env,
        stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
    ending = asyncio.ensure_future(process.communicate())
    if stop_when is not None:
        await until(lambda: stop_when() or ending.done(), timeout=30,
                    what="the client's requests")
        if process.returncode is None:
            process.terminate()
    _, stderr = await asyncio.wait_for(ending, 60)
    assert process.returncode is not None
    return process.returncode, stderr.decode(errors="replace")


@pytest.mark.asyncio
async def test_moas_client_connects_asks_for_its_layout_and_quits() -> None:
    async with LiveServer() as live:
        # (--quit-after is a bound only: the client is closed once the server has had
        # its layout and answered its hello, and still ends as --quit-after ends it)
        code, stderr = await run_client(
            f"127.0.0.1:{live.port}", "--station", "2", "--rows", "1", "--columns", "10",
            "--quit-after", "30",
            stop_when=lambda: (2, 1, 1, 10) in live.calls("layout") and live.calls("snapshot"))
        assert code == 0, stderr
        assert (2, 1, 1, 10) in live.calls("layout")
        assert live.calls("snapshot"), "hello was answered with the state"


@pytest.mark.asyncio
async def test_moas_client_says_when_it_never_reached_the_server() -> None:
    live = LiveServer()
    await live.start()
    port = live.port
    await live.stop()
    code, stderr = await run_client(f"127.0.0.1:{port}", "--quit-after", "0.5")
    assert code == EXIT_NEVER_CONNECTED
    assert f"could not reach the server at 127.0.0.1:{port}" in stderr


@pytest.mark.parametrize(("args", "words"), [
    (["host:port"], "the port 'port' is not a number"),
    (["--rows", "0"], "--rows must be between 1 and 50"),
    (["--quit-after", "-1"], "--quit-after must be more than 0 seconds"),
])
def test_bad_arguments_are_explained(args: list[str], words: str,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        main(args)
    assert stopped.value.code == 2
    assert words in capsys.readouterr().err
