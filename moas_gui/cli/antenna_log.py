"""``moas-server --antenna-log FILE.moas --adif OUT.adi [--from T] [--to T]``: the antenna
journal kept for a configuration file, written as ADIF, without starting a server.

Exit status: 0 when the file is written, 1 when there is no journal to read or the file
cannot be written, 2 for options that do not go together or a time that is not one.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the export's modules load when it runs (moas-server starts quickly)
    from moas_gui.antenna_log.records import JournalReader, Period

__all__ = ["add_arguments", "export_antenna_log", "open_journal", "wants_export"]

Opener = Callable[[Path], "JournalReader"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The export's options, on ``moas-server``'s parser."""
    parser.add_argument(
        "--antenna-log",
        metavar="FILE",
        help="the antenna journal kept for the configuration FILE: with --adif, write it "
        "as ADIF and exit (docs/antenna-log.md)",
    )
    parser.add_argument("--adif", metavar="OUT", help="the ADIF file (.adi) --antenna-log writes")
    parser.add_argument(
        "--from",
        dest="log_from",
        metavar="T",
        help="with --adif: the contacts from T on (ISO 8601 UTC, e.g. 2026-11-28T00:00Z)",
    )
    parser.add_argument(
        "--to", dest="log_to", metavar="T", help="with --adif: the contacts before T (ISO 8601 UTC)"
    )
    parser.add_argument(
        "--station-callsign",
        metavar="CALL",
        help="with --adif: the station's call, written as STATION_CALLSIGN",
    )


def wants_export(args: argparse.Namespace) -> bool:
    """Whether the command line asks for the export (or one of its options)."""
    return bool(
        args.antenna_log or args.adif or args.log_from or args.log_to or args.station_callsign
    )


def open_journal(config: Path) -> JournalReader:
    """The journal kept for ``config``; ``FileNotFoundError`` when there is none yet."""
    from moas_gui.antenna_log.journal import open_reader

    reader: JournalReader = open_reader(config)
    return reader


def _fail(text: str, status: int) -> int:
    print(f"moas-server: {text}", file=sys.stderr)
    return status


def _bounds(args: argparse.Namespace) -> tuple[float | None, float | None, str]:
    """``--from`` and ``--to`` in POSIX seconds (None: not given), or what is wrong."""
    from moas_gui.antenna_log.adif import parse_utc

    found: list[float | None] = []
    for option, text in (("--from", args.log_from), ("--to", args.log_to)):
        if text is None:
            found.append(None)
            continue
        try:
            found.append(parse_utc(text))
        except ValueError as exc:
            return None, None, f"{option}: {exc}"
    start, end = found
    if start is not None and end is not None and start >= end:
        return None, None, f"--from {args.log_from} is not before --to {args.log_to}"
    return start, end, ""


def _utc(seconds: float) -> str:
    from datetime import UTC, datetime  # the export's alone: moas-server --add-operator needs none

    return datetime.fromtimestamp(seconds, UTC).strftime("%Y-%m-%d %H:%M:%S UTC")


def _period(reader: JournalReader, start: float | None, end: float | None) -> Period | None:
    """From ``start`` to ``end``, the journal's own first and last times where not given
    (its last second included); None when one is needed and the journal is empty."""
    from moas_gui.antenna_log.records import Period
    from moas_gui.antenna_log.report import whole_journal

    if start is not None and end is not None:
        return Period(start, end)
    whole = whole_journal(reader)
    if whole is None:
        return None
    return Period(whole.start if start is None else start, whole.end if end is None else end)


def _open(config: Path, opener: Opener) -> tuple[JournalReader | None, str]:
    """The journal of ``config``, or why it cannot be read."""
    import sqlite3

    try:
        return opener(config), ""
    except FileNotFoundError:
        return None, (
            f"{config}: no antenna journal for this file yet (the server keeps one "
            "while it runs with it, unless --no-antenna-log)"
        )
    except ImportError:
        return None, "this build keeps no antenna journal"
    except (OSError, sqlite3.Error) as exc:
        return None, f"{config}: cannot read its antenna journal: {exc}"


def export_antenna_log(args: argparse.Namespace, opener: Opener = open_journal) -> int:
    """Writes ``args.adif`` from the journal of ``args.antenna_log``; the exit status."""
    import sqlite3

    from moas_gui.antenna_log.adif import write_adif

    if not args.antenna_log or not args.adif:
        return _fail(
            "--antenna-log FILE and --adif OUT go together (and --from, --to and "
            "--station-callsign with them)",
            2,
        )
    start, end, problem = _bounds(args)
    if problem:
        return _fail(problem, 2)
    config = Path(args.antenna_log)
    reader, problem = _open(config, opener)
    if reader is None:
        return _fail(problem, 1)
    try:
        period = _period(reader, start, end)
        if period is None:
            return _fail(f"{config}: its antenna journal is empty; nothing to export", 1)
        count = write_adif(reader, period, args.adif, station_callsign=args.station_callsign or "")
    except sqlite3.Error as exc:
        return _fail(f"{config}: cannot read its antenna journal: {exc}", 1)
    except OSError as exc:
        return _fail(f"{args.adif}: cannot write it: {exc.strerror or exc}", 1)
    plural = "" if count == 1 else "s"
    print(f"{args.adif}: {count} contact{plural} from {_utc(period.start)} to {_utc(period.end)}")
    return 0
