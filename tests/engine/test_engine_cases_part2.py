"""The four cases an independent checker found in shared transmit antennas, partners,
alternate paths, alternate antennas and sub receivers (issue 25), each replayed from its
file in ``tests/engine/engine_cases/`` (a complete ``.moas``, the events, and what was seen), and
each held against the manual's text.

The state the engine wants for the switch is also loaded into the emulated firmware, so
the conflict-table case is judged by the box's own conflict resolver.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from engine_builders import example
from engine_invariants import Facts, violations

from moas_gui.cli import server
from moas_gui.config import parse_config
from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, EngineError
from moas_gui.hw.moas2.emulator import EmulatorModel
from moas_gui.hw.moas2.sync import difference, initialise

CASES = Path(__file__).parent / "engine_cases"


def _case(name: str) -> tuple[dict[str, Any], Config]:
    data = json.loads((CASES / name).read_text())
    result = parse_config(json.dumps(data["moas"]), name)
    assert result.config is not None, result.problems
    return data, result.config


def _replay(cfg: Config, events: list[dict[str, Any]]) -> Engine:
    e = Engine(cfg, now=0.0)
    for i, ev in enumerate(events):
        now = 1.0 + i
        if ev["op"] == "frequency":
            e.set_frequency(ev["station"], ev["radio"], ev["khz"], now=now)
        else:
            station, radio, antenna, target, exclusive = ev["args"]
            e.select(station, radio, antenna, target, exclusive, now=now)
    return e


def _set_flag(cfg: Config, ref: RadioRef, **flags: bool) -> Config:
    radios = tuple(replace(r, **flags) if r.ref == ref else r for r in cfg.radios)
    return replace(cfg, radios=radios)


# -- 1. two paths of one antenna (5.8) ----------------------------------------------------------

def test_alternate_paths_are_one_antenna_for_two_radios() -> None:
    """5.8: "the MOAS server considers them to be different antennas. The configuration file
    specifies that they are alternates for each other"; 1.1.1: "The operator will not be able
    to select that antenna unless it is configured to be shared"."""
    data, cfg = _case("same-antenna.json")
    e = _replay(cfg, data["events"])
    path_group = {23, 30}
    holders = {(v.station, v.radio) for v in e.radios() if {v.tx, v.rx} & path_group}
    # radio 5 is radio 1's sub receiver; radio 2 is another radio's family
    assert (1, 5) in holders
    assert (1, 2) not in holders, e.radio_view(1, 2)
    assert violations(e, Facts.of(cfg)) == []
    # nor can radio 2 press the other path while radio 5 listens on this one
    with pytest.raises(EngineError, match="in use by station 1 radio 5"):
        e.select(1, 2, 30, "both", False, now=10.0)


def test_a_sub_receiver_without_a_port_keeps_its_relays_when_its_main_radio_has_none() -> None:
    """6.10's sub receiver rides on its main radio's port: radio 1 has no antenna here, yet
    radio 5 listens on 23, so port 1 must close radio 5's relays for 23 (relay 7 at 3986.5)."""
    data, cfg = _case("same-antenna.json")
    e = _replay(cfg, data["events"])
    assert e.radio_view(1, 1).rx is None and e.radio_view(1, 5).rx == 23
    port1 = e.switch_states()[1].station(1)
    assert port1.rx == e.slot_of(1, 23, 1, 1)
    assert port1.rx_relays == frozenset({7})


# -- 2. an alternate antenna another radio holds (5.9) -----------------------------------------

def test_an_alternate_in_use_gives_no_antenna() -> None:
    """5.9: "If the alternate antenna is not available it will select no antenna for the
    receiving station"."""
    data, cfg = _case("alt-conflict.json")
    e = _replay(cfg, data["events"])
    r2, r3 = e.radio_view(1, 2), e.radio_view(1, 3)
    assert r2.rx == 0 and r2.tx == 34
    assert r3.rx == 41 and r3.alt is None
    state = e.switch_states()[1]
    # radio 2 (port 2) transmitting still switches radio 3 (port 3) away: to nothing
    assert 3 in state.use_alternate[2 - 1]
    assert state.station(3).alt == 63 and state.station(3).alt_relays == frozenset()
    assert violations(e, Facts.of(cfg)) == []


