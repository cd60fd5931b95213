"""The emulated MOAS II's safety rules, tried on many random stations and
histories (hypothesis):

* the relays of a transmitting station never change in wait mode;
* in interrupt mode they change only while its inhibit is asserted;
* two stations never hold conflicting antennas (alternates aside), and a
  station on an alternate that conflicts closes no relays.

The clock moves one millisecond at a time and the rules are checked after
every step and every command, so a change cannot slip between two looks (a
step while no timer runs is skipped: the box's state changes only when a
timer runs out or a command or key line comes).
"""

from __future__ import annotations

from dataclasses import dataclass

from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.station import SlotRole
from moas_gui.hw.moas2.emulator.view import BoxView
from moas_gui.hw.moas2.sixbit import to_char

ANTENNAS = [0, 1, 2, 3, 4, 5, 63]
STATIONS = range(1, 7)
BUSY = [1, 2, 3]
"""The stations the histories use: few, so that they meet often."""


@dataclass(frozen=True)
class Setup:
    conflicts: list[tuple[int, int]]
    fast: list[tuple[int, int]]
    interrupt: frozenset[int]
    inhibit_ms: int
    interrupt_ms: int
    receive_ms: dict[int, int]
    alternates: dict[int, frozenset[int]]
    systems: dict[int, int]

    def commands(self) -> str:
        pairs = "".join(to_char(a) + to_char(b) for a, b in self.conflicts)
        fast = "".join(to_char(a) + to_char(b) for a, b in self.fast)
        text = f"%C{pairs};&F{fast};[{self.inhibit_ms};]{self.interrupt_ms};"
        if self.interrupt:
            text += "/I" + "".join(map(str, sorted(self.interrupt))) + ";"
        for n, ms in self.receive_ms.items():
            text += f"\\{n}{ms};"
        for n, others in self.alternates.items():
            text += f"@{n}{''.join(map(str, sorted(others - {n})))};"
        if self.systems:
            text += "_S" + "".join(to_char(a) + to_char(s) for a, s in self.systems.items()) + ";"
        return text + "*1;"


_pair = st.tuples(st.sampled_from(ANTENNAS[:-1]), st.sampled_from(ANTENNAS[:-1]))
setups = st.builds(
    Setup,
    conflicts=st.lists(_pair, max_size=8).map(lambda p: p + [(a, a) for a in range(6)]),
    fast=st.lists(_pair, max_size=10),
    interrupt=st.frozensets(st.sampled_from(BUSY)),
    inhibit_ms=st.integers(5, 12),
    interrupt_ms=st.integers(0, 5),
    receive_ms=st.dictionaries(st.sampled_from(BUSY), st.integers(0, 8), max_size=3),
    alternates=st.dictionaries(
        st.sampled_from(BUSY), st.frozensets(st.sampled_from(BUSY)), max_size=2
    ),
    systems=st.dictionaries(st.sampled_from(ANTENNAS[:-1]), st.integers(1, 2), max_size=2),
)

_antenna_op = st.tuples(
    st.just("antenna"),
    st.sampled_from(BUSY),
    st.sampled_from("BTRAX"),
    st.sampled_from(ANTENNAS),
    st.frozensets(st.integers(0, 15), max_size=4),
)
operations = st.lists(
    st.one_of(
        _antenna_op,
        _antenna_op,
        st.tuples(st.just("key"), st.sampled_from(BUSY), st.just(True)),
        st.tuples(st.just("key"), st.sampled_from(BUSY), st.booleans()),
        st.tuples(st.just("wait"), st.integers(1, 12)),
        st.tuples(st.just("wait"), st.integers(1, 12)),
        st.tuples(st.just("resolver"), st.booleans()),
    ),
    min_size=15,
    max_size=50,
)


