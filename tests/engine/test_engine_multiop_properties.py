"""The multi-operator rules of the property suite (``engine_invariants.multiop_violations``):
shared transmit antennas, partners, alternate paths, alternate antennas and sub receivers.

First that random evenings on generated multi-operator stations keep every rule and that the
checks really run; then, per rule, that the check catches it broken on purpose: the engine
patched back to the behaviour issue 25 found, or a state made by hand.
"""

from __future__ import annotations

import json
import os
import random
from collections import Counter
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from engine_invariants import MULTIOP_RULES, Facts, multiop_violations, operations, run_evening
from engine_stations import (
    SUB_KINDS,
    features,
    frequencies_for,
    generated_station,
    multiop_station,
    partner_sub_evening,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import moas_gui.engine.engine as engine_module
import moas_gui.engine.outputs as outputs_module
from moas_gui.config import parse_config
from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, derive, rules
from moas_gui.engine.index import ConfigIndex, RadioKind
from moas_gui.engine.slots import SlotClasses

CASES = Path(__file__).parent / "engine_cases"
EXAMPLES = int(os.environ.get("MOAS_ENGINE_EXAMPLES", "12"))
FAST = settings(max_examples=EXAMPLES, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])


def _case(name: str) -> tuple[Config, list[dict[str, Any]]]:
    data = json.loads((CASES / name).read_text())
    cfg = parse_config(json.dumps(data["moas"]), name).config
    assert cfg is not None
    return cfg, data["events"]


def _replay(name: str) -> tuple[Engine, Facts]:
    cfg, events = _case(name)
    e = Engine(cfg, now=0.0)
    for i, ev in enumerate(events):
        if ev["op"] == "frequency":
            e.set_frequency(ev["station"], ev["radio"], ev["khz"], now=1.0 + i)
        else:
            e.select(*ev["args"], now=1.0 + i)
    return e, Facts.of(cfg)


def _fired(e: Engine, facts: Facts, rule: str, text: str) -> list[str]:
    counts: Counter[str] = Counter()
    found = [p for p in multiop_violations(e, facts, counts) if text in p]
    assert counts[rule] > 0, counts
    return found


# -- the rules hold, and the checks run -------------------------------------------------------

@FAST
@given(st.integers(0, 2**32 - 1))
def test_every_multiop_rule_holds_on_generated_multiop_stations(seed: int) -> None:
    rng = random.Random(seed)
    cfg = multiop_station(rng)
    run_evening(cfg, list(operations(cfg, rng, 120, frequencies_for(cfg))))


def test_the_generated_stations_use_the_features_and_every_check_runs() -> None:
    stations = [generated_station(random.Random(seed)) for seed in range(200)]
    multiop = [cfg for cfg in stations if {"SharedTX", "alternate paths"} <= features(cfg)]
    assert len(multiop) >= len(stations) // 4
    seen: Counter[str] = Counter()
    for cfg in multiop:
        seen.update(features(cfg))
    for feature in ("SharedTX", "Partner list", "Partner function", "alternate paths",
                    "Alternate rules", "AltActive", "sub receiver with port",
                    "sub receiver without port", "UseMainFreq", "PersistSubReceiver",
                    "RadioRXAntenna"):
        assert seen[feature] > 0, feature
    counts: Counter[str] = Counter()
    for seed in range(4):  # the first evenings already run every check (the wide run:
        rng = random.Random(seed)  # benchmarks/bench_engine_properties.py)
        cfg = multiop_station(rng, shared_alternates=seed % 2 == 1)
        run_evening(cfg, list(operations(cfg, rng, 200, frequencies_for(cfg))), counts=counts)
    for seed in range(40):  # issue 39's stations, until every kind of sub receiver was seen
        rng = random.Random(seed)  # beside its partner's alternate
        cfg = multiop_station(rng, partner_subs=True)
        run_evening(cfg, partner_sub_evening(cfg, rng, 300), counts=counts)
        if all(counts[rule] for rule in MULTIOP_RULES):
            break
    for rule in MULTIOP_RULES:
        assert counts[rule] > 0, (rule, counts)


