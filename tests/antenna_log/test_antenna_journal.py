"""The antenna journal (moas_gui.antenna_log.journal) on a real SQLite file: where it is,
what it keeps, the spans and transmissions read back, the contacts joined to them, and
the retention."""

from __future__ import annotations

import sqlite3
import threading
from pathlib import Path

import pytest

from moas_gui import places
from moas_gui.antenna_log.journal import (
    BATCH,
    MAX_QUEUED,
    SIZE_EVERY,
    AntennaInfo,
    Journal,
    journal_path,
    open_reader,
)
from moas_gui.antenna_log.records import AntennaSpan, HeadingMark, KeySpan, Period
from moas_gui.sources.n1mm_contact import ContactPacket

T0 = 1_700_000_000.0
ALL = Period(T0 - 10_000, T0 + 10_000)


@pytest.fixture
def journal(tmp_path: Path) -> Journal:
    j = Journal(tmp_path / "j.sqlite", clock=lambda: T0 + 5000)
    yield j  # type: ignore[misc]
    j.close()


def qso(cid: str, t: float, call: str = "DL1ABC", *, kind: str = "contactinfo",
        radio_nr: int = 1) -> ContactPacket:
    return ContactPacket(kind, cid, t, call, "14", "CW", 14025.0, 14025.0,  # type: ignore[arg-type]
                         radio_nr, "OP-PC", "K1XX", "CQWW")


