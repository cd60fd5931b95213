"""``moas-server --flex-list`` hears the test radio's discovery datagrams; ``--flex-radios``
that make no sense stop the command line with the reason."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
from typing import NamedTuple

import pytest
from helpers import free_port

from moas_gui.cli import server
from moas_gui.testing.flex_radio import FlexRadio


class Listed(NamedTuple):
    port: int
    """The UDP port it listened on."""
    done: subprocess.CompletedProcess[str]


@pytest.fixture(scope="module")
def flex_lists(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Listed]:
    """Two ``moas-server --flex-list`` processes at once (each listens its 3 s): ``heard``
    on a port the test radio announces itself on, ``silent`` on one nobody announces on."""
    heard = free_port(socket.SOCK_DGRAM)
    silent = free_port(socket.SOCK_DGRAM)
    while silent == heard:
        silent = free_port(socket.SOCK_DGRAM)
    radio = FlexRadio(port=4994, nickname="Contest")
    done = threading.Event()

    def announce() -> None:
        while not done.wait(0.2):
            radio.announce(("127.0.0.1", heard))

    def start(name: str, port: int) -> subprocess.Popen[str]:
        home = tmp_path_factory.mktemp(name)
        env = dict(os.environ, XDG_STATE_HOME=str(home / "state"),
                   XDG_CONFIG_HOME=str(home / "config"))
        return subprocess.Popen([sys.executable, "-m", "moas_gui.cli.server", "--flex-list",
                                 "--flex-discovery-port", str(port)], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, env=env)

    talker = threading.Thread(target=announce, daemon=True)
    talker.start()
    running = {name: (port, start(name, port)) for name, port in (("heard", heard),
                                                                   ("silent", silent))}
    listed: dict[str, Listed] = {}
    try:
        for name, (port, process) in running.items():
            out, err = process.communicate(timeout=60)
            listed[name] = Listed(port, subprocess.CompletedProcess(process.args,
                                                                    process.returncode, out, err))
    finally:
        done.set()
        talker.join()
        for _, process in running.values():
            if process.poll() is None:
                process.kill()
                process.wait()
    return listed


@pytest.mark.realtime  # real moas-server processes, listening their 3 s (both at once)
@pytest.mark.shared
def test_flex_list_prints_the_radios_heard(flex_lists: dict[str, Listed]) -> None:
    listed = flex_lists["heard"].done
    assert listed.returncode == 0, listed.stderr
    assert listed.stdout.splitlines() == [
        "FLEX-6600\tnickname Contest\tserial 1234-5678-9012-3456\t127.0.0.1:4994"]


@pytest.mark.realtime  # real moas-server processes, listening their 3 s (both at once)
@pytest.mark.shared
def test_flex_list_says_when_none_was_heard(flex_lists: dict[str, Listed]) -> None:
    port, listed = flex_lists["silent"]
    assert listed.returncode == 3
    assert f"no FlexRadio heard on UDP port {port}" in listed.stderr
    assert "--flex ADDR" in listed.stderr


@pytest.mark.parametrize("text, why", [("A=1", "station/radio"), ("A=1/1,A=1/2", "twice"),
                                       ("slice=1/1", "slice letter")])
def test_flex_radios_that_make_no_sense_are_a_usage_error(
        text: str, why: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        server._parser().parse_args(["--flex", "10.0.0.5", "--flex-radios", text])
    assert stopped.value.code == 2
    assert why in capsys.readouterr().err


def test_the_flex_options_reach_the_server_options() -> None:
    args = server._parser().parse_args(["--flex", "Shack", "--flex", "10.0.0.5:4992",
                                        "--flex-radios", "A=1/1,B=2/1"])
    args.switch_timing = args.rotator_timing = None
    options = server._options(args)
    assert options.flex == ("Shack", "10.0.0.5:4992")
    assert options.flex_radios == "A=1/1,B=2/1" and options.flex_discovery_port == 4992


def test_a_second_launch_with_another_flexradio_is_refused_by_the_running_server() -> None:
    from types import SimpleNamespace

    args = server._parser().parse_args(["--flex", "Contest"])
    args.switch_timing = args.rotator_timing = None
    running = SimpleNamespace(options=server._options(args),
                              client_address=("127.0.0.1", 12059))
    same = server.launch_request(server._parser().parse_args(["--flex", "Contest"]))
    other = server.launch_request(server._parser().parse_args(["--flex", "10.0.0.5"]))
    assert server.vet_launch(running, same, headless=False) is None  # type: ignore[arg-type]
    refusal = server.vet_launch(running, other, headless=False)  # type: ignore[arg-type]
    assert refusal is not None and "--flex 10.0.0.5" in refusal and "--flex Contest" in refusal