def test_the_generated_stations_of_issue_29() -> None:
    """Alternate rules whose alternate is a SharedTX antenna interlocked radios may hold,
    partners on both sides, sub receivers with and without ports, three or more radios
    sharing one antenna (all interlocked)."""
    stations = [multiop_station(random.Random(seed)) for seed in range(200)]
    shared_alt = [cfg for cfg in stations if any(
        rule.antenna is not None and cfg.antenna(rule.antenna) is not None
        and cfg.antenna(rule.antenna).shared_tx for r in cfg.radios for rule in r.alternate)]
    assert len(shared_alt) >= 50
    both_ways = [cfg for cfg in stations if any(
        p in {q.ref for q in cfg.radios} and r.ref in cfg.radio(p.station, p.radio).partner
        for r in cfg.radios for p in r.partner)]
    assert both_ways
    three = [cfg for cfg in stations if any(len(r.always) >= 2 for r in cfg.radios)]
    assert three
    seen: Counter[str] = Counter()
    for cfg in shared_alt:
        seen.update(features(cfg))
    assert seen["sub receiver with port"] and seen["sub receiver without port"]


@FAST
@given(st.integers(0, 2**32 - 1))
def test_no_receiver_on_a_transmit_antenna_on_issue_29s_stations(seed: int) -> None:
    rng = random.Random(seed)
    cfg = multiop_station(rng, shared_alternates=True)
    counts: Counter[str] = Counter()
    run_evening(cfg, list(operations(cfg, rng, 150, frequencies_for(cfg, only_configured=True))),
                counts=counts)


def test_the_generated_stations_of_issue_39() -> None:
    """Partners each with a sub receiver, of all three kinds among the stations (a port of
    its own; riding on the main radio's port with and without ``PersistSubReceiver``)."""
    seen: Counter[str] = Counter()
    for seed in range(30):
        cfg = multiop_station(random.Random(seed), partner_subs=True)
        partners = [r for r in cfg.radios if r.partner]
        assert len(partners) == 2 and all(r.sub_receiver is not None for r in partners)
        seen.update(features(cfg))
    for kind in SUB_KINDS:
        assert seen[kind] >= 5, (kind, seen)


@FAST
@given(st.integers(0, 2**32 - 1))
def test_every_multiop_rule_holds_on_issue_39s_stations(seed: int) -> None:
    rng = random.Random(seed)
    cfg = multiop_station(rng, partner_subs=True)
    run_evening(cfg, partner_sub_evening(cfg, rng, 150))


# -- each rule caught broken ------------------------------------------------------------------

def test_two_paths_of_one_antenna_are_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine before: paths conflicted only as their Conflicts lists said."""
    monkeypatch.setattr(ConfigIndex, "_physical_conflicts", lambda self: None)
    e, facts = _replay("same-antenna.json")
    assert _fired(e, facts, "one physical antenna", "two paths of one antenna (5.8)")


def test_an_alternate_someone_holds_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine before: an alternate rule's antenna was used whoever held it."""
    monkeypatch.setattr(derive, "available",
                        lambda ix, st, ref, want, partner=None: want)
    e, facts = _replay("alt-conflict.json")
    assert _fired(e, facts, "alternate not held", "alternate 0 is 0, held by station 1 radio 2")


def _partner_transmitting() -> tuple[Engine, Facts]:
    e, facts = _replay("switch-conflict-table.json")
    e.set_transmitting(1, 2, True, now=10.0)      # radio 2 transmits on shared 21
    return e, facts


def test_the_shared_transmit_listener_rule_holds_for_partners() -> None:
    e, facts = _partner_transmitting()
    assert e.radio_view(1, 1).alt == e.radio_view(1, 2).rx == 39
    counts: Counter[str] = Counter()
    assert multiop_violations(e, facts, counts) == []
    assert counts["shared TX listener"] == 1


def test_a_listener_moved_to_another_antenna_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """A hand-made state: radio 1's alternate is another antenna than the partner's."""
    e, facts = _partner_transmitting()
    views = tuple(replace(v, alt=45) if (v.station, v.radio) == (1, 1) else v
                  for v in e.radios())
    monkeypatch.setattr(e, "radios", lambda: views)
    assert _fired(e, facts, "shared TX listener", "not none or the partner's receive antenna")


def test_a_partner_left_without_the_partners_antenna_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A patched engine that never applies 5.13."""
    monkeypatch.setattr(derive, "partner_alternate", lambda ix, st, ref, other: None)
    e, facts = _partner_transmitting()
    assert e.radio_view(1, 1).alt is None
    assert _fired(e, facts, "shared TX listener", "meet 5.13's conditions")


def test_a_sub_receiver_dropping_its_relays_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine before: PersistSubReceiver read from the sub receiver's own entry only."""
    def own_entry_only(self: ConfigIndex, sub: RadioRef, name: str) -> bool:
        info = self.radios.get(sub)
        return info is not None and info.kind is RadioKind.SUB and bool(getattr(info.radio, name))
    monkeypatch.setattr(ConfigIndex, "sub_flag", own_entry_only)
    e, facts = _replay("sub-persist.json")
    assert _fired(e, facts, "sub receiver relays", "with PersistSubReceiver: port 5")


