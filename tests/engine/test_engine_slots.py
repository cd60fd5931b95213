"""Switch slots for configurations with more antennas than a switch has numbers."""

from __future__ import annotations

import pytest
from engine_builders import antenna, config, engine, pair, radio, table_problems

from moas_gui.config.model import Switch
from moas_gui.engine import Engine, Unavailable
from moas_gui.engine.slots import UNKNOWN_TR_SETTLE_S


def _many(count: int = 80, indicate_tr: bool = True) -> Engine:
    """``count`` antennas on 20 m, each conflicting only with itself (so no two share a
    class), two radios on one switch: far more slot keys than 63."""
    antennas = [antenna(i, (20,), {(1, 1): [i % 60], (1, 2): [i % 60]}, fast=(i,))
                for i in range(count)]
    return engine(config(antennas, [radio(1, 1, 1), radio(1, 2, 2)],
                         switches=[Switch(1, "emulator", indicate_tr=indicate_tr)]))


def test_small_configurations_get_fixed_slots() -> None:
    e = engine("multi-multi-20")               # 86 antennas, 19 classes
    first = e.slot_of(1, 166, 1, 1)
    assert first is not None
    e.set_frequency(1, 1, 14025)
    e.select(1, 1, 166)
    assert e.slot_of(1, 166, 1, 1) == first
    assert table_problems(e) == []


def test_more_antennas_than_slots_are_given_slots_as_they_come_into_use() -> None:
    e = _many()
    e.set_frequency(1, 1, 14025, now=0)
    e.set_frequency(1, 2, 14100, now=0)
    for i in range(2, 80):
        e.select(1, 1, i, now=float(i))
        assert pair(e, 1, 1) == (i, i)
        assert table_problems(e) == [], i
    slots = {e.slot_of(1, i, 1, 1) for i in range(70, 80)}
    assert None not in slots and all(0 <= s <= 62 for s in slots)  # type: ignore[operator]


def test_slot_given_up_while_transmitting_keeps_its_antenna_until_receive() -> None:
    e = _many()
    e.set_frequency(1, 1, 14025, now=0)
    e.set_frequency(1, 2, 14100, now=0)
    held = e.slot_of(1, 0, 1, 1)
    e.set_transmitting(1, 1, True, now=1)
    e.select(1, 1, 70, now=2)                  # antenna 0 given up while transmitting
    t = 3.0
    with pytest.raises(Unavailable, match="no free antenna slot"):
        for i in range(2, 70):
            e.select(1, 2, i, now=t)
            t += 1
            assert e.slot_of(1, 0, 1, 1) == held   # never reused meanwhile
    before = e.radios()
    assert e.switch_states()[1].station(1).tx == e.slot_of(1, 70, 1, 1)
    e.set_transmitting(1, 1, False, now=t)
    t += 5
    for i in range(30, 69):
        e.select(1, 2, i, now=t)
        t += 1
    assert table_problems(e) == []
    assert before != e.radios()


def test_switch_without_transmit_reports_settles_after_a_while() -> None:
    e = _many(indicate_tr=False)
    e.set_frequency(1, 1, 14025, now=0)
    e.set_frequency(1, 2, 14100, now=0)
    t = 1.0
    for i in range(2, 63):                     # 2 + 61 keys: every slot given
        e.select(1, 2, i, now=t)
        t += 0.01
    with pytest.raises(Unavailable):
        e.select(1, 2, 63, now=t)
    assert pair(e, 1, 2) == (62, 62)
    e.select(1, 2, 63, now=t + UNKNOWN_TR_SETTLE_S + 1)
    assert pair(e, 1, 2) == (63, 63)
    assert table_problems(e) == []
