"""The antenna journal: what the station's antennas, key lines and rotators did, and the
logger's contacts, in one SQLite file per configuration.

Writing never waits: :meth:`Journal.antenna`, :meth:`~Journal.keyed`,
:meth:`~Journal.heading` and :meth:`~Journal.contact` put a small tuple on a queue and
return; one writer thread of the journal's own takes the queue in batches (one
transaction each) and writes them.  The event loop, and the path from a band change to
the switch, never touch the file.  A write that fails is logged (once a minute at most)
and the server carries on.

The queue is bounded: when :data:`MAX_QUEUED` records wait (or half as many, for
contacts, so that a flood of contacts never crowds out the antennas), a new one is
dropped and counted (:meth:`Journal.stats`), with one warning a minute saying how many.
A contact dated before 2000 or more than a day ahead of the clock is refused and
counted the same way (:func:`~moas_gui.antenna_log.records.contact_date_problem`).

Where: ``places.data_dir() / "antenna-log" / "<config stem>-<hash>.sqlite"``, the hash
of the configuration file's resolved path (:func:`journal_path`), so that editing the
file does not start a new journal and two files of the same name do not share one.
WAL mode: the ADIF export and the contest report read while the server writes.

Retention (``docs/antenna-log.md``): at open, and every hour while it is open, rows
older than :data:`KEEP_DAYS` days are removed (but the last antenna of each radio, which
is still in force), and so are rows dated more than a day ahead of the clock; when the
file is still over :data:`MAX_BYTES`, the oldest half of every table's rows goes too,
until it fits, and the file is compacted.  The size is also checked after every
:data:`SIZE_EVERY` rows written, so that a flood is cut when it passes the bound rather
than at the next hourly pass.

Reading (:class:`~moas_gui.antenna_log.records.JournalReader`): antenna spans are built
from consecutive changes of each radio's role (a span still open ends at the end of the
period asked for); key spans from key/unkey rows; each contact is joined to the antennas
by :func:`join_rule` (see there and the doc).
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import queue
import sqlite3
import threading
import time
from bisect import bisect_right
from collections import defaultdict
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final, TypeAlias

from moas_gui import places
from moas_gui.antenna_log.records import (
    AHEAD_CONTACT,
    AntennaSpan,
    Contact,
    ContactPacket,
    HeadingMark,
    KeySpan,
    Period,
    Role,
    contact_date_problem,
)

log = logging.getLogger(__name__)

KEEP_DAYS: Final = 30
"""Rows older than this many days are removed (the antenna still in force stays)."""
MAX_BYTES: Final = 256 * 1024 * 1024
"""A journal over this size loses its oldest rows until it fits (a 48-hour contest
at 200 QSOs an hour takes a few MB: see benchmarks/bench_antenna_log.py)."""
CLOCK_TOLERANCE: Final = 120.0
"""Seconds a logging computer's clock may differ from the server's: see :func:`join_rule`."""
PRUNE_EVERY: Final = 3600.0
"""Seconds between two retention passes while the journal is open."""
MAX_QUEUED: Final = 20_000
"""Records that may wait for the writer (a few MB); past it new ones are dropped and
counted.  Contacts are dropped from half of it."""
BATCH: Final = 2_000
"""The most records one transaction writes."""
SIZE_EVERY: Final = 10_000
"""Rows written between two checks of the file's size (besides the hourly pass)."""
SHED_LOG_INTERVAL: Final = 60.0
"""Seconds between two warnings about dropped or refused records."""
ROLES: Final[tuple[Role, ...]] = ("tx", "rx", "alt", "sub")

_SCHEMA: Final = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS antenna_changes (
    time REAL NOT NULL, station INTEGER NOT NULL, radio INTEGER NOT NULL,
    role TEXT NOT NULL, antenna TEXT NOT NULL, path TEXT NOT NULL DEFAULT '',
    operator TEXT);
CREATE INDEX IF NOT EXISTS antenna_changes_time ON antenna_changes (time);
CREATE INDEX IF NOT EXISTS antenna_changes_radio
    ON antenna_changes (station, radio, role, time);