def test_a_sub_receiver_transmitting_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    e, facts = _replay("sub-persist.json")
    views = tuple(replace(v, tx=18) if (v.station, v.radio) == (1, 5) else v
                  for v in e.radios())
    monkeypatch.setattr(e, "radios", lambda: views)
    assert _fired(e, facts, "sub receiver relays", "sub receiver station 1 radio 5 transmits")


def test_a_loose_switch_table_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine before: the partner's receive antenna as alternate used the radio's own
    slot, so waiving it loosened the table for the radio's own use of that antenna."""
    real = engine_module.radio_relays
    monkeypatch.setattr(engine_module, "radio_relays",
                        lambda *a: replace(real(*a), alt_partner=False))
    e, facts = _replay("switch-conflict-table.json")
    assert _fired(e, facts, "switch conflict table",
                  "would let station 1 radio 1 take conflicting 39")


def test_a_wrong_radio_rx_antenna_flag_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    e, facts = _replay("switch-conflict-table.json")
    views = tuple(replace(v, radio_rx_antenna=not v.radio_rx_antenna)
                  if (v.station, v.radio) == (1, 2) else v for v in e.radios())
    monkeypatch.setattr(e, "radios", lambda: views)
    assert _fired(e, facts, "RadioRXAntenna", "station 1 radio 2 on 39")


# -- issue 29: no receiver on an antenna another radio transmits on ---------------------------

def _replay_29(partners: bool = False) -> tuple[Engine, Facts]:
    data = json.loads((CASES / "alternate-is-transmitting-antenna.json").read_text())
    if partners:
        data["moas"]["Radios"][0]["Partner"] = [{"Station": 2, "Radio": 1}]
        data["moas"]["Radios"][1]["Partner"] = [{"Station": 1, "Radio": 1}]
    cfg = parse_config(json.dumps(data["moas"]), "case").config
    assert cfg is not None
    e = Engine(cfg, now=0.0)
    for i, ev in enumerate(data["events"]):
        if ev["op"] == "frequency":
            e.set_frequency(ev["station"], ev["radio"], ev["khz"], now=1.0 + i)
        elif ev["op"] == "transmitting":
            e.set_transmitting(ev["switch"], ev["port"], ev["on"], now=1.0 + i)
        else:
            e.select(*ev["args"], now=1.0 + i)
    return e, Facts.of(cfg)


def _old_available(ix: ConfigIndex, st: Any, ref: RadioRef, want: int | None,
                   partner: RadioRef | None = None) -> int | None:
    """A deliberately broken copy: the availability before issue 29 (the sharing rules'
    permission let another radio's SharedTX transmit antenna be the alternate)."""
    if want is None:
        return None
    for other, role, y in rules.users(ix, st, ref):
        if other == partner and role == "rx":
            continue
        if ix.conflict(want, y) and not rules.permitted(ix, st, ref, other, want, y):
            return None
    return want


def test_the_case_keeps_every_rule() -> None:
    for partners in (False, True):
        e, facts = _replay_29(partners)
        counts: Counter[str] = Counter()
        assert multiop_violations(e, facts, counts) == []
        assert counts["receiver off transmit antenna"] > 0
        assert counts["shared alternate armed"] == 1


