"""The engine's wanted states loaded into the emulated MOAS II firmware.

The switch enforces conflicts and hot-switch protection from the tables the
engine sends, so the two must agree: whatever an evening does, once every
station is receiving the box holds exactly the antennas and relays the engine
wants, with nothing left pending (a table that disagreed would hold a change
back, or let one through that the configuration forbids).
"""

from __future__ import annotations

import os
from typing import Any

import pytest
from engine_builders import example
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_engine_properties import FREQUENCIES

from moas_gui.config.model import Config, RadioRef
from moas_gui.engine import Engine, EngineError, SwitchState
from moas_gui.hw.moas2.emulator import EmulatorModel
from moas_gui.hw.moas2.sync import difference, initialise

NAMES = ["small-station", "big-station", "tribander-stack", "triplexer", "multi-multi-20",
         "ms-one-amp", "two-op-shared-tx"]


class Rig:
    """An engine and one emulated box per switch, wired as the server wires them."""

    def __init__(self, cfg: Config) -> None:
        self.engine = Engine(cfg)
        self.now = 0.0
        self.boxes = {w: EmulatorModel() for w in self.engine.switch_states()}
        self.sent: dict[int, SwitchState] = self.engine.switch_states()
        for w, box in self.boxes.items():
            box.feed(initialise(self.sent[w]).encode(), self.now)

    def push(self) -> None:
        for w, state in self.engine.switch_states().items():
            plan = difference(self.sent[w], state)
            assert plan.problems == ()
            self.boxes[w].feed(plan.encode(), self.now)
            self.sent[w] = state

    def tick(self, seconds: float) -> None:
        self.now += seconds
        for box in self.boxes.values():
            box.advance(self.now)

    def key(self, switch: int, port: int, on: bool) -> None:
        self.boxes[switch].set_tr(port, on, self.now)
        try:
            self.engine.set_transmitting(switch, port, on, now=self.now)
        except EngineError:
            pass
        self.push()


def _expected_relays(state: SwitchState) -> frozenset[int]:
    closed = set(state.station0)
    for s in state.stations:
        closed |= s.rx_relays if s.rx != 63 or s.tx == 63 else s.tx_relays
    return frozenset(closed)


def _converged(rig: Rig) -> None:
    for w, box in rig.boxes.items():
        want = rig.engine.switch_states()[w]
        view = box.view()
        for n in range(1, 7):
            sv = view.station(n)
            assert sv.pending == (), (w, n, sv.pending)
            assert sv.tx.antenna == want.station(n).tx, (w, n)
            assert sv.rx.antenna == want.station(n).rx, (w, n)
        assert view.relays == _expected_relays(want), (w, sorted(view.relays),
                                                      sorted(_expected_relays(want)))


def _held_conflicts(rig: Rig, cfg: Config) -> list[str]:
    """Antennas the boxes hold right now (not what is pending) that the configuration
    says conflict, between radios the manual does not let share them."""
    e = rig.engine
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None
    owners: dict[tuple[int, int], RadioRef] = {}
    antennas_of: dict[tuple[int, RadioRef, int], int] = {}
    for r in cfg.radios:
        for sp in r.switches:
            w = sp.switch or only
            assert w is not None
            owners[(w, sp.port)] = r.ref
            for a in cfg.antennas:
                slot = e.slot_of(w, a.id, r.station, r.radio, as_partner_alt=False)
                if slot is not None:
                    antennas_of.setdefault((w, r.ref, slot), a.id)
    problems = []
    for w, box in rig.boxes.items():
        view = box.view()
        held = []
        for n in range(1, 7):
            ref = owners.get((w, n))
            sv = view.station(n)
            if ref is None:
                continue
            for slot in {sv.tx.antenna, sv.rx.antenna} - {63}:
                held.append((ref, antennas_of[(w, ref, slot)]))
        for i, (ra, a) in enumerate(held):
            for rb, b in held[i + 1:]:
                ant_a, ant_b = cfg.antenna(a), cfg.antenna(b)
                assert ant_a is not None and ant_b is not None
                clash = b in ant_a.conflicts or a in ant_b.conflicts
                if ra != rb and clash and not e.may_share(ra, a, rb, b):
                    problems.append(f"switch {w}: {ra} holds {a}, {rb} holds {b}")
    return problems


def _ops(cfg: Config) -> st.SearchStrategy[list[tuple[Any, ...]]]:
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios() if cfg.radio(v.station, v.radio)]
    antennas = [a.id for a in cfg.antennas]
    keyed = [(r.station, r.radio) for r in cfg.radios if r.switches]
    options = [
        st.tuples(st.just("freq"), st.sampled_from(radios), st.sampled_from(FREQUENCIES)),
        st.tuples(st.just("select"), st.sampled_from(radios), st.sampled_from(antennas),
                  st.booleans()),
        st.tuples(st.just("key"), st.sampled_from(keyed), st.booleans()),
    ]
    if cfg.functions:
        options.append(st.tuples(st.just("function"), st.sampled_from(radios),
                                 st.sampled_from([f.id for f in cfg.functions])))
    return st.lists(st.one_of(*options), min_size=3, max_size=20)


@pytest.mark.parametrize("name", NAMES)
def test_box_holds_what_the_engine_wants_once_everyone_receives(name: str) -> None:
    cfg = example(name)
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None

    @settings(max_examples=int(os.environ.get("MOAS_ENGINE_EXAMPLES", "15")), deadline=None,
              derandomize=True, suppress_health_check=[HealthCheck.too_slow])
    @given(_ops(cfg))
    def run(ops: list[tuple[Any, ...]]) -> None:
        rig = Rig(cfg)
        keyed: set[tuple[int, int]] = set()
        for op in ops:
            rig.tick(0.5)
            try:
                if op[0] == "freq":
                    rig.engine.set_frequency(*op[1], op[2], now=rig.now)
                elif op[0] == "select":
                    rig.engine.select(*op[1], op[2], exclusive=op[3], now=rig.now)
                elif op[0] == "function":
                    rig.engine.run_function(*op[1], op[2], now=rig.now)
            except EngineError:
                pass
            if op[0] == "key":
                r = cfg.radio(*op[1])
                assert r is not None
                for sp in r.switches:
                    w = sp.switch or only
                    assert w is not None
                    rig.key(w, sp.port, op[2])
                    if op[2]:
                        keyed.add((w, sp.port))
                    else:
                        keyed.discard((w, sp.port))
            rig.push()
            rig.tick(0.05)
            assert _held_conflicts(rig, cfg) == []
        for w, port in sorted(keyed):
            rig.key(w, port, False)
        rig.tick(1.0)
        rig.push()
        rig.tick(1.0)
        _converged(rig)

    run()
