"""What the running server records (moas_gui.antenna_log.recorder), against a real engine
on the small station and a real journal file: only what the box confirms, once per
change, with the operator who asked; settled headings only; contacts of unknown radios
kept without a station."""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path

import pytest

from moas_gui.antenna_log.journal import Journal
from moas_gui.antenna_log.recorder import AntennaRecorder, switch_path
from moas_gui.config import load_config
from moas_gui.engine import NO_ANTENNA, Engine
from moas_gui.sources.n1mm_contact import ContactPacket

SMALL = Path(__file__).resolve().parents[2] / "examples" / "small-station.moas"


class Clock:
    now = 1_000.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def setup(tmp_path: Path) -> Iterator[tuple[AntennaRecorder, Engine, Journal, Clock]]:
    config = load_config(SMALL).unwrap()
    engine = Engine(config)
    journal = Journal(tmp_path / "j.sqlite")
    clock = Clock()
    yield AntennaRecorder(journal, config, engine, clock=clock), engine, journal, clock
    journal.close()


def rows(journal: Journal, sql: str) -> list[tuple[object, ...]]:
    assert journal.flush()
    db = sqlite3.connect(journal.path)
    try:
        return db.execute(sql).fetchall()
    finally:
        db.close()


def slots_for(engine: Engine, station: int, radio: int) -> tuple[int, int, int]:
    view = engine.radio_view(station, radio)

    def slot(antenna: int | None) -> int:
        if antenna is None:
            return NO_ANTENNA
        found = engine.slot_of(1, antenna, station, radio)
        assert found is not None
        return found
    return slot(view.tx), slot(view.rx), slot(view.alt)


def test_only_what_the_box_confirms_is_recorded_once(
        setup: tuple[AntennaRecorder, Engine, Journal, Clock]) -> None:
    recorder, engine, journal, clock = setup
    engine.set_frequency(1, 1, 14025.0)
    wanted = slots_for(engine, 1, 1)
    recorder.landed(1, 1, (NO_ANTENNA,) * 3)  # the box holds nothing yet: not landed
    assert rows(journal, "SELECT role, antenna FROM antenna_changes") == [("alt", "")]
    clock.now = 1_005.0
    recorder.landed(1, 1, wanted)
    recorder.landed(1, 1, wanted)  # the same again: nothing more
    recorder.landed(1, 3, wanted)  # a port of no radio: nothing
    tribander = "Triband Yagi 20-15-10"
    assert rows(journal, "SELECT time, role, antenna, path FROM antenna_changes "
                         "WHERE antenna != '' ORDER BY rowid") == [
        (1_005.0, "tx", tribander, switch_path(1, 1, wanted[0])),
        (1_005.0, "rx", tribander, switch_path(1, 1, wanted[1])),
    ]
    assert switch_path(1, 2, 5) == "switch 1 port 2 slot 5"


def test_an_operators_request_names_the_change_that_lands_after_it(
        setup: tuple[AntennaRecorder, Engine, Journal, Clock]) -> None:
    recorder, engine, journal, clock = setup
    engine.set_frequency(1, 1, 14025.0)
    recorder.landed(1, 1, slots_for(engine, 1, 1))
    engine.set_frequency(1, 1, 7025.0)
    recorder.chosen_by("Alice", {(1, 1)})
    clock.now += 2
    recorder.landed(1, 1, slots_for(engine, 1, 1))
    engine.set_frequency(1, 1, 14025.0)
    clock.now += 60  # long after her request: a change of its own
    recorder.landed(1, 1, slots_for(engine, 1, 1))
    assert rows(journal, "SELECT antenna, operator FROM antenna_changes WHERE role = 'tx' "
                         "ORDER BY rowid") == [
        ("Triband Yagi 20-15-10", None), ("40 m dipole (also 15 m)", "Alice"),
        ("Triband Yagi 20-15-10", None)]


def test_key_events_headings_and_contacts(
        setup: tuple[AntennaRecorder, Engine, Journal, Clock]) -> None:
    recorder, _engine, journal, clock = setup
    recorder.transmitting(1, 1, False)  # not keyed already: nothing
    recorder.transmitting(1, 1, True)
    recorder.transmitting(1, 1, True)
    recorder.rotator(1, 80, moving=True, online=True)  # turning: not settled
    recorder.rotator(1, 90, moving=False, online=True)
    recorder.rotator(1, 90, moving=False, online=True)  # the same: nothing
    recorder.rotator(1, 120, moving=False, online=False)  # offline: not trusted
    recorder.rotator(1, None, moving=False, online=True)
    clock.now = 1_800_000_000.0  # a contact is dated from 2000 to a day ahead of the clock
    packet = ContactPacket("contactinfo", "c1", 1_800_000_000.0, "W1AW")
    recorder.contact(packet, 1, 2)
    recorder.contact(ContactPacket("contactinfo", "c2", 1_800_000_000.0, "K1AA"), 1, 7)  # no radio 7
    recorder.stopping()  # the transmission still open ends
    assert rows(journal, "SELECT keyed FROM key_events ORDER BY rowid") == [(1,), (0,)]
    assert rows(journal, "SELECT rotator, heading FROM headings") == [("Tribander", 90.0)]
    assert rows(journal, "SELECT contact_id, station, radio, logger_radio FROM contacts "
                         "ORDER BY 1") == [("c1", 1, 2, 1), ("c2", None, None, 1)]
    assert rows(journal, "SELECT name, rotator, offset FROM antennas WHERE rotator IS NOT NULL"
                ) == [("Triband Yagi 20-15-10", "Tribander", 0.0)]


def test_a_sub_receiver_on_its_own_port_is_its_main_radios_sub_role(tmp_path: Path) -> None:
    config = load_config(SMALL.with_name("ms-one-amp.moas")).unwrap()  # 1/3 is 1/1's sub
    engine = Engine(config)
    journal = Journal(tmp_path / "sub.sqlite")
    try:
        recorder = AntennaRecorder(journal, config, engine, clock=Clock())
        engine.set_frequency(1, 3, 14025.0)
        view = engine.radio_view(1, 3)
        assert view.rx is not None
        rx_slot = engine.slot_of(1, view.rx, 1, 3)
        assert rx_slot is not None
        recorder.landed(1, 3, (NO_ANTENNA, (rx_slot + 1) % 32, NO_ANTENNA))  # not yet
        recorder.landed(1, 3, (NO_ANTENNA, rx_slot, NO_ANTENNA))
        assert rows(journal, "SELECT station, radio, role, antenna FROM antenna_changes") == [
            (1, 1, "sub", recorder.name(view.rx))]
    finally:
        journal.close()
