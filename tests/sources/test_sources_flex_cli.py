"""``moas-server --flex-list`` hears the test radio's discovery datagrams; ``--flex-radios``
that make no sense stop the command line with the reason."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from helpers import free_port

from moas_gui.cli import server
from moas_gui.testing.flex_radio import FlexRadio


@pytest.mark.realtime  # a real moas-server process, listening its 3 s
def test_flex_list_prints_the_radios_heard(tmp_path: Path) -> None:
    port = free_port(socket.SOCK_DGRAM)
    radio = FlexRadio(port=4994, nickname="Contest")
    done = threading.Event()

    def announce() -> None:
        while not done.wait(0.2):
            radio.announce(("127.0.0.1", port))

    talker = threading.Thread(target=announce, daemon=True)
    talker.start()
    env = dict(os.environ, XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"))
    try:
        listed = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--flex-list",
                                 "--flex-discovery-port", str(port)], capture_output=True,
                                text=True, check=False, timeout=60, env=env)
    finally:
        done.set()
        talker.join()
    assert listed.returncode == 0, listed.stderr
    assert listed.stdout.splitlines() == [
        "FLEX-6600\tnickname Contest\tserial 1234-5678-9012-3456\t127.0.0.1:4994"]


@pytest.mark.realtime  # a real moas-server process, listening its 3 s
def test_flex_list_says_when_none_was_heard(tmp_path: Path) -> None:
    port = free_port(socket.SOCK_DGRAM)
    env = dict(os.environ, XDG_STATE_HOME=str(tmp_path / "state"),
               XDG_CONFIG_HOME=str(tmp_path / "config"))
    listed = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--flex-list",
                             "--flex-discovery-port", str(port)], capture_output=True,
                            text=True, check=False, timeout=60, env=env)
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