CREATE TABLE IF NOT EXISTS key_events (
    time REAL NOT NULL, station INTEGER NOT NULL, radio INTEGER NOT NULL,
    keyed INTEGER NOT NULL);
CREATE INDEX IF NOT EXISTS key_events_time ON key_events (time);
CREATE INDEX IF NOT EXISTS key_events_radio ON key_events (station, radio, time);
CREATE TABLE IF NOT EXISTS headings (
    time REAL NOT NULL, rotator TEXT NOT NULL, heading REAL NOT NULL);
CREATE INDEX IF NOT EXISTS headings_time ON headings (time);
CREATE TABLE IF NOT EXISTS antennas (
    name TEXT PRIMARY KEY, rotator TEXT, offset REAL NOT NULL DEFAULT 0);
CREATE TABLE IF NOT EXISTS contacts (
    contact_id TEXT PRIMARY KEY, time REAL NOT NULL, call TEXT NOT NULL,
    band TEXT NOT NULL, mode TEXT NOT NULL, station INTEGER, radio INTEGER,
    operator TEXT NOT NULL, contest TEXT NOT NULL, tx_khz REAL, rx_khz REAL,
    deleted INTEGER NOT NULL DEFAULT 0, logger_station TEXT NOT NULL DEFAULT '',
    logger_radio INTEGER, received REAL NOT NULL);
CREATE INDEX IF NOT EXISTS contacts_time ON contacts (time);
"""

_STOP: Final = object()
GATHER_S: Final = 0.5
"""How long the writer lets rows gather after the first before it commits them together
(one commit, not one a row: a band change on a big station lands as several rows).
A flush (:meth:`Journal.flush`) or closing cuts the wait."""
_Row: TypeAlias = tuple[Any, ...]
"""A row as SQLite gives it, or a queued write."""
_ROWS: Final = frozenset("akhc")
"""The queued writes the queue's bound applies to: antennas, keying, headings, contacts."""


@dataclass(frozen=True, slots=True)
class AntennaInfo:
    """What the join needs to know of a configured antenna: the rotator that turns it
    (by name, as :class:`HeadingMark` names it) and the antenna's offset from it."""

    name: str
    rotator: str | None = None
    offset: float = 0.0


@dataclass(frozen=True, slots=True)
class JournalStats:
    """The journal writer's counts of records queued, written, failed, dropped and
    refused."""

    queued: int
    written: int
    failed: int
    dropped: int = 0
    """Records dropped because :data:`MAX_QUEUED` were waiting."""
    refused: int = 0
    """Contacts refused for their date (before 2000, or more than a day ahead)."""


def journal_path(config_path: Path | str) -> Path:
    """The journal of the configuration at ``config_path`` (keyed by its resolved path)."""
    resolved = Path(config_path).expanduser().resolve()
    digest = hashlib.sha256(str(resolved).encode("utf-8", "surrogatepass")).hexdigest()[:12]
    return places.data_dir() / "antenna-log" / f"{resolved.stem}-{digest}.sqlite"


def open_reader(config_path: Path | str) -> Journal:
    """The existing journal of ``config_path``, opened to read only (the ``--adif``
    export); :class:`FileNotFoundError` saying where it looked when there is none."""
    path = journal_path(config_path)
    if not path.is_file():
        raise FileNotFoundError(f"No antenna log for {config_path}: {path} does not exist "
                                "(the server records one while it runs that configuration, "
                                "unless started with --no-antenna-log)")
    return Journal(path, read_only=True)