def test_the_alternate_comes_back_when_the_antenna_is_free_again() -> None:
    data, cfg = _case("alt-conflict.json")
    e = _replay(cfg, data["events"])
    e.select(1, 2, 40, "rx", False, now=20.0)   # radio 2 listens elsewhere
    assert e.radio_view(1, 2).rx == 40
    assert e.radio_view(1, 5).rx == 0           # its own sub receiver is family: no matter
    e.select(1, 5, 40, "rx", False, now=21.0)
    assert e.radio_view(1, 3).alt == 0


# -- 3. PersistSubReceiver and UseMainFreq on either entry (6.10) -------------------------------

def test_persist_sub_receiver_on_the_main_radios_entry_holds_during_transmit() -> None:
    """6.10's radio table lists "PersistSubReceiver ... True if the sub receiver relays should
    remain set during transmit" with "SubReceiver", on the main radio's entry."""
    data, cfg = _case("sub-persist.json")
    assert cfg.radio(1, 1).persist_sub_receiver and not cfg.radio(1, 5).persist_sub_receiver
    e = _replay(cfg, data["events"])
    port5 = e.switch_states()[1].station(5)
    assert e.radio_view(1, 5).rx == 18
    assert port5.tx == port5.rx != 63
    assert port5.tx_relays == port5.rx_relays == frozenset({42})


def test_persist_sub_receiver_on_the_sub_receivers_entry_still_works() -> None:
    data, cfg = _case("sub-persist.json")
    moved = _set_flag(_set_flag(cfg, RadioRef(1, 1), persist_sub_receiver=False),
                      RadioRef(1, 5), persist_sub_receiver=True)
    e = _replay(moved, data["events"])
    port5 = e.switch_states()[1].station(5)
    assert port5.tx == port5.rx != 63


def test_without_persist_sub_receiver_the_relays_drop_during_transmit() -> None:
    data, cfg = _case("sub-persist.json")
    off = _set_flag(cfg, RadioRef(1, 1), persist_sub_receiver=False)
    e = _replay(off, data["events"])
    port5 = e.switch_states()[1].station(5)
    assert port5.rx != 63 and port5.tx == 63 and port5.tx_relays == frozenset()


def test_use_main_freq_on_either_entry() -> None:
    """6.10: "UseMainFreq ... True if the subreceiver antenna selection should be based on
    the main radio frequency"."""
    _, cfg = _case("sub-persist.json")
    for where in (RadioRef(1, 1), RadioRef(1, 5)):
        e = Engine(_set_flag(cfg, where, use_main_freq=True), now=0.0)
        e.set_frequency(1, 1, 1850.0, now=1.0)
        assert e.radio_view(1, 5).khz == 1850.0, where
    e = Engine(cfg, now=0.0)
    e.set_frequency(1, 1, 1850.0, now=1.0)
    assert e.radio_view(1, 5).khz is None


# -- 4. the switch's conflict table with per-radio slots ----------------------------------------

def test_the_table_forbids_the_partners_antenna_in_the_radios_own_slot() -> None:
    """5.13 lets radio 1 listen on its partner's receive antenna (39) while the partner
    transmits; the table the box gets must still forbid radio 1 holding 39 in its own slot
    while radio 2 holds it."""
    data, cfg = _case("switch-conflict-table.json")
    e = _replay(cfg, data["events"])
    r1, r2 = e.radio_view(1, 1), e.radio_view(1, 2)
    assert r2.rx == 39 and r1.alt == 39
    state = e.switch_states()[1]
    own = e.slot_of(1, 39, 1, 1, as_partner_alt=False)
    partners = e.slot_of(1, 39, 1, 2)
    assert own is not None and partners is not None and own != partners
    assert (min(own, partners), max(own, partners)) in state.conflicts
    alt_slot = state.station(1).alt
    assert alt_slot not in (own, partners, 63)
    assert (min(alt_slot, partners), max(alt_slot, partners)) not in state.conflicts
    assert e.slot_of(1, 39, 1, 1) == alt_slot     # the slot its port uses for 39 now