@pytest.mark.parametrize("partners", [False, True])
def test_a_receiver_on_the_transmitting_antenna_is_caught(
        partners: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine patched back to the old availability: station 2 radio 1 listens on
    antenna 0 while station 1 radio 1 transmits on it."""
    monkeypatch.setattr(derive, "available", _old_available)
    e, facts = _replay_29(partners)
    assert _fired(e, facts, "receiver off transmit antenna",
                  "station 2 radio 1 (port 2) listens on 0 while station 1 radio 1 transmits "
                  "on 0")


def test_a_loose_alternate_slot_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    """The old engine, and the table before issue 29: the alternate used the radio's own
    slot for the shared antenna, whose conflict with the other transmit slot was waived."""
    monkeypatch.setattr(derive, "available", _old_available)
    monkeypatch.setattr(SlotClasses, "alt_key",
                        lambda self, a, owner, partner_alt=False: self.key(a, owner, partner_alt))
    e, facts = _replay_29()
    assert _fired(e, facts, "alternate slot table", "port 2's alternate 0")


# -- issue 39: the partner's alternate beside a sub receiver ----------------------------------

RIDING = "partner-alternate-riding-sub.json"


def _replay_39(sub_entry: dict[str, Any] | None = None, main_entry: dict[str, Any] | None = None,
               transmitting: bool = False) -> tuple[Engine, Facts]:
    """Issue 39's case, with fields set on the sub receiver's (1.2) or main radio's (1.1)
    entry, and station 1 radio 1 keyed at the end."""
    data = json.loads((CASES / RIDING).read_text())
    for radio, extra in ((2, sub_entry), (1, main_entry)):
        entry = next(r for r in data["moas"]["Radios"] if (r["Station"], r["Radio"]) == (1, radio))
        entry.update(extra or {})
    cfg = parse_config(json.dumps(data["moas"]), RIDING).config
    assert cfg is not None
    e = Engine(cfg, now=0.0)
    for i, ev in enumerate(data["events"]):
        if ev["op"] == "frequency":
            e.set_frequency(ev["station"], ev["radio"], ev["khz"], now=1.0 + i)
        else:
            e.select(*ev["args"], now=1.0 + i)
    if transmitting:
        e.set_transmitting(1, 1, True, now=20.0)
    return e, Facts.of(cfg)


KEEPS_LISTENING = [({"Switches": [{"Port": 3}]}, None), (None, {"PersistSubReceiver": True})]


@pytest.mark.parametrize("transmitting", [False, True])
def test_issue_39s_case_keeps_every_rule(transmitting: bool) -> None:
    for sub_entry, main_entry in [(None, None), *KEEPS_LISTENING]:
        e, facts = _replay_39(sub_entry, main_entry, transmitting)
        counts: Counter[str] = Counter()
        assert multiop_violations(e, facts, counts) == [], (sub_entry, main_entry)
        assert counts["partner alternate beside sub"] == 1


def test_the_partners_antenna_refused_beside_a_riding_sub_receiver_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The engine before issue 39: every sub receiver of the partner blocked the alternate."""
    monkeypatch.setattr(derive, "sub_keeps_listening", lambda ix, sub: "patched")
    e, facts = _replay_39()
    assert e.radio_view(2, 1).alt is None
    assert _fired(e, facts, "partner alternate beside sub",
                  "meet 5.13's conditions beside station 1 radio 1's sub receiver")


@pytest.mark.parametrize(("sub_entry", "main_entry"), KEEPS_LISTENING)
def test_the_partners_antenna_given_beside_a_listening_sub_receiver_is_caught(
        sub_entry: dict[str, Any] | None, main_entry: dict[str, Any] | None,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """An engine broken the other way: no sub receiver of the partner ever blocks the
    alternate, though with its own port or PersistSubReceiver it keeps listening."""
    monkeypatch.setattr(derive, "sub_keeps_listening", lambda ix, sub: "")
    e, facts = _replay_39(sub_entry, main_entry)
    assert e.radio_view(2, 1).alt == 1
    assert _fired(e, facts, "partner alternate beside sub", "which keeps listening while")


def test_a_riding_sub_receiver_kept_during_transmit_beside_the_alternate_is_caught(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """A broken switch state: port 1 keeps the riding sub receiver's relay 22 while
    transmitting (as with PersistSubReceiver, which the station does not set), when port 2
    listens on antenna 1 as its alternate."""
    real = outputs_module._riding_sub_receiver

    def persisting(ix: ConfigIndex, st: Any, info: Any) -> Any:
        found = real(ix, st, info)
        return None if found is None else (found[0], found[1], True)

    monkeypatch.setattr(outputs_module, "_riding_sub_receiver", persisting)
    e, facts = _replay_39()
    assert 22 in e.switch_states()[1].station(1).tx_relays
    assert _fired(e, facts, "partner alternate beside sub", "keeps station 1 radio 2's relays")



@pytest.mark.parametrize(("broken", "text"), [
    ("patched", "meet 5.13's conditions beside"),     # every sub receiver blocks (before)
    ("", "which keeps listening while"),              # no sub receiver ever blocks
])
def test_issue_39s_evenings_catch_a_broken_engine(broken: str, text: str,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """The random evenings on issue 39's stations find either broken copy by themselves."""
    monkeypatch.setattr(derive, "sub_keeps_listening", lambda ix, sub: broken)
    for seed in range(40):
        rng = random.Random(seed)
        cfg = multiop_station(rng, partner_subs=True)
        try:
            run_evening(cfg, partner_sub_evening(cfg, rng, 300))
        except AssertionError as err:
            if text in str(err):
                return
    raise AssertionError(f"no evening caught the engine broken ({broken!r})")