def test_the_journal_lives_in_the_data_directory_keyed_by_the_resolved_path(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    one = journal_path(Path("a/station.moas"))
    assert one.parent == places.data_dir() / "antenna-log" == tmp_path / "data" / "moas-gui" / "antenna-log"
    assert one == journal_path(tmp_path / "a" / ".." / "a" / "station.moas")  # same file
    assert one != journal_path(tmp_path / "b" / "station.moas")  # same name, other file
    assert one.name.startswith("station-") and one.suffix == ".sqlite"


def test_it_is_in_wal_mode_with_its_tables(journal: Journal) -> None:
    journal.antenna(1, 1, "tx", "Yagi", at=T0)
    assert journal.flush()
    db = sqlite3.connect(journal.path)
    assert db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    tables = {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    assert {"antenna_changes", "key_events", "headings", "contacts"} <= tables
    db.close()


def test_writes_come_from_one_thread_of_its_own(journal: Journal) -> None:
    names = {t.name for t in threading.enumerate()}
    assert f"antenna journal {journal.path.name}" in names
    before = journal.stats()
    journal.heading("Tower", 45, at=T0)
    assert journal.stats().queued == before.queued + 1
    assert journal.flush()
    assert journal.stats().written == before.written + 1


def test_antenna_spans_run_from_change_to_change_and_an_open_one_to_the_period_end(
        journal: Journal) -> None:
    journal.antenna(1, 1, "tx", "20m Stack", at=T0)
    journal.antenna(1, 1, "rx", "Beverage NE", at=T0 + 1)
    journal.antenna(1, 1, "tx", "20m Stack", at=T0 + 50)  # the same again: one span
    journal.antenna(1, 1, "tx", "40m 4-square", at=T0 + 100)
    journal.antenna(2, 1, "tx", "15m Yagi", at=T0 + 20)
    assert journal.flush()
    spans = journal.antenna_spans(Period(T0 - 10, T0 + 200))
    assert spans == [
        AntennaSpan(1, 1, "tx", "20m Stack", T0, T0 + 100),
        AntennaSpan(1, 1, "rx", "Beverage NE", T0 + 1, T0 + 200),
        AntennaSpan(2, 1, "tx", "15m Yagi", T0 + 20, T0 + 200),
        AntennaSpan(1, 1, "tx", "40m 4-square", T0 + 100, T0 + 200),
    ]
    # a period that begins later still knows what was in force then; spans are clipped
    assert journal.antenna_spans(Period(T0 + 60, T0 + 120)) == [
        AntennaSpan(1, 1, "tx", "20m Stack", T0 + 60, T0 + 100),
        AntennaSpan(1, 1, "rx", "Beverage NE", T0 + 60, T0 + 120),
        AntennaSpan(2, 1, "tx", "15m Yagi", T0 + 60, T0 + 120),
        AntennaSpan(1, 1, "tx", "40m 4-square", T0 + 100, T0 + 120),
    ]


def test_key_spans_carry_the_transmit_antenna_of_their_start(journal: Journal) -> None:
    journal.antenna(1, 1, "tx", "20m Stack", at=T0)
    journal.keyed(1, 1, True, at=T0 + 10)
    journal.keyed(1, 1, True, at=T0 + 11)  # repeated: still one transmission
    journal.keyed(1, 1, False, at=T0 + 15)
    journal.antenna(1, 1, "tx", "40m Dipole", at=T0 + 20)
    journal.keyed(1, 1, True, at=T0 + 30)  # still keyed at the period's end
    journal.keyed(1, 2, False, at=T0 + 31)  # an unkey without a key: nothing
    assert journal.flush()
    assert journal.key_spans(Period(T0, T0 + 40)) == [
        KeySpan(1, 1, "20m Stack", T0 + 10, T0 + 15),
        KeySpan(1, 1, "40m Dipole", T0 + 30, T0 + 40),
    ]
    assert journal.key_spans(Period(T0 + 12, T0 + 14)) == [
        KeySpan(1, 1, "20m Stack", T0 + 12, T0 + 14)]


def test_headings_and_extent(journal: Journal) -> None:
    assert journal.extent() is None
    journal.heading("Tower", 45, at=T0)
    journal.heading("Tower", 90, at=T0 + 60)
    journal.keyed(1, 1, True, at=T0 + 100)
    assert journal.flush()
    assert journal.headings(Period(T0, T0 + 61)) == [HeadingMark("Tower", 45.0, T0),
                                                      HeadingMark("Tower", 90.0, T0 + 60)]
    assert journal.extent() == Period(T0, T0 + 100)


def station_history(journal: Journal) -> None:
    journal.describe([AntennaInfo("20m Stack", "Tower", 0), AntennaInfo("40m Yagi", "Tower", 180),
                      AntennaInfo("Beverage NE")])
    journal.antenna(1, 1, "tx", "20m Stack", path="switch 1 port 1 slot 3", at=T0)
    journal.antenna(1, 1, "rx", "Beverage NE", at=T0)
    journal.heading("Tower", 45, at=T0 + 5)
    journal.keyed(1, 1, True, at=T0 + 10)
    journal.keyed(1, 1, False, at=T0 + 14)
    journal.antenna(1, 1, "tx", "40m Yagi", path="switch 1 port 1 slot 5", at=T0 + 20)
    journal.antenna(1, 1, "rx", "40m Yagi", at=T0 + 20)
    journal.heading("Tower", 60, at=T0 + 40)


def test_a_contact_takes_the_antennas_of_its_radios_last_transmission(journal: Journal) -> None:
    station_history(journal)
    # logged at T0+25 by a computer whose clock is right: the band changed at T0+20,
    # but the contact was made on the transmission of T0+10..14 (the 20 m stack)
    journal.contact(qso("a1", T0 + 25), 1, 1)
    assert journal.flush()
    (c,) = journal.contacts(ALL)
    assert (c.contact_id, c.call, c.station, c.radio) == ("a1", "DL1ABC", 1, 1)
    assert (c.tx_antenna, c.rx_antenna, c.heading) == ("20m Stack", "Beverage NE", 45.0)
    assert c.switch_path == "switch 1 port 1 slot 3"
    assert (c.tx_khz, c.rx_khz, c.operator, c.contest) == (14025.0, 14025.0, "K1XX", "CQWW")


def test_without_a_transmission_near_it_the_antennas_at_its_time(journal: Journal) -> None:
    station_history(journal)
    journal.contact(qso("b1", T0 + 500), 1, 1)  # long after the last transmission
    journal.contact(qso("b2", T0 + 30), 1, 2)  # a radio that never transmitted nor had antennas
    journal.contact(qso("b3", T0 + 30), None, None)  # a radio of no station here
    assert journal.flush()
    b2, b3, b1 = journal.contacts(ALL)
    # the 40 m Yagi points 180 degrees from its rotator's 60
    assert (b1.tx_antenna, b1.rx_antenna, b1.heading) == ("40m Yagi", "40m Yagi", 240.0)
    assert b1.switch_path == "switch 1 port 1 slot 5"
    assert (b2.tx_antenna, b2.rx_antenna, b2.heading, b2.switch_path) == ("", "", None, "")
    assert (b3.station, b3.radio, b3.tx_antenna) == (None, None, "")


def test_the_clock_tolerance_covers_a_logging_computer_behind_or_ahead(journal: Journal) -> None:
    station_history(journal)
    # the contact reached the server at T0+16, just after its transmission, from a
    # computer whose clock is 106 s behind: its moment is when it arrived
    journal.contact(qso("c1", T0 - 90), 1, 1, at=T0 + 16)
    # one 100 s ahead, arriving at T0+22 (after the band change, still the 20 m QSO)
    journal.contact(qso("c3", T0 + 122), 1, 1, at=T0 + 22)
    # 146 s behind: beyond the tolerance, the antennas at its time (none then)
    journal.contact(qso("c2", T0 - 130), 1, 1, at=T0 + 16)
    # re-sent (edited) long after: its timestamp, and the arrival of the first copy
    journal.contact(qso("c4", T0 - 89), 1, 1, at=T0 + 16)
    journal.contact(qso("c4", T0 - 89, "DL1ABD", kind="contactreplace"), 1, 1, at=T0 + 4000)
    assert journal.flush()
    c2, c1, c4, c3 = journal.contacts(ALL)
    assert (c1.tx_antenna, c1.time) == ("20m Stack", T0 - 90)  # its own timestamp kept
    assert c3.tx_antenna == "20m Stack"
    assert c2.tx_antenna == ""
    assert (c4.call, c4.tx_antenna) == ("DL1ABD", "20m Stack")


def test_duplicates_replacements_and_deletions(journal: Journal) -> None:
    station_history(journal)
    journal.contact(qso("d1", T0 + 12, "W1AW"), 1, 1)
    journal.contact(qso("d1", T0 + 12, "W1AW"), 1, 1)  # All Computers: the same ID again
    journal.contact(qso("d2", T0 + 13, "K9XX"), 1, 1)
    journal.contact(qso("d2", T0 + 500, "K9XY", kind="contactreplace"), 1, 1)
    journal.contact(qso("d1", T0 + 12, kind="contactdelete"), 1, 1)
    journal.contact(qso("d9", T0 + 12, kind="contactdelete"), 1, 1)  # never logged: nothing
    assert journal.flush()
    (d2,) = journal.contacts(ALL)
    assert (d2.contact_id, d2.call, d2.time, d2.tx_antenna) == ("d2", "K9XY", T0 + 500, "40m Yagi")
    rows = sqlite3.connect(journal.path).execute(
        "SELECT contact_id, deleted, logger_station, logger_radio FROM contacts ORDER BY 1")
    assert rows.fetchall() == [("d1", 1, "OP-PC", 1), ("d2", 0, "OP-PC", 1)]


def test_contacts_are_read_by_period(journal: Journal) -> None:
    station_history(journal)
    for i in range(5):
        journal.contact(qso(f"p{i}", T0 + 100 * i), 1, 1)
    assert journal.flush()
    assert [c.contact_id for c in journal.contacts(Period(T0 + 100, T0 + 300))] == ["p1", "p2"]


def test_the_reader_opens_an_existing_journal_read_only(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    config = tmp_path / "station.moas"
    with pytest.raises(FileNotFoundError, match="No antenna log for .*station.moas"):
        open_reader(config)
    writer = Journal(journal_path(config))
    station_history(writer)
    writer.contact(qso("r1", T0 + 12), 1, 1)
    assert writer.flush()
    reader = open_reader(config)
    try:
        assert [c.tx_antenna for c in reader.contacts(ALL)] == ["20m Stack"]
        with pytest.raises(RuntimeError, match="read only"):
            reader.keyed(1, 1, True)
    finally:
        reader.close()
        writer.close()


def test_old_rows_are_removed_at_open_but_the_antennas_in_force_stay(tmp_path: Path) -> None:
    path = tmp_path / "old.sqlite"
    day = 86400.0
    old = Journal(path, clock=lambda: T0)
    old.antenna(1, 1, "tx", "Old Yagi", at=T0 - 40 * day)
    old.antenna(1, 1, "tx", "Older Yagi", at=T0 - 50 * day)
    old.antenna(1, 1, "rx", "Gone", at=T0 - 45 * day)
    old.antenna(1, 1, "rx", "Beverage", at=T0 - 1 * day)
    old.keyed(1, 1, True, at=T0 - 40 * day)
    old.keyed(1, 1, False, at=T0 - 40 * day + 1)
    old.heading("Tower", 10, at=T0 - 31 * day)
    old.contact(qso("o1", T0 - 31 * day), 1, 1)
    old.contact(qso("n1", T0 - 29 * day), 1, 1)
    old.close()
    again = Journal(path, clock=lambda: T0)  # 30 days kept
    assert again.flush()
    db = sqlite3.connect(path)
    changes = db.execute("SELECT antenna FROM antenna_changes ORDER BY time").fetchall()
    assert changes == [("Old Yagi",), ("Beverage",)]  # the last tx one is still in force
    assert db.execute("SELECT COUNT(*) FROM key_events").fetchone() == (0,)
    assert db.execute("SELECT COUNT(*) FROM headings").fetchone() == (0,)
    assert db.execute("SELECT contact_id FROM contacts").fetchall() == [("n1",)]
    db.close()
    again.close()


def test_a_journal_over_its_size_cap_loses_its_oldest_half(tmp_path: Path) -> None:
    path = tmp_path / "big.sqlite"
    first = Journal(path, clock=lambda: T0)
    for i in range(20_000):
        first.antenna(1, 1, "tx", f"antenna {i % 7} " + "x" * 40, at=T0 - 20_000 + i)
    first.close()
    size = path.stat().st_size
    capped = Journal(path, clock=lambda: T0, max_bytes=size // 3)
    assert capped.flush()
    db = sqlite3.connect(path)
    low, n = db.execute("SELECT MIN(time), COUNT(*) FROM antenna_changes").fetchone()
    db.close()
    assert n < 20_000 // 2 and low > T0 - 20_000 / 2
    capped.close()
    assert path.stat().st_size <= size // 3


def test_a_write_that_fails_is_logged_and_the_journal_carries_on(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    j = Journal(tmp_path / "f.sqlite", clock=lambda: T0)
    try:
        j.antenna(1, 1, "tx", "Yagi", at=T0)
        assert j.flush()
        db = sqlite3.connect(j.path)
        db.execute("DROP TABLE key_events")
        db.commit()
        db.close()
        j.keyed(1, 1, True, at=T0 + 1)
        assert j.flush()
        assert j.stats().failed == 1
        assert "antenna log" in caplog.text and "carries on" in caplog.text
        j.antenna(1, 1, "tx", "Dipole", at=T0 + 2)
        assert j.flush()
        assert [s.antenna for s in j.antenna_spans(Period(T0, T0 + 3))] == ["Yagi", "Dipole"]
    finally:
        j.close()


# -- the bounds (issue 38): the queue, the dates, the retention across every table ---------

def test_a_contact_flood_is_bounded_dropped_counted_and_said_once(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    j = Journal(tmp_path / "flood.sqlite", clock=lambda: T0)
    blocker = sqlite3.connect(j.path, timeout=0)
    try:
        j.antenna(1, 1, "tx", "Yagi", at=T0)
        assert j.flush()
        blocker.execute("BEGIN EXCLUSIVE")  # the writer cannot write: the queue fills
        flood = 30_000
        for i in range(flood):
            j.contact(qso(f"f{i}", T0 - 60), 1, 1)
        j.antenna(1, 1, "tx", "Dipole", at=T0 + 1)  # antennas still have room
        dropped = j.stats().dropped
        assert dropped >= flood - MAX_QUEUED // 2 - BATCH
        blocker.execute("ROLLBACK")
        assert j.flush(30)
        stats = j.stats()
        assert stats.dropped == dropped and stats.queued + dropped == flood + 2
        lines = [r for r in caplog.records if "dropped (the writer is behind)" in r.getMessage()]
        assert len(lines) == 1 and "in all" in lines[0].getMessage()
        assert [s.antenna for s in j.antenna_spans(Period(T0, T0 + 2))
                if s.role == "tx"] == ["Yagi", "Dipole"]
        db = sqlite3.connect(j.path)
        (kept,) = db.execute("SELECT COUNT(*) FROM contacts").fetchone()
        db.close()
        assert kept <= flood - dropped
    finally:
        blocker.close()
        j.close()


def test_a_contact_dated_before_2000_or_over_a_day_ahead_is_refused_and_counted(
        tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    j = Journal(tmp_path / "dates.sqlite", clock=lambda: T0)
    try:
        j.contact(qso("far", 253_402_214_400.0), 1, 1)  # 9999-12-31
        j.contact(qso("old", 915_148_800.0), 1, 1)  # 1999-01-01
        j.contact(qso("soon", T0 + 86_400 + 60), 1, 1)
        j.contact(qso("ok", T0 + 3600), 1, 1)  # a logging computer's clock an hour fast
        j.contact(qso("gone", 915_148_800.0, kind="contactdelete"), 1, 1)  # a delete's date is not kept
        assert j.flush()
        assert j.stats().refused == 3
        assert [c.contact_id for c in j.contacts(Period(0, 4e11))] == ["ok"]
        lines = [r.getMessage() for r in caplog.records if "refused for their date" in r.getMessage()]
        assert len(lines) == 1 and "far: it is dated more than a day ahead" in lines[0]
    finally:
        j.close()


def test_retention_by_size_takes_every_table_even_rows_of_one_time(tmp_path: Path) -> None:
    path = tmp_path / "contacts.sqlite"
    first = Journal(path, clock=lambda: T0)
    for i in range(60_000):  # a contact flood, every one of the same time
        first.contact(qso(f"c{i:05d}", T0 - 100, call="X" * 12), 1, 1)
        if i % 5_000 == 0:  # within the queue's bound
            first.antenna(1, 1, "tx", f"antenna {i}", at=T0 - 100 + i / 1000)
            assert first.flush(30)
    first.close()
    assert first.stats().dropped == 0 and path.stat().st_size > 3_000_000
    capped = Journal(path, clock=lambda: T0, max_bytes=1_000_000)
    assert capped.flush()
    capped.close()
    assert path.stat().st_size <= 1_000_000
    db = sqlite3.connect(path)
    (contacts,) = db.execute("SELECT COUNT(*) FROM contacts").fetchone()
    tx = db.execute("SELECT antenna FROM antenna_changes ORDER BY time DESC LIMIT 1").fetchone()
    db.close()
    assert 0 < contacts < 60_000 // 4
    assert tx == ("antenna 55000",)  # the antenna in force stays


def test_retention_removes_rows_dated_far_ahead_whatever_wrote_them(tmp_path: Path) -> None:
    path = tmp_path / "ahead.sqlite"
    Journal(path, clock=lambda: T0).close()
    db = sqlite3.connect(path)  # as an earlier version, which took any date, left them
    db.execute("INSERT INTO contacts VALUES ('z', 253402214400, 'ZZ', '14', 'CW', 1, 1, '', "
               "'', NULL, NULL, 0, '', 1, ?)", (T0,))
    db.execute("INSERT INTO contacts VALUES ('a', ?, 'AA', '14', 'CW', 1, 1, '', '', NULL, "
               "NULL, 0, '', 1, ?)", (T0 - 60, T0))
    db.execute("INSERT INTO key_events VALUES (253402214400, 1, 1, 1)")
    db.execute("INSERT INTO headings VALUES (?, 'Tower', 90)", (T0 + 3 * 86400,))
    db.commit()
    db.close()
    again = Journal(path, clock=lambda: T0)
    try:
        assert again.flush()
        extent = again.extent()
        assert extent is not None and extent.end == T0 - 60
        assert [c.contact_id for c in again.contacts(Period(0, 4e11))] == ["a"]
    finally:
        again.close()


def test_a_flood_is_cut_to_the_size_bound_while_the_journal_is_open(tmp_path: Path) -> None:
    path = tmp_path / "open.sqlite"
    j = Journal(path, clock=lambda: T0, max_bytes=1_000_000)
    try:
        for i in range(60_000):  # no reopening, no hourly pass: the writer checks itself
            j.contact(qso(f"c{i:05d}", T0 - 100, call="X" * 12), 1, 1)
            if i % 5_000 == 4_999:
                assert j.flush(60)
        assert j.stats().dropped == 0
        db = sqlite3.connect(path)
        pages, free, size = (db.execute(f"PRAGMA {p}").fetchone()[0]
                             for p in ("page_count", "freelist_count", "page_size"))
        (contacts,) = db.execute("SELECT COUNT(*) FROM contacts").fetchone()
        db.close()
        # cut at each check; what came after the last one is at most a check and a batch
        assert (pages - free) * size <= 1_000_000 + (SIZE_EVERY + BATCH) * 100  # 60k: 3.2 MB
        assert contacts < 60_000 // 2
    finally:
        j.close()
