"""Issue 39: the partner's alternate beside a sub receiver, by how the sub receiver is wired.

The case ``tests/engine/engine_cases/partner-alternate-riding-sub.json``: partners station 1
radio 1 (transmits on the ``SharedTX`` antenna 0, receives on RX-only 1) and station 2 radio 1
(on 0); station 1 radio 1's sub receiver, radio 2, has no port of its own (it rides on port 1)
and no ``PersistSubReceiver``, and ends up listening on antenna 1 too.  Its relay 22 is then
among port 1's receive relays only, open exactly while station 1 radio 1 transmits, which is
exactly when station 2 radio 1 is switched to its alternate: 5.13's "The other partner has an
antenna which can be used" holds, and the alternate stays antenna 1.  With a port of its own,
or with ``PersistSubReceiver``, the sub receiver keeps listening while its main radio
transmits (6.10), so the antenna is in use (1.1.4) and the alternate is none: the radio view
says why.  Replayed through the engine's public API and loaded into the emulated firmware.
(The property suite's rule for it, and the rule caught on broken copies of the engine:
``test_engine_multiop_properties.py``.)
"""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path
from typing import Any

import pytest
from engine_invariants import Facts, apply, violations
from engine_stations import multiop_station, partner_sub_evening

from moas_gui.config import parse_config
from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, EngineError
from moas_gui.hw.moas2.emulator import EmulatorModel
from moas_gui.hw.moas2.sync import initialise

CASES = Path(__file__).parent / "engine_cases"
NAME = "partner-alternate-riding-sub.json"


def _data() -> dict[str, Any]:
    data: dict[str, Any] = json.loads((CASES / NAME).read_text())
    return data


def _config(moas: dict[str, Any]) -> Config:
    result = parse_config(json.dumps(moas), NAME)
    assert result.config is not None, result.problems
    return result.config


def _entry(moas: dict[str, Any], station: int, radio: int) -> dict[str, Any]:
    found: dict[str, Any] = next(r for r in moas["Radios"]
                                 if (r["Station"], r["Radio"]) == (station, radio))
    return found


def _persist(data: dict[str, Any]) -> dict[str, Any]:
    """``PersistSubReceiver`` on the main radio's entry (6.10's table)."""
    out = copy.deepcopy(data)
    _entry(out["moas"], 1, 1)["PersistSubReceiver"] = True
    return out


def _own_port(data: dict[str, Any]) -> dict[str, Any]:
    """The sub receiver on a port of its own (port 3)."""
    out = copy.deepcopy(data)
    _entry(out["moas"], 1, 2)["Switches"] = [{"Port": 3}]
    return out


def replay(data: dict[str, Any]) -> tuple[Engine, Config]:
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


def test_beside_a_riding_sub_receiver_the_partners_receive_antenna_stays_the_alternate() -> None:
    """5.13: "The other partner has an antenna which can be used"; 6.10:
    "PersistSubReceiver ... True if the sub receiver relays should remain set during
    transmit" (without it they do not)."""
    e, cfg = replay(_data())
    one, sub, two = e.radio_view(1, 1), e.radio_view(1, 2), e.radio_view(2, 1)
    assert (one.tx, one.rx, sub.rx) == (0, 1, 1)
    assert (two.tx, two.rx) == (0, 0)
    assert two.alt == 1, two
    assert two.alt_why == "" and "alt_why" not in two.to_dict()
    assert violations(e, Facts.of(cfg)) == []
    # while the partner transmits too, and after it stops
    e.set_transmitting(1, 1, True, now=20.0)
    assert e.radio_view(2, 1).alt == 1
    assert violations(e, Facts.of(cfg)) == []
    e.set_transmitting(1, 1, False, now=21.0)
    assert e.radio_view(2, 1).alt == 1


@pytest.mark.parametrize(("variant", "because"), [(_persist, "PersistSubReceiver"),
                                                  (_own_port, "its own port")])
def test_a_sub_receiver_that_keeps_listening_leaves_no_alternate_and_the_view_says_why(
        variant: Any, because: str) -> None:
    """5.9: "If the alternate antenna is not available it will select no antenna for the
    receiving station"; 1.1.4: "if a station is using an antenna then other stations cannot
    use that antenna"."""
    e, cfg = replay(variant(_data()))
    two = e.radio_view(2, 1)
    assert e.radio_view(1, 2).rx == 1
    assert two.alt is None
    assert "station 1 radio 2" in two.alt_why and because in two.alt_why, two.alt_why
    assert "partner's receive antenna RX EU" in two.alt_why, two.alt_why
    assert two.to_dict()["alt_why"] == two.alt_why
    assert e.switch_states()[1].station(2).alt == 63
    assert violations(e, Facts.of(cfg)) == []


def test_moving_the_riding_sub_receiver_changes_nothing_for_the_alternate() -> None:
    """After the sixth event the sub receiver is on antenna 2: the alternate is 1 then, and
    stays 1 when the sub receiver joins antenna 1 (before issue 39 it became none)."""
    data = _data()
    data["events"] = data["events"][:6]
    e, _cfg = replay(data)
    assert e.radio_view(1, 2).rx == 2 and e.radio_view(2, 1).alt == 1
    e.select(1, 2, 1, "rx", False, now=30.0)
    assert e.radio_view(2, 1).alt == 1


