"""The switch link's clocks, and the test hook (``MOAS_GUI_SWITCH_TIMING``) through which
tests of the real ``moas-server`` process shorten them: parsed strictly, every refusal
saying what and where, and ``moas-server`` refusing to start on a text it cannot use."""

from __future__ import annotations

from pathlib import Path

import pytest

from moas_gui.cli import server
from moas_gui.hw.moas2.timing import (
    ENVIRONMENT,
    REAL_TIMING,
    LinkTiming,
    parse_timing,
    timing_from_environment,
)


def test_the_real_clocks() -> None:
    assert REAL_TIMING == LinkTiming(ping_interval=1.0, answer_timeout=3.0, retry_first=0.5,
                                     retry_max=8.0)
    assert REAL_TIMING.problems() == []


def test_names_not_given_keep_their_real_values() -> None:
    assert parse_timing("ping_interval=0.1 answer_timeout=0.5") == LinkTiming(
        ping_interval=0.1, answer_timeout=0.5, retry_first=0.5, retry_max=8.0)
    assert parse_timing(" retry_first=0.1,retry_max=0.4 ") == LinkTiming(
        retry_first=0.1, retry_max=0.4)


@pytest.mark.parametrize(("text", "says"), [
    ("", "no name=seconds given"),
    ("ping_interval", "'ping_interval' is not name=seconds"),
    ("ping=0.1", ("unknown name 'ping' (known: ping_interval, answer_timeout, retry_first, "
                  "retry_max, relay_dwell)")),
    ("answer_timeout=0.5 answer_timeout=0.6", "answer_timeout is given twice"),
    ("answer_timeout=half", "answer_timeout='half' is not a number of seconds"),
    ("answer_timeout=0", "answer_timeout=0 is not a positive number of seconds"),
    ("answer_timeout=-1", "answer_timeout=-1 is not a positive number of seconds"),
    ("answer_timeout=nan", "answer_timeout=nan is not a positive number of seconds"),
    ("answer_timeout=inf", "answer_timeout=inf is not a positive number of seconds"),
    ("ping_interval=0.5 answer_timeout=0.5",
     "ping_interval (0.5 s) must be shorter than answer_timeout (0.5 s)"),
    ("retry_first=1 retry_max=0.5", "retry_first (1 s) must not be longer than retry_max"),
])
def test_a_text_it_cannot_use_is_refused_saying_what(text: str, says: str) -> None:
    with pytest.raises(ValueError) as refused:
        parse_timing(text)
    assert str(refused.value).startswith(f"{ENVIRONMENT}: ")
    assert says in str(refused.value)


def test_only_the_environment_variable_sets_the_hook() -> None:
    assert timing_from_environment({}) is None
    assert timing_from_environment({ENVIRONMENT: "answer_timeout=2"}) == LinkTiming(
        answer_timeout=2.0)


def test_moas_server_refuses_to_start_on_a_text_it_cannot_use(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.setenv(ENVIRONMENT, "answer_timeout=soon")
    status = server.main(["--headless", "--new-instance", str(tmp_path / "none.moas")])
    assert status == 2
    assert capsys.readouterr().err == (
        f"moas-server: {ENVIRONMENT}: answer_timeout='soon' is not a number of seconds\n")


def test_moas_server_hands_the_hooks_clocks_to_its_switch_links() -> None:
    args = server._parser().parse_args(["--headless", "station.moas"])
    assert server._options(args).switch_timing is None  # type: ignore[attr-defined]
    args.switch_timing = parse_timing("ping_interval=0.1 answer_timeout=0.5")
    options = server._options(args)
    assert options.switch_timing == LinkTiming(  # type: ignore[attr-defined]
        ping_interval=0.1, answer_timeout=0.5)