def _box_with(e: Engine) -> EmulatorModel:
    box = EmulatorModel()
    box.feed(initialise(e.switch_states()[1]).encode(), 0.0)
    box.advance(1.0)
    return box


def test_the_emulated_box_refuses_the_radios_own_slot_and_takes_the_alternate() -> None:
    data, cfg = _case("switch-conflict-table.json")
    e = _replay(cfg, data["events"])
    wanted = e.switch_states()[1]
    box = _box_with(e)
    assert box.view().station(2).rx.antenna == e.slot_of(1, 39, 1, 2)
    # radio 2 transmits: radio 1 (port 1) goes to its alternate, the partner's antenna
    box.set_tr(2, True, 2.0)
    box.advance(3.0)
    # a wrong command putting radio 1's own slot for 39 on port 1's receive is held back
    own = e.slot_of(1, 39, 1, 1, as_partner_alt=False)
    assert own is not None
    bad = replace(wanted, stations=tuple(
        replace(s, rx=own) if n == 0 else s for n, s in enumerate(wanted.stations)))
    box.feed(difference(wanted, bad).encode(), 4.0)
    box.advance(5.0)
    view = box.view().station(1)
    assert view.rx.antenna != own
    assert ("rx", own) in view.pending or view.rx.antenna == wanted.station(1).rx


# -- --check says which entry the flags belong on ---------------------------------------------

def _check(tmp_path: Path, moas: dict[str, Any], capsys: pytest.CaptureFixture[str]) -> list[str]:
    """``moas-server --check`` on ``moas`` (its own command, in this process: what it says
    is the test, not the process; tests/config/test_config_fuzz.py runs it as a process)."""
    path = tmp_path / "station.moas"
    path.write_text(json.dumps(moas, indent=2))
    capsys.readouterr()
    status = server.main(["--check", str(path)])
    out, err = capsys.readouterr()
    assert status == 0, out + err
    return [line for line in out.splitlines() if "warning:" in line]


def _radio_entry(moas: dict[str, Any], radio: int) -> dict[str, Any]:
    return next(r for r in moas["Radios"] if r["Radio"] == radio)


