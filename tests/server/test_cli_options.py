"""Options the three programs share: ``--log-level`` in any case, ``--version``."""

from __future__ import annotations

import logging
import subprocess
import sys
from collections.abc import Callable

import pytest

from moas_gui import __version__
from moas_gui.cli import emulator, rotator, server
from moas_gui.cli.options import log_level_number


def parse_server(argv: list[str]) -> object:
    return server._parser().parse_args(argv)


def parse_emulator(argv: list[str]) -> object:
    return emulator._parser().parse_args(argv)


def parse_rotator(argv: list[str]) -> object:
    return rotator._arguments(argv)


PARSERS: dict[str, Callable[[list[str]], object]] = {
    "moas-server": parse_server, "moas-emulator": parse_emulator, "moas-rotator": parse_rotator}


@pytest.mark.parametrize("program", sorted(PARSERS))
@pytest.mark.parametrize("written", ["debug", "DEBUG", "Debug", "info", "INFO", "warning",
                                     "Warning", "error", "ERROR"])
def test_every_program_takes_the_same_log_levels_in_any_case(program: str, written: str) -> None:
    args = PARSERS[program](["--log-level", written])
    assert args.log_level == written.lower()  # type: ignore[attr-defined]
    assert log_level_number(args.log_level) == getattr(logging, written.upper())  # type: ignore[attr-defined]


@pytest.mark.parametrize("program", sorted(PARSERS))
def test_an_unknown_log_level_is_a_usage_error_that_lists_the_levels(
        program: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        PARSERS[program](["--log-level", "loud"])
    assert stopped.value.code == 2
    assert "'loud' is not one of debug, info, warning, error" in capsys.readouterr().err


@pytest.mark.realtime
@pytest.mark.parametrize("program", ["moas_gui.cli.emulator", "moas_gui.cli.rotator",
                                     "moas_gui.cli.server"])
def test_every_program_tells_its_version(program: str) -> None:
    done = subprocess.run([sys.executable, "-m", program, "--version"], capture_output=True,
                          text=True, check=False, timeout=60)
    assert done.returncode == 0, done.stderr
    name = "moas-" + program.rsplit(".", 1)[1]
    assert done.stdout.strip() == f"{name} {__version__}"


def test_the_antenna_genius_options_are_read_and_bad_ones_say_what_is_wrong(
        capsys: pytest.CaptureFixture[str]) -> None:
    from moas_gui.config.model import RadioRef

    args = parse_server(["--ag-port", "9007", "--ag-radios", "1/1,2/1",
                         "--ag-discovery", "127.0.0.1:9999"])
    assert args.ag_port == 9007  # type: ignore[attr-defined]
    assert args.ag_radios == (RadioRef(1, 1), RadioRef(2, 1))  # type: ignore[attr-defined]
    assert args.ag_discovery == ("127.0.0.1", 9999)  # type: ignore[attr-defined]
    for option, value, words in (("--ag-radios", "1:1", "'1:1' is not STATION/RADIO"),
                                 ("--ag-discovery", "localhost", "not ADDR:PORT")):
        with pytest.raises(SystemExit) as stopped:
            parse_server([option, value])
        assert stopped.value.code == 2
        assert words in capsys.readouterr().err
