"""Issue 29: an alternate is never the antenna another radio transmits on, shared or not.

The case ``tests/engine/engine_cases/alternate-is-transmitting-antenna.json`` (two interlocked
radios sharing the ``SharedTX`` antenna 0; station 2 radio 1 listens on RX-only 1 with an
``Alternate`` rule naming 0; station 1 radio 1 keys), replayed through the engine's public
API, then as its partner variant (``Partner`` both ways) and its three-radio variant (a third
interlocked radio on antenna 0 is the one keying).  Each is held against the manual's text and
also loaded into the emulated firmware, whose own conflict resolver must keep station 2's
relay for antenna 0 open while antenna 0 is transmitted on.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from engine_invariants import Facts, violations

from moas_gui.config import parse_config
from moas_gui.config.model import Config
from moas_gui.engine import Engine, derive
from moas_gui.engine.rules import permitted, users
from moas_gui.hw.moas2.emulator import EmulatorModel
from moas_gui.hw.moas2.sync import initialise

CASES = Path(__file__).parent / "engine_cases"
NAME = "alternate-is-transmitting-antenna.json"
ANTENNA0_RELAYS = {(1, 1): 1, (2, 1): 2, (3, 1): 5}
"""Each radio's relay for antenna 0 (the shared transmit antenna)."""


def _data() -> dict[str, Any]:
    data: dict[str, Any] = json.loads((CASES / NAME).read_text())
    return data


def _config(moas: dict[str, Any]) -> Config:
    result = parse_config(json.dumps(moas), NAME)
    assert result.config is not None, result.problems
    return result.config


def _radio(moas: dict[str, Any], station: int) -> dict[str, Any]:
    found: dict[str, Any] = next(r for r in moas["Radios"] if r["Station"] == station)
    return found


def _partners(data: dict[str, Any]) -> dict[str, Any]:
    """The partner variant: the two radios are partners both ways (5.13)."""
    out = copy.deepcopy(data)
    _radio(out["moas"], 1)["Partner"] = [{"Station": 2, "Radio": 1}]
    _radio(out["moas"], 2)["Partner"] = [{"Station": 1, "Radio": 1}]
    return out


def _three_radios(data: dict[str, Any]) -> dict[str, Any]:
    """The three-radio variant: station 3 radio 1 (port 3) also shares antenna 0, interlocked
    with both, and it is the one that keys; station 1 radio 1 holds 0 too."""
    out = copy.deepcopy(data)
    moas = out["moas"]
    for ant, relay in ((0, 5), (1, 6)):
        moas["Antennas"][ant]["Control"][0]["Stations"].append(
            {"Station": 3, "Radio": 1, "Relays": [relay]})
    for station in (1, 2):
        _radio(moas, station)["Always"].append({"Station": 3, "Radio": 1})
    moas["Radios"].append({"Station": 3, "Radio": 1, "Switches": [{"Port": 3}],
                           "Always": [{"Station": 1, "Radio": 1}, {"Station": 2, "Radio": 1}]})
    events = out["events"]
    out["events"] = [events[0], {"op": "frequency", "station": 3, "radio": 1, "khz": 7150.0},
                     *events[1:3], {"op": "transmitting", "switch": 1, "port": 3, "on": True}]
    return out


def _replay(data: dict[str, Any]) -> tuple[Engine, Config]:
    cfg = _config(data["moas"])
    e = Engine(cfg, now=0.0)
    for i, ev in enumerate(data["events"]):
        now = 1.0 + i
        if ev["op"] == "frequency":
            e.set_frequency(ev["station"], ev["radio"], ev["khz"], now=now)
        elif ev["op"] == "transmitting":
            e.set_transmitting(ev["switch"], ev["port"], ev["on"], now=now)
        else:
            e.select(*ev["args"], now=now)
    return e, cfg


VARIANTS = {"case": lambda d: d, "partners": _partners, "three radios": _three_radios}


def _keyed(data: dict[str, Any]) -> int:
    """The port that keys in the case's last event."""
    last = data["events"][-1]
    assert last["op"] == "transmitting" and last["on"]
    port: int = last["port"]
    return port


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_the_alternate_is_none_while_another_radio_transmits_on_it(variant: str) -> None:
    """5.9: "This feature is designed for cases where there might be a problem, such as a
    damaged receiver front end, if a station transmits on an antenna while another station is
    listening ... If the alternate antenna is not available it will select no antenna for the
    receiving station."  5.12's permission is for transmitting in turn only."""
    data = VARIANTS[variant](_data())
    e, cfg = _replay(data)
    me = e.radio_view(2, 1)
    assert me.rx == 1
    holders = [v for v in e.radios() if (v.station, v.radio) != (2, 1) and v.tx == 0]
    assert holders, e.radios()           # someone else holds the shared antenna for transmit
    assert me.alt is None, me
    state = e.switch_states()[1]
    keyed = _keyed(data)
    # the radio still leaves its receive antenna while the other keys: to nothing
    assert 2 in state.use_alternate[keyed - 1]
    assert state.station(2).alt == 63 and state.station(2).alt_relays == frozenset()
    assert violations(e, Facts.of(cfg)) == []


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_the_emulated_box_never_closes_the_listeners_relay_on_the_keyed_antenna(
        variant: str) -> None:
    data = VARIANTS[variant](_data())
    e, _cfg = _replay(data)
    keyed = _keyed(data)
    box = EmulatorModel()
    box.feed(initialise(e.switch_states()[1]).encode(), 100.0)
    box.advance(101.0)
    box.set_tr(keyed, True, 102.0)
    box.advance(103.0)
    view = box.view()
    assert view.station(keyed).transmitting
    assert ANTENNA0_RELAYS[(keyed, 1)] in view.station(keyed).closed
    assert ANTENNA0_RELAYS[(2, 1)] not in view.station(2).closed, view.station(2)


