"""The emulated MOAS II reset and loaded again while a station's key line stays
high, as the switch programming manual has it: ``*0`` is the power-up state
(inactive, every relay open, every station in wait mode); after ``*1`` the
transmitting station's antenna changes wait for the end of its transmission in
wait mode, and in interrupt mode come after its inhibit and the interrupt
delay, the slow way.  And the record of every relay change, key change and
reset, with each station's key state, that tests read."""

from __future__ import annotations

import pytest

from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.record import Entry, EntryCause, Record
from moas_gui.hw.moas2.emulator.station import StationPhase
from moas_gui.hw.moas2.emulator.stepped import SteppedBox

LOAD = "&1;!1B112;!2B234;"
"""A small load: every pair fast, station 1 on antenna 1 (relays 1 2), station 2 on
antenna 2 (relays 3 4)."""


def loaded_box(events: str = "") -> SteppedBox:
    box = SteppedBox(active=True, events=events)
    box.send(LOAD)
    box.settle()
    return box


# --------------------------------------------------------------------------- reset under a key


def test_a_reset_under_a_transmitting_station_opens_every_relay() -> None:
    box = loaded_box()
    box.key(1, True, at=10)
    assert box.relays == {1, 2, 3, 4}
    box.send("*0;", at=20)
    assert box.relays == set()
    view = box.model.view()
    assert not view.active
    assert view.station(1).key and view.station(1).closed == frozenset()
    assert view.station(1).mode.name == "WAIT"


def test_after_a_reload_a_keyed_station_in_wait_mode_gets_its_antenna_when_it_unkeys() -> None:
    box = loaded_box("A")
    box.key(1, True, at=10)
    box.send("*0;", at=20)
    box.send("*A;" + LOAD, at=21)
    out = box.send("*1;", at=22)
    # station 2 receives: its antenna is taken at once; station 1 transmits on nothing and
    # takes only its receive antenna (whose relays are not closed while it transmits)
    assert box.relays == {3, 4}
    assert "!1f1;" in out and "!1F1;" not in out
    assert box.station(1).transmitting and box.station(1).pending == (("T", 1),)
    box.wait(500)
    assert box.relays == {3, 4} and not box.inhibited(1)
    assert box.key(1, False, at=600) == "!1F1;"
    assert box.relays == {1, 2, 3, 4}


def test_after_a_reload_a_keyed_station_in_interrupt_mode_is_inhibited_then_switched_slowly(
) -> None:
    box = loaded_box()
    box.key(1, True, at=10)
    box.send("*0;", at=20)
    box.send("*A;/I1;]5;[20;" + LOAD, at=21)
    assert box.station(1).mode.name == "INTERRUPT"
    box.send("*1;", at=30)
    assert box.relays == {3, 4}
    assert box.inhibited(1) and box.station(1).phase is StationPhase.INTERRUPT
    box.wait(34)
    assert box.relays == {3, 4}
    assert box.wait(35) == "!1F1;"  # the relays move after the interrupt delay ...
    assert box.relays == {1, 2, 3, 4}
    assert box.inhibited(1) and box.station(1).phase is StationPhase.SLOW  # ... the slow way
    box.wait(54)
    assert box.inhibited(1)
    box.wait(55)
    assert not box.inhibited(1) and box.station(1).phase is StationPhase.TRANSMIT


def test_a_station_keyed_while_the_box_is_inactive_transmits_once_it_is_active() -> None:
    box = SteppedBox(events="T")
    box.key(2, True, at=1)  # no T/R event while inactive
    box.send("!2B234;")
    assert box.send("*1;", at=5) == "<2};"  # on the air, on no antenna yet
    assert box.relays == set()
    assert box.key(2, False, at=9) == ">2};"
    assert box.relays == {3, 4}


def test_extra_relays_of_a_keyed_station_also_wait_after_a_reload() -> None:
    box = SteppedBox()
    box.key(1, True)
    box.send("!1B112;!1X09;*1;")
    assert box.relays == set()
    box.key(1, False, at=5)
    assert box.relays == {1, 2}
    box.key(1, True, at=10)
    assert box.relays == {1, 2, 9}


# --------------------------------------------------------------------------- the record


def test_the_record_shows_each_relay_change_with_the_key_states() -> None:
    box = loaded_box()
    start = box.model.record.written
    box.key(1, True, at=10)
    box.send("!2B156;", at=20)
    box.key(1, False, at=30)
    entries = box.model.record.after(start)
    assert [(e.event, e.cause) for e in entries] == [
        (EntryCause.KEY, "key 1"), (EntryCause.RELAYS, "!2B156;"), (EntryCause.KEY, "unkey 1")]
    moved = entries[1]
    assert moved.keyed == {1}
    assert moved.station_relays(1) == {1, 2} and moved.station_relays(2) == {5, 6}
    assert moved.relays == {1, 2, 5, 6} and moved.active
    assert entries[2].keyed == frozenset()


def test_the_record_shows_a_reset_with_the_key_states_of_that_moment() -> None:
    box = loaded_box()
    box.key(2, True, at=10)
    start = box.model.record.written
    box.send("*0;", at=20)
    reset, opened = box.model.record.after(start)
    assert (reset.event, reset.cause, reset.keyed) == (EntryCause.RESET, "*0;", {2})
    assert reset.relays == {1, 2, 3, 4}  # what the reset met
    assert (opened.event, opened.relays, opened.active) == (EntryCause.RELAYS, frozenset(), False)
    assert opened.station_relays(2) == frozenset() and opened.keyed == {2}
    assert box.model.record.resets == 1


def test_the_record_shows_relays_moved_by_a_timer() -> None:
    box = SteppedBox(active=True)
    box.send("\\1100;!1B112;")  # receive delay 100 ms
    box.settle()
    box.key(1, True, at=0)
    box.send("!1B234;", at=1)
    start = box.model.record.written
    box.key(1, False, at=10)
    box.wait(200)
    causes = [(e.event, e.cause, sorted(e.relays)) for e in box.model.record.after(start)]
    assert causes == [(EntryCause.KEY, "unkey 1", [1, 2]), (EntryCause.RELAYS, "timer", [3, 4])]


def test_the_record_is_bounded_and_numbered() -> None:
    record = Record(size=3)
    for seq in range(1, 6):
        record.add(Entry(seq, 0.0, EntryCause.KEY, "key 1", True, frozenset(), frozenset({1}),
                         (frozenset(),) * 6, frozenset()))
    assert [e.seq for e in record] == [3, 4, 5]
    assert [e.seq for e in record.after(1)] == [3, 4, 5]  # 2 is gone: the reader can tell
    assert [e.seq for e in record.after(4)] == [5]
    assert record.after(5) == []
    entry = record.last
    assert entry is not None and Entry.from_json(entry.as_json()) == entry


@pytest.mark.asyncio
async def test_the_real_time_box_keeps_the_same_record() -> None:
    box = EmulatedBox()
    box.receive(b"*1;&1;!1B112;")
    box.set_tr(1, True)
    assert [(e.event, e.cause) for e in box.record] == [
        (EntryCause.RELAYS, "!1B112;"), (EntryCause.KEY, "key 1")]
    assert box.record.last is not None and box.record.last.keyed == {1}
    box.close()