def test_check_is_quiet_about_the_flags_on_the_main_radios_entry(tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    data, _ = _case("sub-persist.json")
    moas = data["moas"]
    _radio_entry(moas, 1)["UseMainFreq"] = True
    assert not [w for w in _check(tmp_path, moas, capsys) if "SubReceiver" in w]


def test_check_says_the_flags_belong_on_the_main_radios_entry(tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    data, _ = _case("sub-persist.json")
    moas = data["moas"]
    del _radio_entry(moas, 1)["PersistSubReceiver"]
    _radio_entry(moas, 5).update(PersistSubReceiver=True, UseMainFreq=True)
    warnings = _check(tmp_path, moas, capsys)
    for key in ("PersistSubReceiver", "UseMainFreq"):
        found = [w for w in warnings if f'"{key}" belongs on the entry of its main radio, '
                 "station 1 radio 1" in w]
        assert len(found) == 1, warnings
        assert "station 1 radio 5's" in found[0] and "honoured here too" in found[0]


def test_check_says_a_flag_without_a_sub_receiver_does_nothing(tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    data, _ = _case("sub-persist.json")
    moas = data["moas"]
    _radio_entry(moas, 2)["PersistSubReceiver"] = True
    warnings = _check(tmp_path, moas, capsys)
    assert any("station 1 radio 2's \"PersistSubReceiver\" has no effect" in w
               for w in warnings), warnings


# -- the two-operator example (examples/two-op-shared-tx.moas) ---------------------------------

def test_the_two_operator_example_evening_through_the_engine_and_the_emulated_box() -> None:
    """The walk-through of docs/configuration.md: shared tribander, partners on 20 m, the
    dipole's second feed and the beverage as alternate on 40 m, the sub receiver."""
    cfg = example("two-op-shared-tx")
    e = Engine(cfg, now=0.0)
    e.set_frequency(1, 1, 14025, now=1.0)
    e.set_frequency(2, 1, 14200, now=2.0)
    e.select(2, 1, 0, "both", now=3.0)          # operator 2 presses the tribander
    e.select(2, 1, 2, "rx", now=4.0)            # and listens on RX US
    op1, op2, sub = e.radio_view(1, 1), e.radio_view(2, 1), e.radio_view(1, 2)
    assert (op1.tx, op1.rx) == (0, 0) and (op2.tx, op2.rx) == (0, 2)
    assert op2.radio_rx_antenna and not op1.radio_rx_antenna
    assert sub.khz == 14025 and sub.tx is None and sub.rx not in (0, None)
    assert op1.alt == 2                          # 5.13: the partner's receive antenna
    box = EmulatorModel()
    box.feed(initialise(e.switch_states()[1]).encode(), 5.0)
    box.advance(6.0)
    box.set_tr(2, True, 7.0)                     # operator 2 transmits on the tribander
    e.set_transmitting(1, 2, True, now=7.0)
    box.advance(8.0)
    view = box.view()
    partner_alt = e.slot_of(1, 2, 1, 1)
    assert partner_alt == e.switch_states()[1].station(1).alt
    assert partner_alt != e.slot_of(1, 2, 1, 1, as_partner_alt=False)
    assert view.station(2).tx.antenna == e.slot_of(1, 0, 2, 1)
    sub_port = e.switch_states()[1].station(3)
    assert sub_port.tx == sub_port.rx != 63     # PersistSubReceiver on the main radio's entry
    e.set_transmitting(1, 2, False, now=9.0)
    # 40 m: the vertical for operator 1, the dipole through coax 2 for operator 2
    e.set_frequency(1, 1, 7150, now=10.0)
    e.set_frequency(2, 1, 7050, now=11.0)
    assert e.radio_view(1, 1).tx == 3 and e.radio_view(2, 1).tx == 5
    e.set_transmitting(1, 2, True, now=12.0)
    assert e.radio_view(1, 1).alt == 7           # 5.9: the beverage
    state = e.switch_states()[1]
    assert 1 in state.use_alternate[2 - 1]
    assert violations(e, Facts.of(cfg)) == []


def test_a_partner_alternate_slot_given_out_as_needed_survives_a_restart() -> None:
    """With more keys than a switch's 63 slots, slots are given out as needed; the partner's
    alternate slot (the key's third part) is exported and restored like any other."""
    from engine_builders import antenna, config, radio

    from moas_gui.engine.snapshot import export_selections, restore_selections

    both = {(1, 1): [0], (1, 2): [8]}
    ants = [antenna(0, (20,), both, fast=(1, 2), shared_tx=True),
            antenna(1, (20,), {(1, 1): [1], (1, 2): [9]}, fast=(0,), rx_only=True),
            antenna(2, (20,), {(1, 1): [2], (1, 2): [10]}, fast=(0,), rx_only=True)]
    ants += [antenna(10 + i, (20,), {(1, 1): [20 + i % 40], (1, 2): [20 + i % 40]})
             for i in range(40)]
    partners = {"always": (RadioRef(1, 2),), "partner": (RadioRef(1, 2),)}
    others = {"always": (RadioRef(1, 1),), "partner": (RadioRef(1, 1),)}
    cfg = config(ants, [radio(1, 1, 1, **partners), radio(1, 2, 2, **others)])
    e = Engine(cfg, now=0.0)
    assert not e._maps[1].static                 # more keys than slots: given out as needed
    e.set_frequency(1, 1, 14025, now=1.0)
    e.set_frequency(1, 2, 14100, now=2.0)
    e.select(1, 2, 0, "both", now=3.0)
    e.select(1, 2, 2, "rx", now=4.0)
    assert e.radio_view(1, 1).alt == 2
    alt_slot = e.switch_states()[1].station(1).alt
    assert alt_slot == e.slot_of(1, 2, 1, 1, as_partner_alt=True) != 63
    data = json.loads(json.dumps(export_selections(e)))
    assert any(len(item) == 4 and item[3] is True for item in data["maps"]["1"]["slots"])
    again = Engine(cfg, now=100.0)
    restore_selections(again, data)
    assert again.radios() == e.radios()
    assert again.switch_states() == e.switch_states()
