"""Safety rules under random evenings: hypothesis drives frequencies, presses, functions,
relative steps, directions and T/R changes through every example station."""

from __future__ import annotations

import functools
import os
from typing import Any

import pytest
from engine_builders import antenna, config, example, radio, table_problems
from engine_invariants import apply as apply_op
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from moas_gui.config.model import Config, RadioRef, RotatorControl
from moas_gui.engine import Engine, EngineError

EXAMPLE_NAMES = ["2x6", "small-station", "big-station", "tribander-stack", "multi-multi-20",
                 "triplexer", "ms-one-amp", "two-op-shared-tx"]
FREQUENCIES = [1830.0, 1999.0, 3550.0, 3799.5, 7025.0, 7300.0, 10120.0, 13999.0, 14000.0,
               14025.0, 14200.0, 14351.0, 18100.0, 21025.0, 21300.0, 24900.0, 28500.0,
               5000.0, 50100.0]


def _shared_tx_station() -> Config:
    rel = {(1, 1): [0], (1, 2): [8], (1, 3): [16]}
    radios = [radio(1, 1, 1, always=(RadioRef(1, 2),), partner=(RadioRef(1, 2),)),
              radio(1, 2, 2, always=(RadioRef(1, 1),), partner=(RadioRef(1, 1),)),
              radio(1, 3, 3, inhibit_only_on_transmit=True)]
    return config([
        antenna(0, (20, 15), rel, conflicts=(0, 1, 2), fast=(0, 1, 2, 3), shared_tx=True),
        antenna(1, (20, 15), {(1, 1): [1], (1, 2): [9], (1, 3): [17]}, conflicts=(0, 1),
                fast=(0, 1, 2)),
        antenna(2, (20, 15), {(1, 1): [2], (1, 2): [10], (1, 3): [18]}, conflicts=(0, 2),
                fast=(0, 1, 2)),
        antenna(3, (20, 15, 40), {(1, 1): [3], (1, 2): [11], (1, 3): [19]}, fast=(0, 3)),
        antenna(4, (20, 15, 40), {(1, 1): [4], (1, 2): [12], (1, 3): [20]}, rx_only=True,
                conflicts=(), fast=(0, 3)),
    ], radios)


NAMES = [*EXAMPLE_NAMES, "shared-tx"]


@functools.cache
def station(name: str) -> Config:
    """The station ``name``, read when its test first asks (not when every worker collects
    the suite: reading the examples cost each worker 0.06 s of processor time)."""
    return _shared_tx_station() if name == "shared-tx" else example(name)


def _operations(cfg: Config) -> st.SearchStrategy[list[tuple[Any, ...]]]:
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios()]
    antennas = [a.id for a in cfg.antennas]
    ports = sorted({(s.id, p) for s in cfg.switches for p in range(1, 7)})
    electrical = [r.id for r in cfg.rotators if r.control is RotatorControl.ELECTRICAL]
    options = [
        st.tuples(st.just("freq"), st.sampled_from(radios), st.sampled_from(FREQUENCIES),
                  st.sampled_from([None, 0.0, 3.0, -250.0])),
        st.tuples(st.just("select"), st.sampled_from(radios), st.sampled_from(antennas),
                  st.sampled_from(["both", "both", "tx", "rx"]), st.booleans()),
        st.tuples(st.just("tr"), st.sampled_from(ports), st.booleans()),
        st.tuples(st.just("relative"), st.sampled_from(radios), st.sampled_from([1, -1])),
        st.tuples(st.just("run"), st.just("stop") | st.just("start")),
    ]
    if cfg.functions:
        options.append(st.tuples(st.just("function"), st.sampled_from(radios),
                                 st.sampled_from([f.id for f in cfg.functions])))
    if electrical:
        options.append(st.tuples(st.just("direction"), st.sampled_from(electrical),
                                 st.integers(0, 359)))
    return st.lists(st.one_of(*options), min_size=5, max_size=30)


def _covers(cfg: Config, station: int, number: int, antenna_id: int, khz: float) -> bool:
    ant = cfg.antenna(antenna_id)
    assert ant is not None
    for cr in ant.control:
        if any(s.applies_to(station, number) for s in cr.stations) and cr.range.contains(khz):
            return True
    return False


def _check(e: Engine, cfg: Config) -> None:
    assert table_problems(e) == []
    states = e.switch_states()
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None
    for view in e.radios():
        r = cfg.radio(view.station, view.radio)
        if r is None or view.khz is None or view.tx_khz is None:
            continue
        if any(x.sub_receiver == view.radio or x.alt_receiver == view.radio
               for x in cfg.radios if x.station == view.station):
            continue
        covered = view.tx is not None and _covers(cfg, view.station, view.radio, view.tx,
                                                  view.tx_khz)
        if not covered:
            assert view.inhibited, view
            if r.inhibit_only_on_transmit and not view.transmitting:
                continue
            for sp in r.switches:
                w = sp.switch or only
                assert w is not None
                assert sp.port in states[w].inhibited, (view, w)


@pytest.mark.parametrize("name", sorted(NAMES))
def test_random_evenings_keep_every_safety_rule(name: str) -> None:
    cfg = station(name)

    @settings(max_examples=int(os.environ.get("MOAS_ENGINE_EXAMPLES", "25")), deadline=None,
              derandomize=True,
              suppress_health_check=[HealthCheck.too_slow])
    @given(_operations(cfg))
    def run(ops: list[tuple[Any, ...]]) -> None:
        e = Engine(cfg)
        now = 0.0
        for op in ops:
            now += 0.7
            before_states = e.switch_states()
            before_views = {(v.station, v.radio): v for v in e.radios()}
            transmitting = {(v.station, v.radio) for v in e.radios() if v.transmitting}
            try:
                changes = apply_op(e, op, now)
            except EngineError as err:
                assert err.message
                assert e.switch_states() == before_states
                assert {(v.station, v.radio): v for v in e.radios()} == before_views
                continue
            after = e.switch_states()
            for w, state in after.items():
                if w in changes.switches:
                    assert changes.switches[w] == state
                else:
                    assert before_states[w] == state
            for v in e.radios():
                key = (v.station, v.radio)
                assert (RadioRef(*key) in changes.radios) == (before_views[key] != v)
            if op[0] != "tr":
                for s, n in transmitting:
                    r = cfg.radio(s, n)
                    for sp in r.switches if r else ():
                        w = sp.switch or cfg.switches[0].id
                        assert after[w].station(sp.port).extra == \
                            before_states[w].station(sp.port).extra
            _check(e, cfg)

    run()
