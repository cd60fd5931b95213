"""The manual's rules after every random event (see ``engine_invariants.py`` for the rules):
every example station and generated stations, a fast derandomized subset here; the
benchmark-sized job (``benchmarks/bench_engine_properties.py``) runs over 10^5 events."""

from __future__ import annotations

import os
import random

import pytest
from engine_builders import example
from engine_invariants import Facts, operations, replay_matches, run_evening
from engine_stations import frequencies_for, generated_station
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EXAMPLES = ["2x6", "small-station", "big-station", "tribander-stack", "multi-multi-20",
            "triplexer", "ms-one-amp", "two-op-shared-tx"]
RUNS = int(os.environ.get("MOAS_ENGINE_EXAMPLES", "2"))
"""Evenings per station here (two on each of eight examples, 300 events each); the
benchmark-sized run is ``benchmarks/bench_engine_properties.py``."""
EVENTS = 300

FAST = settings(max_examples=RUNS, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.parametrize("name", EXAMPLES)
def test_every_rule_holds_after_every_event_on_the_examples(name: str) -> None:
    cfg = example(name)
    facts = Facts.of(cfg)

    @FAST
    @given(st.integers(0, 2**32 - 1))
    def run(seed: int) -> None:
        ops = list(operations(cfg, random.Random(seed), EVENTS))
        run_evening(cfg, ops, facts)

    run()


@FAST
@given(st.integers(0, 2**32 - 1))
def test_every_rule_holds_after_every_event_on_generated_stations(seed: int) -> None:
    rng = random.Random(seed)
    cfg = generated_station(rng)
    run_evening(cfg, list(operations(cfg, rng, EVENTS, frequencies_for(cfg))))


@pytest.mark.parametrize("name", ["big-station", "multi-multi-20"])
def test_the_same_events_give_the_same_result(name: str) -> None:
    cfg = example(name)
    ops = list(operations(cfg, random.Random(name), 200))
    assert replay_matches(cfg, ops)


def test_the_checks_catch_a_broken_rule() -> None:
    """The checks themselves can fail: two radios forced onto one antenna are reported."""
    from engine_builders import engine
    from engine_invariants import violations

    from moas_gui.engine.engine import Engine
    e: Engine = engine("big-station")
    e.set_frequency(1, 1, 14025)
    e.set_frequency(2, 1, 14025)
    v1 = e.radio_view(1, 1)
    assert violations(e, Facts.of(e.config)) == []
    # Forge a state no operation can reach: both radios on radio 1.1's antenna.
    e._views[e._radio(2, 1)] = e.radio_view(2, 1).__class__(
        2, 1, 14025.0, 14025.0, v1.tx, v1.rx)
    assert any("conflict" in p for p in violations(e, Facts.of(e.config)))