class Journal:
    """One configuration's journal: the writer (a thread fed by a queue) and the reader
    (:class:`~moas_gui.antenna_log.records.JournalReader`)."""

    def __init__(self, path: Path, *, read_only: bool = False,
                 clock: Callable[[], float] = time.time, keep_days: float = KEEP_DAYS,
                 max_bytes: int = MAX_BYTES, tolerance: float = CLOCK_TOLERANCE) -> None:
        self.path = Path(path)
        self.clock = clock
        self.keep_days = keep_days
        self.max_bytes = max_bytes
        self.tolerance = tolerance
        self.read_only = read_only
        self._queue: queue.SimpleQueue[object] = queue.SimpleQueue()
        self._queued = self._written = self._failed = 0
        self._shed = {"dropped": 0, "refused": 0}
        """Records dropped for a full queue, contacts refused for their date."""
        self._shed_said = {"dropped": (-SHED_LOG_INTERVAL, 0), "refused": (-SHED_LOG_INTERVAL, 0)}
        """Per kind: when the last warning was written and the count it gave."""
        self._last_error = 0.0
        self._since_size = 0
        """Rows written since the file's size was last compared with its bound."""
        self._read_lock = threading.Lock()
        self._hurry = threading.Event()
        """Set by a flush or close: the writer stops gathering and writes at once."""
        self._thread: threading.Thread | None = None
        if read_only:
            uri = f"{self.path.resolve().as_uri()}?mode=ro"
            self._reader = sqlite3.connect(uri, uri=True, check_same_thread=False)
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            writer = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None)
            writer.execute("PRAGMA journal_mode=WAL")
            writer.execute("PRAGMA synchronous=NORMAL")
            writer.executescript(_SCHEMA)
            self._reader = sqlite3.connect(self.path, check_same_thread=False)
            self._thread = threading.Thread(target=self._write_loop, args=(writer,),
                                            name=f"antenna journal {self.path.name}",
                                            daemon=True)
            self._thread.start()

    # -- writing: any thread, never waits ------------------------------------------------
    def _put(self, item: _Row) -> None:
        if self._thread is None:
            raise RuntimeError(f"{self.path} is open to read only")
        if isinstance(item, tuple) and item[0] in _ROWS:
            waiting = self._queue.qsize()
            if waiting >= (MAX_QUEUED // 2 if item[0] == "c" else MAX_QUEUED):
                self._shed_one("dropped", f"{waiting:,} records wait to be written")
                return
        self._queued += 1
        self._queue.put(item)
        if item is _STOP or (isinstance(item, tuple) and item[0] == "sync"):
            self._hurry.set()

    def antenna(self, station: int, radio: int, role: Role, antenna: str, *, path: str = "",
                operator: str | None = None, at: float | None = None) -> None:
        """``radio`` of ``station`` has ``antenna`` as its ``role`` antenna, as the switch
        confirmed it (``""``: none); ``path`` the relay path, ``operator`` who chose it."""
        self._put(("a", self.clock() if at is None else at, station, radio, role, antenna,
                   path, operator))

    def keyed(self, station: int, radio: int, keyed: bool, *, at: float | None = None) -> None:
        self._put(("k", self.clock() if at is None else at, station, radio, int(keyed)))

    def heading(self, rotator: str, heading: float, *, at: float | None = None) -> None:
        """Rotator ``rotator`` settled on ``heading``."""
        self._put(("h", self.clock() if at is None else at, rotator, float(heading)))

    def contact(self, packet: ContactPacket, station: int | None, radio: int | None, *,
                at: float | None = None) -> None:
        """A contact packet of a logger, mapped to this server's ``station``/``radio``
        (None: none).  A ``contactinfo`` whose ID is known is a duplicate and dropped;
        a ``contactreplace`` replaces; a ``contactdelete`` marks the contact deleted.
        One dated before 2000 or more than a day ahead of the clock is refused (counted)."""
        received = self.clock() if at is None else at
        if packet.kind != "contactdelete" and packet.time is not None:
            problem = contact_date_problem(packet.time, received)
            if problem is not None:
                self._shed_one("refused", f"the last, {packet.contact_id}: {problem}")
                return
        self._put(("c", received, packet, station, radio))

    def _shed_one(self, kind: str, detail: str) -> None:
        """Counts a dropped or refused record; a warning a minute says how many."""
        self._shed[kind] += 1
        now = time.monotonic()
        said_at, said_count = self._shed_said[kind]
        if now - said_at < SHED_LOG_INTERVAL:
            return
        total = self._shed[kind]
        self._shed_said[kind] = (now, total)
        what = ("dropped (the writer is behind)" if kind == "dropped"
                else "refused for their date (before 2000 or more than a day ahead)")
        log.warning("The antenna log %s: %d record%s %s since the last such line, %d in all; "
                    "%s", self.path.name, total - said_count, "" if total - said_count == 1
                    else "s", what, total, detail)

    def describe(self, antennas: Iterable[AntennaInfo]) -> None:
        """The configuration's antennas (their rotators, for the join's heading)."""
        self._put(("d", tuple(antennas)))

    def flush(self, timeout: float = 10.0) -> bool:
        """Wait (off the loop: tests, the export) until everything queued is written."""
        if self._thread is None:
            return True
        done = threading.Event()
        self._queue.put(("sync", done))
        self._hurry.set()
        return done.wait(timeout)

    def close(self, timeout: float = 10.0) -> None:
        """Write what is queued, then close (blocks up to ``timeout``: call it off the loop)."""
        thread, self._thread = self._thread, None
        if thread is not None:
            self._queue.put(_STOP)
            self._hurry.set()
            thread.join(timeout)
        with self._read_lock:
            self._reader.close()

    def stats(self) -> JournalStats:
        return JournalStats(self._queued, self._written, self._failed,
                            self._shed["dropped"], self._shed["refused"])

    # -- the writer thread ------------------------------------------------------------------
    def _write_loop(self, db: sqlite3.Connection) -> None:
        last_prune = -PRUNE_EVERY
        try:
            while True:
                if self.clock() - last_prune >= PRUNE_EVERY or self._over_size(db):
                    last_prune = self.clock()
                    self._guarded(db, lambda: self._prune(db))
                items = [self._queue.get()]
                if self._queue.qsize() < BATCH:  # a backlog is written at once
                    self._hurry.wait(GATHER_S)  # let a band change's rows gather (unless hurried)
                with contextlib.suppress(queue.Empty):
                    while len(items) < BATCH:
                        items.append(self._queue.get_nowait())
                stop = any(item is _STOP for item in items)
                if self._queue.empty() and self._thread is not None:  # hurried and done
                    self._hurry.clear()
                rows = [i for i in items if isinstance(i, tuple) and i[0] != "sync"]
                if rows:
                    self._guarded(db, lambda: self._write(db, rows))  # noqa: B023
                for item in items:
                    if isinstance(item, tuple) and item[0] == "sync":
                        item[1].set()
                if stop:
                    return
        finally:
            db.close()

    def _prune(self, db: sqlite3.Connection) -> None:
        prune(db, self.clock(), self.keep_days, self.max_bytes)
        self._since_size = 0

    def _over_size(self, db: sqlite3.Connection) -> bool:
        """After every :data:`SIZE_EVERY` rows written: is the file over its bound? (A
        flood must not wait for the hourly pass to be cut.)"""
        if self._since_size < SIZE_EVERY:
            return False
        self._since_size = 0
        try:
            return _size(db) > self.max_bytes
        except sqlite3.Error:
            return False

    def _guarded(self, db: sqlite3.Connection, work: Callable[[], None]) -> None:
        try:
            work()
        except sqlite3.Error as exc:
            with contextlib.suppress(sqlite3.Error):
                db.execute("ROLLBACK")
            self._failed += 1
            now = time.monotonic()
            if now - self._last_error >= 60.0:
                self._last_error = now
                log.warning("The antenna log %s could not be written (%s); the server carries "
                            "on without it", self.path, exc)

    def _write(self, db: sqlite3.Connection, rows: list[_Row]) -> None:
        db.execute("BEGIN")
        new_contacts: list[tuple[object, ...]] = []  # in a row: one statement (a flood's)
        for row in rows:
            kind = row[0]
            if kind == "c" and row[2].kind == "contactinfo":
                new_contacts.append(_contact_values(*row[1:]))
                continue
            if new_contacts:
                db.executemany(_NEW_CONTACT, new_contacts)
                new_contacts = []
            if kind == "a":
                db.execute("INSERT INTO antenna_changes VALUES (?, ?, ?, ?, ?, ?, ?)", row[1:])
            elif kind == "k":
                db.execute("INSERT INTO key_events VALUES (?, ?, ?, ?)", row[1:])
            elif kind == "h":
                db.execute("INSERT INTO headings VALUES (?, ?, ?)", row[1:])
            elif kind == "c":
                _write_contact(db, *row[1:])
            elif kind == "d":
                db.execute("DELETE FROM antennas")
                db.executemany("INSERT OR REPLACE INTO antennas VALUES (?, ?, ?)",
                               [(a.name, a.rotator, a.offset) for a in row[1]])
        if new_contacts:
            db.executemany(_NEW_CONTACT, new_contacts)
        db.execute("COMMIT")
        self._written += len(rows)
        self._since_size += len(rows)

    # -- reading: JournalReader -------------------------------------------------------------
    @contextlib.contextmanager
    def _cursor(self) -> Iterator[sqlite3.Connection]:
        with self._read_lock:
            yield self._reader

    def extent(self) -> Period | None:
        with self._cursor() as db:
            lows, highs = [], []
            for table in ("antenna_changes", "key_events", "headings", "contacts"):
                low, high = db.execute(f"SELECT MIN(time), MAX(time) FROM {table}").fetchone()
                if low is not None:
                    lows.append(low)
                    highs.append(high)
        return Period(min(lows), max(highs)) if lows else None

    def antenna_spans(self, period: Period) -> list[AntennaSpan]:
        with self._cursor() as db:
            rows = _rows_in(db, "antenna_changes", "station, radio, role",
                            "station, radio, role, antenna", period)
        return antenna_spans_of(rows, period)

    def key_spans(self, period: Period) -> list[KeySpan]:
        with self._cursor() as db:
            rows = _rows_in(db, "key_events", "station, radio", "station, radio, keyed", period)
            first = min((r[0] for r in rows), default=period.start)
            tx_period = Period(min(first, period.start), period.end)
            tx_rows = _rows_in(db, "antenna_changes", "station, radio, role",
                               "station, radio, role, antenna", tx_period, role="tx")
        return key_spans_of(rows, _SpanIndex(_path_spans(tx_rows, tx_period)), period)

    def headings(self, period: Period) -> list[HeadingMark]:
        with self._cursor() as db:
            rows = db.execute("SELECT rotator, heading, time FROM headings WHERE time >= ? "
                              "AND time < ? ORDER BY time, rowid",
                              (period.start, period.end)).fetchall()
        return [HeadingMark(r, h, t) for r, h, t in rows]

    def contacts(self, period: Period) -> list[Contact]:
        # a contact's moment is within τ of its time; its transmission within τ before that
        wide = Period(period.start - 2 * self.tolerance - 1, period.end + self.tolerance + 1)
        with self._cursor() as db:
            logged = db.execute(
                "SELECT contact_id, time, call, band, mode, station, radio, operator, contest, "
                "tx_khz, rx_khz, received FROM contacts WHERE deleted = 0 AND time >= ? AND time < ? "
                "ORDER BY time, contact_id", (period.start, period.end)).fetchall()
            if not logged:
                return []
            changes = _rows_in(db, "antenna_changes", "station, radio, role",
                               "station, radio, role, antenna, path", wide)
            keys = _rows_in(db, "key_events", "station, radio", "station, radio, keyed", wide)
            marks = _rows_in(db, "headings", "rotator", "rotator, heading", wide)
            antennas = {n: AntennaInfo(n, r, o) for n, r, o in
                        db.execute("SELECT name, rotator, offset FROM antennas")}
        spans = _SpanIndex(_path_spans(changes, wide))
        key_index = _KeyIndex(key_spans_of(keys, spans, wide))
        headings = _HeadingIndex(marks)
        return [join_rule(row, spans, key_index, headings, antennas, self.tolerance)
                for row in logged]


# -- writing a contact --------------------------------------------------------------------------

def _write_contact(db: sqlite3.Connection, received: float, packet: ContactPacket,
                   station: int | None, radio: int | None) -> None:
    if packet.kind == "contactdelete":
        db.execute("UPDATE contacts SET deleted = 1 WHERE contact_id = ?", (packet.contact_id,))
        return
    # a duplicate (same ID) of a contactinfo is dropped; a contactreplace takes every
    # field but when the contact first arrived (what the join times it by)
    db.execute(_NEW_CONTACT if packet.kind == "contactinfo" else _REPLACED_CONTACT,
               _contact_values(received, packet, station, radio))


def _contact_values(received: float, packet: ContactPacket, station: int | None,
                    radio: int | None) -> tuple[object, ...]:
    return (packet.contact_id, packet.time if packet.time is not None else received,
            packet.call, packet.band, packet.mode, station, radio, packet.operator,
            packet.contest, packet.tx_khz, packet.rx_khz, packet.station_name,
            packet.radio_nr, received)


_REPLACED: Final = ("time", "call", "band", "mode", "station", "radio", "operator", "contest",
                    "tx_khz", "rx_khz", "logger_station", "logger_radio")
_INSERT_CONTACT: Final = ("INSERT INTO contacts VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, 0, ?, ?, ?) "
                          "ON CONFLICT (contact_id) ")
_NEW_CONTACT: Final = _INSERT_CONTACT + "DO NOTHING"
"""A contactinfo: a duplicate (same ID) is dropped."""
_REPLACED_CONTACT: Final = (_INSERT_CONTACT + "DO UPDATE SET "
                            + ", ".join(f"{c} = excluded.{c}" for c in _REPLACED))
"""A contactreplace: every field but when the contact first arrived (what the join times
it by)."""


# -- retention ------------------------------------------------------------------------------------

_TABLES: Final = ("antenna_changes", "key_events", "headings", "contacts")
_IN_FORCE: Final = ("SELECT r FROM (SELECT rowid AS r, ROW_NUMBER() OVER (PARTITION BY "
                    "station, radio, role ORDER BY time DESC, rowid DESC) AS n FROM "
                    "antenna_changes) WHERE n = 1")
"""The antenna each radio's role had last: it is still in force, and kept."""


def prune(db: sqlite3.Connection, now: float, keep_days: float, max_bytes: int) -> int:
    """Remove rows older than ``keep_days`` (but each radio's antennas still in force) and
    rows dated more than a day after ``now``, then, while the file is over ``max_bytes``,
    the oldest half of every table's rows (by their time; the antennas in force stay).
    Returns how many rows went."""
    gone = _remove_outside(db, now - keep_days * 86400.0, now + AHEAD_CONTACT)
    size = _size(db)
    rounds = 0
    while size > max_bytes and rounds < 32:
        went = _remove_oldest_half(db)
        if not went:
            break
        gone += went
        db.execute("VACUUM")
        size, rounds = _size(db), rounds + 1
    return gone


def _size(db: sqlite3.Connection) -> int:
    pages = db.execute("PRAGMA page_count").fetchone()[0]
    free = db.execute("PRAGMA freelist_count").fetchone()[0]
    return int((pages - free) * db.execute("PRAGMA page_size").fetchone()[0])


def _remove_outside(db: sqlite3.Connection, cutoff: float, ahead: float) -> int:
    """Rows before ``cutoff`` (but the antennas in force) and rows after ``ahead``."""
    db.execute("BEGIN")
    gone = db.execute(f"DELETE FROM antenna_changes WHERE time < ? AND rowid NOT IN "
                      f"({_IN_FORCE})", (cutoff,)).rowcount
    for table in _TABLES[1:]:
        gone += db.execute(f"DELETE FROM {table} WHERE time < ?", (cutoff,)).rowcount
    for table in _TABLES:
        gone += db.execute(f"DELETE FROM {table} WHERE time > ?", (ahead,)).rowcount
    db.execute("COMMIT")
    return gone


def _remove_oldest_half(db: sqlite3.Connection) -> int:
    """The oldest half of each table's rows (ties by age of writing); the antennas in force
    stay."""
    db.execute("BEGIN")
    gone = 0
    for table in _TABLES:
        keep = f" WHERE rowid NOT IN ({_IN_FORCE})" if table == "antenna_changes" else ""
        (count,) = db.execute(f"SELECT COUNT(*) FROM {table}{keep}").fetchone()
        gone += db.execute(
            f"DELETE FROM {table} WHERE rowid IN (SELECT rowid FROM {table}{keep} "
            "ORDER BY time, rowid LIMIT ?)", ((count + 1) // 2,)).rowcount
    db.execute("COMMIT")
    return gone


# -- building spans -------------------------------------------------------------------------------

def _rows_in(db: sqlite3.Connection, table: str, group: str, columns: str, period: Period,
             role: str | None = None) -> list[_Row]:
    """``time, columns...`` of the rows in ``period`` and, for each ``group``, the last
    row before it (what was in force when the period began), oldest first."""
    where = "" if role is None else f" AND role = '{role}'"
    # the latest row of each group before the period (the last written wins a tie)
    before = db.execute(
        f"SELECT time, {columns} FROM (SELECT time, {columns}, ROW_NUMBER() OVER "
        f"(PARTITION BY {group} ORDER BY time DESC, rowid DESC) AS n FROM {table} "
        f"WHERE time < ?{where}) WHERE n = 1", (period.start,)).fetchall()
    inside = db.execute(
        f"SELECT time, {columns} FROM {table} WHERE time >= ? AND time < ?{where} "
        "ORDER BY time, rowid", (period.start, period.end)).fetchall()
    return sorted(before, key=lambda r: r[0]) + inside


def _clip(start: float, end: float, period: Period) -> tuple[float, float] | None:
    start, end = max(start, period.start), min(end, period.end)
    return (start, end) if end > start else None


@dataclass(frozen=True, slots=True)
class _PathSpan:
    span: AntennaSpan
    path: str


def antenna_spans_of(rows: Sequence[_Row], period: Period) -> list[AntennaSpan]:
    """Spans from change rows ``(time, station, radio, role, antenna[, path])`` (oldest
    first): each lasts until the next change of its radio's role; the last until
    ``period.end``.  A change to the antenna already in force continues its span."""
    return [p.span for p in _path_spans(rows, period)]


def _path_spans(rows: Sequence[_Row], period: Period) -> list[_PathSpan]:
    by_key: dict[_Row, list[_Row]] = defaultdict(list)
    for row in rows:
        by_key[row[1:4]].append(row)
    out: list[_PathSpan] = []
    for (station, radio, role), changes in by_key.items():
        merged = [r for i, r in enumerate(changes) if i == 0 or r[4] != changes[i - 1][4]]
        for i, row in enumerate(merged):
            end = float(merged[i + 1][0]) if i + 1 < len(merged) else period.end
            clipped = _clip(float(row[0]), end, period)
            if clipped is not None:
                span = AntennaSpan(int(station), int(radio), role, str(row[4]), *clipped)
                out.append(_PathSpan(span, str(row[5]) if len(row) > 5 else ""))
    out.sort(key=lambda p: (p.span.start, p.span.station, p.span.radio,
                            ROLES.index(p.span.role)))
    return out


class _SpanIndex:
    """The span of a radio's role in force at a time."""

    def __init__(self, spans: Iterable[_PathSpan]) -> None:
        self._by: dict[tuple[int, int, str], list[_PathSpan]] = defaultdict(list)
        for entry in spans:
            s = entry.span
            self._by[(s.station, s.radio, s.role)].append(entry)
        self._starts = {k: [e.span.start for e in v] for k, v in self._by.items()}

    def at(self, station: int, radio: int, role: str, when: float) -> _PathSpan | None:
        key = (station, radio, role)
        i = bisect_right(self._starts.get(key, []), when) - 1
        if i < 0:
            return None
        entry = self._by[key][i]
        return entry if entry.span.end > when else None


def key_spans_of(rows: Sequence[_Row], tx: _SpanIndex,
                 period: Period) -> list[KeySpan]:
    """Transmissions from key rows ``(time, station, radio, keyed)``; each carries the
    transmit antenna in force when it began."""
    open_at: dict[tuple[int, int], float] = {}
    out: list[KeySpan] = []

    def close(key: tuple[int, int], end: float) -> None:
        start = open_at.pop(key)
        clipped = _clip(start, end, period)
        if clipped is not None:
            found = tx.at(key[0], key[1], "tx", start)
            out.append(KeySpan(key[0], key[1], found.span.antenna if found else "", *clipped))

    for t, station, radio, keyed in rows:
        key = (int(station), int(radio))
        if keyed and key not in open_at:
            open_at[key] = float(t)
        elif not keyed and key in open_at:
            close(key, float(t))
    for key in list(open_at):
        close(key, period.end)
    out.sort(key=lambda s: (s.start, s.station, s.radio))
    return out


class _KeyIndex:
    def __init__(self, spans: Iterable[KeySpan]) -> None:
        self._by: dict[tuple[int, int], list[KeySpan]] = defaultdict(list)
        for s in spans:
            self._by[(s.station, s.radio)].append(s)
        self._starts = {k: [s.start for s in v] for k, v in self._by.items()}

    def last_before(self, station: int, radio: int, when: float,
                    tolerance: float) -> KeySpan | None:
        """The radio's last transmission begun at or before ``when``, unless it ended
        more than ``tolerance`` before it."""
        key = (station, radio)
        i = bisect_right(self._starts.get(key, []), when) - 1
        if i < 0:
            return None
        span = self._by[key][i]
        return span if span.end >= when - tolerance else None


class _HeadingIndex:
    def __init__(self, rows: Iterable[_Row]) -> None:
        self._by: dict[str, list[tuple[float, float]]] = defaultdict(list)
        for t, rotator, heading in rows:
            self._by[str(rotator)].append((float(t), float(heading)))
        for marks in self._by.values():
            marks.sort()
        self._times = {k: [t for t, _ in v] for k, v in self._by.items()}

    def at(self, rotator: str, when: float) -> float | None:
        i = bisect_right(self._times.get(rotator, []), when) - 1
        return None if i < 0 else self._by[rotator][i][1]


def join_rule(row: _Row, spans: _SpanIndex, keys: _KeyIndex,
              headings: _HeadingIndex, antennas: dict[str, AntennaInfo],
              tolerance: float) -> Contact:
    """One contact with its antennas.  With its timestamp ``T`` (the logging computer's
    clock), the time ``R`` it reached this server (the server's clock) and the
    tolerance ``τ`` (:data:`CLOCK_TOLERANCE`):

    * its moment ``M`` is ``R`` when ``|T - R| <= τ`` (a logger sends the packet as the
      QSO is logged: the difference is the logging computer's clock error, and ``R`` is
      the moment on the journal's own clock), else ``T`` (a contact edited or re-sent
      later, or a clock off by more than ``τ``); a ``contactreplace`` keeps the ``R`` of
      the contact it replaces;
    * when its radio has a transmission that began at or before ``M`` and ended no more
      than ``τ`` before ``M``, the last such one is the contact's: its transmit antenna
      (the one in force when it began), the receive antenna in force then, and the heading
      in force at its end;
    * otherwise the transmit and receive antennas in force at ``M``, and the heading then;
    * the heading is the last settled heading of the rotator that turns the transmit
      antenna, plus the antenna's offset (None when no rotator turns it or none is known);
    * ``switch_path`` is the relay path the transmit antenna was confirmed on.
    """
    (cid, t, call, band, mode, station, radio, operator, contest, tx_khz, rx_khz,
     received) = row
    when = float(t)
    moment = float(received) if abs(float(received) - when) <= tolerance else when
    tx_ant = rx_ant = path = ""
    heading: float | None = None
    if station is not None and radio is not None:
        st, rd = int(station), int(radio)
        key = keys.last_before(st, rd, moment, tolerance)
        at, heading_at = (key.start, key.end) if key is not None else (moment, moment)
        tx = spans.at(st, rd, "tx", at)
        rx = spans.at(st, rd, "rx", at)
        tx_ant = key.antenna if key is not None and key.antenna else (tx.span.antenna if tx else "")
        rx_ant = rx.span.antenna if rx else ""
        path = tx.path if tx is not None and tx.span.antenna == tx_ant else ""
        info = antennas.get(tx_ant)
        if info is not None and info.rotator:
            value = headings.at(info.rotator, heading_at)
            heading = None if value is None else (value + info.offset) % 360.0
    return Contact(str(cid), when, str(call), str(band), str(mode),
                   None if station is None else int(station),
                   None if radio is None else int(radio),
                   tx_ant, rx_ant, path, heading, str(operator), str(contest),
                   None if tx_khz is None else float(tx_khz),
                   None if rx_khz is None else float(rx_khz))


__all__ = [
    "CLOCK_TOLERANCE",
    "KEEP_DAYS",
    "MAX_BYTES",
    "MAX_QUEUED",
    "ROLES",
    "AntennaInfo",
    "Journal",
    "JournalStats",
    "journal_path",
    "open_reader",
    "prune",
]
