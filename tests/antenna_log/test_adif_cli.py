"""``moas-server --antenna-log FILE --adif OUT [--from T --to T]``: exit statuses, clear
messages, and the file it writes (read back with adif-io)."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import adif_io
import pytest
from antenna_log_support import T0, MemoryJournal, contest_journal

from moas_gui.antenna_log.records import JournalReader
from moas_gui.cli.antenna_log import export_antenna_log
from moas_gui.cli.server import _parser, main


def arguments(*argv: str) -> argparse.Namespace:
    return _parser().parse_args(list(argv))


def opener_of(journal: JournalReader, seen: list[Path] | None = None):
    def open_reader(config: Path) -> JournalReader:
        if seen is not None:
            seen.append(config)
        return journal

    return open_reader


def test_the_whole_journal_by_default(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "all.adi"
    seen: list[Path] = []
    args = arguments("--antenna-log", "contest.moas", "--adif", str(out))
    assert export_antenna_log(args, opener_of(contest_journal(), seen)) == 0
    assert seen == [Path("contest.moas")]
    qsos, _ = adif_io.read_from_file(str(out))
    assert len(qsos) == 15
    assert "STATION_CALLSIGN" not in qsos[0]
    assert f"{out}: 15 contacts from " in capsys.readouterr().out


def test_from_and_to_choose_the_contacts(tmp_path: Path) -> None:
    out = tmp_path / "hour2.adi"
    args = arguments(
        "--antenna-log",
        "c.moas",
        "--adif",
        str(out),
        "--from",
        _iso(T0 + 3600),
        "--to",
        _iso(T0 + 7200),
        "--station-callsign",
        "w1xx",
    )
    assert export_antenna_log(args, opener_of(contest_journal())) == 0
    qsos, _ = adif_io.read_from_file(str(out))
    assert sorted(q["CALL"] for q in qsos) == ["EA0EE", "EA1EE", "F1CC", "I0DD", "I1DD"]
    assert {q["STATION_CALLSIGN"] for q in qsos} == {"W1XX"}


def test_a_last_contact_on_the_journals_last_second_is_written(tmp_path: Path) -> None:
    journal = contest_journal()
    last = journal.contacts_[-1]
    journal.contacts_[-1] = replace(last, time=T0 + 7200.4)
    out = tmp_path / "last.adi"
    args = arguments("--antenna-log", "c.moas", "--adif", str(out))
    assert export_antenna_log(args, opener_of(journal)) == 0
    assert len(adif_io.read_from_file(str(out))[0]) == 15


def test_no_journal_yet_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def missing(config: Path) -> JournalReader:
        raise FileNotFoundError(config)

    out = tmp_path / "x.adi"
    args = arguments("--antenna-log", "new.moas", "--adif", str(out))
    assert export_antenna_log(args, missing) == 1
    assert "new.moas: no antenna journal for this file yet" in capsys.readouterr().err
    assert not out.exists()


def test_an_empty_journal_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "x.adi"
    args = arguments("--antenna-log", "new.moas", "--adif", str(out))
    assert export_antenna_log(args, opener_of(MemoryJournal())) == 1
    assert "its antenna journal is empty; nothing to export" in capsys.readouterr().err
    assert not out.exists()


def test_an_unwritable_file_says_which(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "no-such-dir" / "x.adi"
    args = arguments("--antenna-log", "c.moas", "--adif", str(out))
    assert export_antenna_log(args, opener_of(contest_journal())) == 1
    assert f"{out}: cannot write it" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["--antenna-log", "c.moas", "--adif", "o.adi", "--from", "friday"],
            "--from: 'friday' is not a time; write it as ISO 8601 in UTC",
        ),
        (
            ["--antenna-log", "c.moas", "--adif", "o.adi", "--to", "2026-02-30"],
            "--to: '2026-02-30' is not a time",
        ),
        (
            [
                "--antenna-log",
                "c.moas",
                "--adif",
                "o.adi",
                "--from",
                "2026-11-29",
                "--to",
                "2026-11-28",
            ],
            "--from 2026-11-29 is not before --to 2026-11-28",
        ),
        (["--adif", "o.adi"], "--antenna-log FILE and --adif OUT go together"),
        (["--antenna-log", "c.moas"], "--antenna-log FILE and --adif OUT go together"),
        (["--from", "2026-11-28"], "--antenna-log FILE and --adif OUT go together"),
    ],
)
def test_options_that_do_not_go_together(
    argv: list[str],
    message: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_file_that_never_ran_has_nothing_to_export(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "x.adi"
    assert main(["--antenna-log", str(tmp_path / "never.moas"), "--adif", str(out)]) == 1
    assert capsys.readouterr().err.startswith("moas-server: ")
    assert not out.exists()


def _iso(seconds: float) -> str:
    from datetime import UTC, datetime

    return datetime.fromtimestamp(seconds, UTC).isoformat()