class Watcher:
    """Runs the model and checks the rules after every look."""

    def __init__(self, setup: Setup) -> None:
        self.model = EmulatorModel()
        self.setup = setup
        self.ms = 0
        self.model.feed(setup.commands().encode(), 0.0)
        self.before = self.look(self.model.view())

    @staticmethod
    def look(view: BoxView) -> dict[int, tuple[bool, frozenset[int]]]:
        return {s.number: (s.transmitting, s.closed) for s in view.stations}

    def check(self) -> None:
        view = self.model.view()  # one look serves every rule
        now = self.look(view)
        for n in STATIONS:
            was_on_air, was_closed = self.before[n]
            on_air, closed = now[n]
            if was_on_air and on_air and closed != was_closed:
                assert n in self.setup.interrupt, f"station {n} relays moved on the air in wait mode"
                assert self.model.inhibited(n), f"station {n} relays moved without inhibit"
        self.check_conflicts(view)
        self.before = now

    def check_conflicts(self, view: BoxView) -> None:
        claims = {}
        for n, station in self.model.stations.items():
            held = {station.current[SlotRole.TX].antenna, station.current[SlotRole.RX].antenna}
            if SlotRole.TX in station.incoming:
                held.add(station.incoming[SlotRole.TX].antenna)
            claims[n] = held
        table = self.model.conflicts
        for a in STATIONS:
            for b in STATIONS:
                if a < b:
                    for x in claims[a]:
                        for y in claims[b]:
                            assert not table.get(x, y), f"stations {a}, {b} hold {x}, {y}"
        for station_view in view.stations:
            if station_view.on_alternate and any(
                table.get(station_view.alt.antenna, y) for m in STATIONS
                if m != station_view.number for y in claims[m]
            ):
                assert station_view.closed == frozenset(), \
                    f"station {station_view.number} on a busy alternate"

    def run(self, op: tuple) -> None:  # type: ignore[type-arg]
        kind = op[0]
        if kind == "antenna":
            _, station, letter, antenna, relays = op
            if letter == "X":
                antenna = 0
            text = f"!{station}{letter}{to_char(antenna)}{''.join(to_char(r) for r in sorted(relays))};"
            self.model.feed(text.encode(), self.ms / 1000)
            self.check()
        elif kind == "key":
            self.model.set_tr(op[1], op[2], self.ms / 1000)
            self.check()
        elif kind == "resolver":
            self.model.feed(b"*R;" if op[1] else b"*r;", self.ms / 1000)
            self.check()
        else:
            for _ in range(op[1]):
                self.ms += 1
                if self.model.next_deadline() is None:
                    continue  # no timer runs: the box changes only at the next command
                self.model.advance(self.ms / 1000)
                self.check()


_STATION_1_INTERRUPTS_ON_ANTENNA_0 = (
    Setup(
        conflicts=[(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5)],
        fast=[],
        interrupt=frozenset({1}),
        inhibit_ms=5,
        interrupt_ms=1,
        receive_ms={},
        alternates={},
        systems={},
    ),
    [("antenna", 1, "B", 0, frozenset())] * 9
    + [
        ("antenna", 1, "B", 0, frozenset([0])),
        ("antenna", 2, "B", 0, frozenset()),
        ("key", 1, True),
        ("antenna", 1, "B", 0, frozenset()),
        ("antenna", 1, "B", 1, frozenset()),
        ("wait", 5),
    ],
)
"""Station 1 (interrupt mode) transmits on antenna 0 and asks for antenna 1
while station 2 waits for antenna 0: station 2 must not get antenna 0 in the
step that starts station 1's interrupt, since station 1's relays stay on
antenna 0 through the interrupt delay."""


# 60 fixed histories here; the wide random search is benchmarks/bench_properties.py
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(setups, operations)
@example(*_STATION_1_INTERRUPTS_ON_ANTENNA_0)
def test_safety_rules_hold_through_any_history(setup: Setup, ops: list) -> None:  # type: ignore[type-arg]
    watcher = Watcher(setup)
    for op in ops:
        watcher.run(op)
    # Finally let everyone go back to receive and every timer run out.
    for n in BUSY:
        watcher.run(("key", n, False))
    watcher.run(("resolver", True))
    watcher.run(("wait", 80))
    assert watcher.model.next_deadline() is None
    assert not any(watcher.model.inhibited(n) for n in STATIONS)


@settings(max_examples=60, deadline=None)
@given(setups, st.lists(_antenna_op, max_size=25))
def test_with_everyone_receiving_no_request_waits_except_for_a_conflict(
    setup: Setup, ops: list  # type: ignore[type-arg]
) -> None:
    watcher = Watcher(setup)
    for op in ops:
        watcher.run(op)
    watcher.run(("wait", 80))
    for n, station in watcher.model.stations.items():
        for kind, request in station.pending.items():
            assert kind in (SlotRole.TX, SlotRole.RX), f"station {n} {kind} waits with nobody on the air"
            assert request.conflict_reported, f"station {n} {kind} waits but not for a conflict"


def test_an_antenna_left_by_an_interrupt_goes_to_the_waiting_station_when_the_relays_move() -> None:
    setup, ops = _STATION_1_INTERRUPTS_ON_ANTENNA_0
    watcher = Watcher(setup)
    for op in ops:
        watcher.run(op)
    one, two = watcher.model.stations[1], watcher.model.stations[2]
    assert one.current[SlotRole.TX].antenna == 0 and two.current[SlotRole.TX].antenna == 63
    watcher.run(("wait", 1))  # the interrupt delay runs out: station 1's relays move
    assert one.current[SlotRole.TX].antenna == 1
    assert two.current[SlotRole.TX].antenna == 0 and two.current[SlotRole.RX].antenna == 0
