"""The test hook ``MOAS_GUI_SAVE_DELAY`` through which tests of the real ``moas-server``
process shorten how long state saves are gathered (``SAVE_DELAY_S``, a second): parsed
strictly (a number of seconds above 0 and at most the real second), a refusal saying
what and where, ``moas-server`` refusing to start on it, and the delay reaching the
running configuration's state keeper."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import pytest

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.cli import server
from moas_gui.state_store import SAVE_DELAY_HOOK, SAVE_DELAY_S, save_delay_from_environment

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_only_the_environment_variable_sets_the_delay() -> None:
    assert save_delay_from_environment({}) is None
    assert save_delay_from_environment({SAVE_DELAY_HOOK: "0.1"}) == 0.1
    assert save_delay_from_environment({SAVE_DELAY_HOOK: "1"}) == SAVE_DELAY_S


@pytest.mark.parametrize(("text", "says"), [
    ("soon", "'soon' is not a number of seconds"),
    ("", "'' is not a number of seconds"),
    ("0", "0 is not a number of seconds above 0 and at most 1"),
    ("-0.5", "-0.5 is not a number of seconds above 0 and at most 1"),
    ("2", "2 is not a number of seconds above 0 and at most 1"),
    ("nan", "nan is not a number of seconds above 0 and at most 1"),
    ("inf", "inf is not a number of seconds above 0 and at most 1"),
])
def test_a_delay_it_cannot_use_is_refused_saying_what(text: str, says: str) -> None:
    with pytest.raises(ValueError) as refused:
        save_delay_from_environment({SAVE_DELAY_HOOK: text})
    assert str(refused.value) == f"{SAVE_DELAY_HOOK}: {says}"


def test_moas_server_refuses_to_start_on_a_delay_it_cannot_use(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setenv(SAVE_DELAY_HOOK, "later")
    # (a headless start hands its log to standard error: this process's loggers are
    # put back as they were afterwards)
    loggers = [logging.getLogger(name) for name in ("moas_gui", "aiohttp")]
    kept = [(logger.handlers[:], logger.level, logger.propagate) for logger in loggers]
    try:
        status = server.main(["--headless", "--new-instance", str(tmp_path / "none.moas")])
    finally:
        for logger, (handlers, level, propagate) in zip(loggers, kept, strict=True):
            logger.handlers[:] = handlers
            logger.setLevel(level)
            logger.propagate = propagate
    assert status == 2
    assert capsys.readouterr().err == (
        f"moas-server: {SAVE_DELAY_HOOK}: 'later' is not a number of seconds\n")


def test_moas_server_hands_the_delay_to_the_state_keeper(tmp_path: Path) -> None:
    args = server._parser().parse_args(["--headless", "station.moas"])
    assert server._options(args).save_delay == SAVE_DELAY_S  # type: ignore[attr-defined]
    args.save_delay = 0.1
    assert server._options(args).save_delay == 0.1  # type: ignore[attr-defined]


@pytest.mark.asyncio
async def test_the_running_configuration_keeps_its_state_on_the_delay_given(
        tmp_path: Path) -> None:
    station = tmp_path / "station.moas"
    shutil.copy(EXAMPLES / "small-station.moas", station)
    for delay in (SAVE_DELAY_S, 0.25):
        app = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                      udp_bind="127.0.0.1", start_rotator_program=False,
                                      save_delay=delay))
        try:
            await app.open(station)
            assert app._run is not None and app._run.keeper is not None
            assert app._run.keeper.delay == delay
        finally:
            await app.close()