def test_the_slot_tables_show_the_pairing_is_safe() -> None:
    """Port 1 (the partner and its riding sub receiver): transmit relays [1], receive relays
    [2, 22] -- the sub receiver's relay 22 only among the receive relays.  Port 2's alternate
    is its partner-alternate slot for antenna 1 (relay 12), switched in only while port 1
    transmits (``@``), when port 1 holds relay 1 alone; the table waives that slot against
    port 1's receive slot only, and still forbids antenna 1 in port 2's own slot."""
    e, _cfg = replay(_data())
    state = e.switch_states()[1]
    port1, port2 = state.station(1), state.station(2)
    assert port1.tx_relays == frozenset({1})
    assert port1.rx_relays == frozenset({2, 22})
    assert port1.rx == e.slot_of(1, 1, 1, 1, as_partner_alt=False)
    assert port2.alt == e.slot_of(1, 1, 2, 1, as_partner_alt=True) == e.slot_of(1, 1, 2, 1)
    assert port2.alt_relays == frozenset({12})
    assert state.use_alternate[0] == frozenset({2})          # only while port 1 transmits
    assert all(2 not in listed for listed in state.use_alternate[1:])
    waived = (min(port2.alt, port1.rx), max(port2.alt, port1.rx))
    assert waived not in state.conflicts
    own = e.slot_of(1, 1, 2, 1, as_partner_alt=False)
    assert own is not None and (min(own, port1.rx), max(own, port1.rx)) in state.conflicts


def test_the_emulated_box_accepts_the_pairing_and_never_closes_both_relays() -> None:
    """The box takes the wanted state, and through key-down and key-up relay 12 (station 2
    on antenna 1) and relay 22 (the sub receiver on antenna 1) are never closed together."""
    e, _cfg = replay(_data())
    box = EmulatorModel()
    box.feed(initialise(e.switch_states()[1]).encode(), 100.0)
    box.advance(101.0)
    view = box.view()
    assert view.station(1).closed == frozenset({2, 22})
    assert view.station(2).closed == frozenset({11})
    box.set_tr(1, True, 102.0)
    box.advance(103.0)
    view = box.view()
    assert view.station(1).transmitting
    assert view.station(1).closed == frozenset({1})
    assert view.station(2).closed == frozenset({12})     # the alternate, taken by the box
    box.set_tr(1, False, 104.0)
    box.advance(105.0)
    view = box.view()
    assert view.station(1).closed == frozenset({2, 22})
    assert view.station(2).closed == frozenset({11})
    assert box.record, "the box recorded no relay changes"
    for entry in box.record:
        closed = set().union(*entry.closed)
        assert not {12, 22} <= closed, entry


def test_an_operators_why_says_why_the_alternate_is_none() -> None:
    """The reason travels in the radio entry (``alt_why``) to the clients, whose why (the
    desktop's Why? and tooltip, ``client.model.explain``) says it; absent when there is an
    alternate."""
    from moas_gui.client.model import explain, parse_radio

    e, _cfg = replay(_persist(_data()))
    told = parse_radio(json.loads(json.dumps(e.radio_view(2, 1).to_dict())))
    text = explain(told, None)
    assert "No alternate antenna while station 1 radio 1 transmits on Tribander" in text, text
    assert "keeps listening" in text and "PersistSubReceiver" in text, text
    e, _cfg = replay(_data())
    told = parse_radio(json.loads(json.dumps(e.radio_view(2, 1).to_dict())))
    assert told.alt == 1 and told.alt_why == "" and "No alternate" not in explain(told, None)


def _riding_pairings(e: Engine, facts: Facts) -> list[tuple[int, int, int]]:
    """(switch, listener's port, partner's port) wherever a radio's alternate is its
    partner's receive antenna with the partner's riding sub receiver (no
    ``PersistSubReceiver``) listening on an antenna conflicting with it."""
    views = {RadioRef(v.station, v.radio): v for v in e.radios()}
    found = []
    for sub, t in facts.subs.items():
        vs, vt = views[sub], views[t]
        if not facts.rides_silent(sub) or vs.rx is None or vt.rx is None:
            continue
        for ref, v in views.items():
            if v.alt is None or v.alt != vt.rx or not facts.conflict(vs.rx, v.alt) \
                    or frozenset((ref, t)) not in facts.partners_now(e):
                continue
            mine, theirs = facts.switches_of(ref), facts.switches_of(t)
            found += [(w, p, tp) for w in mine for p in mine[w] for tp in theirs.get(w, ())]
    return found


def test_the_emulated_box_accepts_every_riding_pairing_of_issue_39s_stations() -> None:
    """On generated stations (partners each with a sub receiver of one of the three kinds),
    wherever the engine gives a radio its partner's receive antenna beside the partner's
    riding sub receiver, the wanted state loaded into the emulated firmware with the
    partner keyed connects the radio to the alternate's relays and the partner's port to
    its transmit relays alone (the sub receiver's dropped)."""
    checked = 0
    for seed in range(60):
        rng = random.Random(seed)
        cfg = multiop_station(rng, partner_subs=True)
        facts = Facts.of(cfg)
        e = Engine(cfg)
        for i, op in enumerate(partner_sub_evening(cfg, rng, 200)):
            try:
                apply(e, op, 0.7 * (i + 1))
            except EngineError:
                continue
            if any(v.transmitting for v in e.radios()):
                continue
            for w, p, tp in _riding_pairings(e, facts):
                state = e.switch_states()[w]
                box = EmulatorModel()
                box.feed(initialise(state).encode(), 0.0)
                box.advance(1.0)
                box.set_tr(tp, True, 2.0)
                box.advance(3.0)
                view = box.view()
                assert p in state.use_alternate[tp - 1]
                assert view.station(p).closed == state.station(p).alt_relays, (seed, i, op)
                assert view.station(tp).closed == state.station(tp).tx_relays, (seed, i, op)
                checked += 1
    assert checked >= 10, checked       # 16 pairings with these seeds