def _old_available(ix: Any, st: Any, ref: Any, want: int | None,
                   partner: Any = None) -> int | None:
    """The availability before issue 29: the sharing rules' permission let an alternate be
    a ``SharedTX`` antenna an interlocked radio holds for transmit."""
    if want is None:
        return None
    for other, role, y in users(ix, st, ref):
        if other == partner and role == "rx":
            continue
        if ix.conflict(want, y) and not permitted(ix, st, ref, other, want, y):
            return None
    return want


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_the_box_refuses_the_pairing_even_with_the_old_engine(
        variant: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The switch's table is a safety layer of its own: with the engine patched back to the
    old availability (alternate 0 given), the alternate's slot still conflicts with every
    other radio's transmit slot for antenna 0, so the box keeps the relay open."""
    monkeypatch.setattr(derive, "available", _old_available)
    data = VARIANTS[variant](_data())
    e, _cfg = _replay(data)
    assert e.radio_view(2, 1).alt == 0            # the old engine's answer
    state = e.switch_states()[1]
    alt_slot = state.station(2).alt
    for v in e.radios():
        if (v.station, v.radio) != (2, 1) and v.tx == 0:
            tx_slot = e.slot_of(1, 0, v.station, v.radio)
            assert tx_slot is not None and tx_slot != alt_slot
            assert (min(alt_slot, tx_slot), max(alt_slot, tx_slot)) in state.conflicts
    keyed = _keyed(data)
    box = EmulatorModel()
    box.feed(initialise(state).encode(), 100.0)
    box.advance(101.0)
    box.set_tr(keyed, True, 102.0)
    box.advance(103.0)
    assert ANTENNA0_RELAYS[(2, 1)] not in box.view().station(2).closed


def test_the_alternate_is_given_when_nobody_else_holds_the_antenna() -> None:
    """The rule still works: once station 1 radio 1 transmits on another antenna (and holds
    0 no longer), antenna 0 is free and is station 2 radio 1's alternate while it keys."""
    data = copy.deepcopy(_data())
    moas = data["moas"]
    moas["Antennas"].append({
        "ID": 2, "ShortName": "DIP", "Conflicts": [2], "Fast": [0, 1],
        "Control": [{"LowerFrequency": 7000, "UpperFrequency": 7300,
                     "Stations": [{"Station": 1, "Radio": 1, "Relays": [7]},
                                  {"Station": 2, "Radio": 1, "Relays": [8]}]}]})
    moas["Antennas"][0]["Fast"] = [1, 2]
    moas["Antennas"][1]["Fast"] = [0, 2]
    _radio(moas, 2)["Alternate"][0]["OtherAntennas"] = [0, 2]
    e, cfg = _replay(data)
    e.set_transmitting(1, 1, False, now=20.0)
    e.select(1, 1, 2, "both", False, now=21.0)
    e.set_transmitting(1, 1, True, now=22.0)
    one, two = e.radio_view(1, 1), e.radio_view(2, 1)
    assert (one.tx, one.rx) == (2, 2) and two.rx == 1
    assert two.alt == 0, two
    state = e.switch_states()[1]
    assert 2 in state.use_alternate[0] and state.station(2).alt_relays == frozenset({2})
    assert violations(e, Facts.of(cfg)) == []


def test_the_partners_receive_antenna_is_no_alternate_while_its_sub_receiver_uses_it() -> None:
    """5.13: "The other partner has an antenna which can be used"; 1.1.12: "A sub receiver
    can be configured as an additional radio. The MOAS will select antennas for the sub
    receiver"; 1.1.4: "if a station is using an antenna then other stations cannot use that
    antenna".  On the two-operator example, operator 1's sub receiver (its own port 3)
    listening on operator 1's receive antenna RX US takes it from operator 2's 5.13
    alternate; listening elsewhere, it leaves it."""
    from engine_builders import example

    cfg = example("two-op-shared-tx")
    e = Engine(cfg, now=0.0)
    e.set_frequency(1, 1, 14025, now=1.0)
    e.set_frequency(2, 1, 14200, now=2.0)
    e.select(2, 1, 0, "both", now=3.0)
    e.select(1, 1, 0, "both", now=4.0)
    e.select(1, 1, 2, "rx", now=5.0)              # operator 1 listens on RX US
    op1, sub, op2 = e.radio_view(1, 1), e.radio_view(1, 2), e.radio_view(2, 1)
    assert (op1.tx, op1.rx) == (0, 2) and sub.rx != 2 and op2.tx == op2.rx == 0
    assert op2.alt == 2                            # 5.13: the partner's receive antenna
    e.select(1, 2, 2, "rx", now=6.0)              # the sub receiver listens there too
    assert e.radio_view(1, 2).rx == 2
    assert e.radio_view(2, 1).alt is None
    state = e.switch_states()[1]
    assert state.station(2).alt == 63 and state.station(2).alt_relays == frozenset()
    assert violations(e, Facts.of(cfg)) == []
