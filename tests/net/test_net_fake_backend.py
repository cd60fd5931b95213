"""The fake backend's rules (moas_gui.testing.fake_backend), called directly."""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moas_gui.net.backend import ErrorCode, LogLevel, RequestError
from moas_gui.testing.fake_backend import FakeBackend
from moas_gui.testing.fake_station import (
    DEMO_STATION,
    FakeAntenna,
    FakeLayout,
    FakeRadio,
    FakeStation,
)


class RecordingSink:
    """An EventSink that writes down what it is told."""

    def __init__(self) -> None:
        self.events: list[tuple[str, Any]] = []

    def publish_state(self) -> None:
        self.events.append(("state", None))

    def publish_radio(self, entry: Mapping[str, Any]) -> None:
        self.events.append(("radio", dict(entry)))

    def publish_rotator(self, entry: Mapping[str, Any]) -> None:
        self.events.append(("rotator", dict(entry)))

    def publish_switch(self, entry: Mapping[str, Any]) -> None:
        self.events.append(("switch", dict(entry)))

    def layouts_may_have_changed(self) -> None:
        self.events.append(("layouts", None))

    def publish_log(self, level: LogLevel, message: str) -> None:
        self.events.append(("log", (level, message)))

    def radios(self) -> list[dict[str, Any]]:
        return [e for kind, e in self.events if kind == "radio"]


@pytest.fixture
def sink() -> RecordingSink:
    return RecordingSink()


@pytest.fixture
def fake(sink: RecordingSink) -> FakeBackend:
    return FakeBackend(sink=sink)


def refusal(call: Any, *args: Any) -> RequestError:
    with pytest.raises(RequestError) as caught:
        call(*args)
    return caught.value


def radio(fake: FakeBackend, station: int, number: int = 1) -> dict[str, Any]:
    return next(r for r in fake.snapshot()["radios"]
                if (r["station"], r["radio"]) == (station, number))


def test_the_snapshot_has_the_contracts_shape(fake: FakeBackend) -> None:
    snap = fake.snapshot()
    assert set(snap) == {"config", "radios", "antennas", "rotators", "switches"}
    assert set(snap["radios"][0]) == {"station", "radio", "khz", "tx_khz", "tx", "rx", "alt",
                                      "transmitting", "inhibited", "note", "active", "focus"}
    assert set(snap["antennas"][0]) == {"id", "short", "long", "rotator"}
    assert set(snap["rotators"][0]) == {"id", "short", "heading", "target", "moving", "online"}
    assert snap["switches"] == [{"id": 1, "status": "ok"}]


def test_select_changes_both_antennas_and_tells_the_sink(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    assert fake.select(1, 1, 1, "both", False) == {"tx": 1, "rx": 1}
    assert sink.events == [("radio", radio(fake, 1)), ("layouts", None)]


def test_select_of_what_is_already_selected_tells_nothing(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    assert fake.select(1, 1, 2, "both", True) == {"tx": 2, "rx": 2}
    assert sink.events == []


def test_select_rx_only_changes_the_receive_antenna(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7150, None)
    fake.select(1, 1, 4, "both", False)
    assert fake.select(1, 1, 6, "rx", False) == {"tx": 4, "rx": 6}


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        ((1, 1, 3, "both"), "unavailable", "Antenna 3 (40 Beam) does not cover 14025 kHz"),
        ((9, 1, 1, "both"), "not_found", "there is no station 9 radio 1"),
        ((1, 1, 99, "both"), "not_found", "there is no antenna 99"),
    ],
)
def test_select_refusals_say_why(
    fake: FakeBackend, args: tuple[Any, ...], code: str, message: str
) -> None:
    error = refusal(fake.select, *args, False)
    assert (error.code, error.message) == (code, message)


def test_an_antenna_in_use_by_another_radio_is_unavailable(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7100, None)
    error = refusal(fake.select, 1, 1, 3, "both", False)
    assert error.code is ErrorCode.UNAVAILABLE
    assert error.message == "Antenna 3 (40 Beam) is in use by station 2 radio 1"


def test_receive_only_and_transmit_only_antennas_keep_to_their_role(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7100, None)
    assert refusal(fake.select, 1, 1, 6, "tx", False).message == "Antenna 6 (Bev NE) is receive-only"
    assert refusal(fake.select, 1, 1, 8, "rx", False).message == \
        "Antenna 8 (Amp Load) is transmit-only"
    assert fake.select(1, 1, 8, "tx", False)["tx"] == 8


def test_the_transmit_antenna_does_not_change_while_transmitting(fake: FakeBackend) -> None:
    fake.set_transmitting(1, 1, True)
    error = refusal(fake.select, 1, 1, 1, "tx", False)
    assert (error.code, error.message) == ("unavailable", "station 1 radio 1 is transmitting")
    fake.frequency(1, 1, 7100, None)
    assert radio(fake, 1)["tx"] == 2
    assert radio(fake, 1)["transmitting"] is True


def test_a_band_change_takes_the_lowest_numbered_free_antenna(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7100, None)
    assert (radio(fake, 1)["tx"], radio(fake, 1)["rx"]) == (4, 4)


def test_an_antenna_that_still_covers_the_frequency_is_kept(fake: FakeBackend) -> None:
    fake.select(1, 1, 1, "both", False)
    fake.frequency(1, 1, 14200, None)
    assert radio(fake, 1)["tx"] == 1


def test_a_radio_with_no_free_antenna_is_inhibited_with_a_note(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    fake.frequency(1, 1, 3550, None)
    fake.frequency(2, 1, 3600, None)
    entry = radio(fake, 2)
    assert entry["tx"] is None and entry["inhibited"] is True
    assert entry["note"] == "no free antenna covers 3600 kHz"
    assert entry["rx"] == 6
    assert sink.radios()[-1] == entry


def test_split_frequencies_are_kept_apart(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 14005, 14025)
    entry = radio(fake, 1)
    assert (entry["khz"], entry["tx_khz"]) == (14005, 14025)


def test_swap_exchanges_antennas_when_each_covers_the_others_frequency(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    fake.frequency(1, 1, 7100, None)
    fake.function(1, 1, 0)
    assert (radio(fake, 1)["tx"], radio(fake, 2)["tx"]) == (3, 4)
    assert len(sink.radios()) == 3


def test_swap_is_unavailable_across_bands(fake: FakeBackend) -> None:
    error = refusal(fake.function, 1, 1, 0)
    assert error.code is ErrorCode.UNAVAILABLE and error.message.startswith("Swap is not")


def test_rx_tx_puts_the_receive_antenna_on_the_transmit_antenna(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7100, None)
    fake.select(1, 1, 7, "rx", False)
    fake.function(1, 1, 1)
    assert radio(fake, 1)["rx"] == 4
    assert refusal(fake.function, 1, 1, 1).code is ErrorCode.UNAVAILABLE


def test_an_unknown_function_is_not_found(fake: FakeBackend) -> None:
    error = refusal(fake.function, 1, 1, 42)
    assert (error.code, error.message) == ("not_found", "there is no function 42")


def test_relative_steps_around_the_list_and_skips_what_is_in_use(fake: FakeBackend) -> None:
    assert fake.relative(1, 1, 1, None) == {"tx": 1, "rx": 1}
    assert fake.relative(1, 1, 1, None) == {"tx": 2, "rx": 2}
    assert fake.relative(1, 1, -1, None) == {"tx": 1, "rx": 1}
    fake.frequency(1, 1, 7100, None)
    assert fake.relative(1, 1, 1, None) == {"tx": 4, "rx": 4}


def test_relative_by_index_picks_that_position(fake: FakeBackend) -> None:
    assert fake.relative(1, 1, None, 1) == {"tx": 1, "rx": 1}
    error = refusal(fake.relative, 1, 1, None, 2)
    assert error.code is ErrorCode.NOT_FOUND and "there is no index 2" in error.message


def test_relative_without_a_list_for_the_band_is_unavailable(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 21000, None)
    error = refusal(fake.relative, 1, 1, 1, None)
    assert error.message == "station 1 radio 1 has no relative antennas at 21000 kHz"


def test_the_closest_layout_shows_the_buttons_for_the_frequency(fake: FakeBackend) -> None:
    layout = fake.layout(1, 1, 5, 3)
    assert (layout["rows"], layout["columns"]) == (4, 3)
    cells = {(b["row"], b["column"]): (b["id"], b["label"], b["state"]) for b in layout["buttons"]}
    assert cells == {
        (0, 0): (2, "20 Stack", "selected"),
        (0, 1): (1, "Tribander", "available"),
        (3, 0): (0, "Swap", "unavailable"),
        (3, 1): (1, "RX=TX", "unavailable"),
    }
    knob = fake.layout(1, 1, 1, 40)
    assert (knob["rows"], knob["columns"]) == (1, 10)


def test_button_states_follow_the_other_radio(fake: FakeBackend) -> None:
    fake.frequency(1, 1, 7100, None)
    states = {b["id"]: b["state"] for b in fake.layout(1, 1, 4, 3)["buttons"]
              if b["type"] == "Antenna"}
    assert states == {3: "unavailable", 4: "selected", 6: "available", 7: "available"}


def test_a_layout_for_another_station_only_is_not_offered() -> None:
    station = FakeStation(
        "one layout", (FakeAntenna(1, "A", "A", 0, 30000),),
        (FakeRadio(1, 1, 14000), FakeRadio(2, 1, 7000)),
        layouts=(FakeLayout(2, 2, (), station=2),),
    )
    fake = FakeBackend(station)
    assert fake.layout(2, 1, 2, 2)["buttons"] == []
    error = refusal(fake.layout, 1, 1, 2, 2)
    assert (error.code, error.message) == ("not_found", "there is no layout for station 1 radio 1")


def test_rotate_sets_the_target_and_settle_arrives(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    fake.rotate(1, 400)
    fake.settle(1)
    assert [e for kind, e in sink.events if kind == "rotator"] == [
        {"id": 1, "short": "Tribander", "heading": 0.0, "target": 40.0, "moving": True,
         "online": True},
        {"id": 1, "short": "Tribander", "heading": 40.0, "target": None, "moving": False,
         "online": True},
    ]


def test_stop_ends_a_turn(fake: FakeBackend) -> None:
    fake.rotate(2, 90)
    fake.stop(2)
    rot = next(r for r in fake.snapshot()["rotators"] if r["id"] == 2)
    assert (rot["heading"], rot["target"], rot["moving"]) == (45.0, None, False)


def test_an_offline_rotator_cannot_turn_and_an_unknown_one_is_not_found(fake: FakeBackend) -> None:
    assert refusal(fake.rotate, 3, 10).message == "rotator 3 (40 Beam) is offline"
    assert refusal(fake.stop, 7).code is ErrorCode.NOT_FOUND


def test_stopped_switches_refuse_changes_but_still_show_state(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    fake.stop_switches()
    assert ("switch", {"id": 1, "status": "stopped"}) in sink.events
    error = refusal(fake.select, 1, 1, 1, "both", False)
    assert (error.code, error.message) == ("not_running", "the switches are stopped")
    assert fake.snapshot()["switches"] == [{"id": 1, "status": "stopped"}]
    fake.start_switches()
    assert fake.select(1, 1, 1, "both", False)["tx"] == 1


def test_without_a_configuration_everything_is_not_running(
    fake: FakeBackend, sink: RecordingSink
) -> None:
    fake.unload()
    for call, args in [(fake.snapshot, ()), (fake.layout, (1, 1, 4, 3)), (fake.stop, (1,)),
                       (fake.frequency, (1, 1, 7000, None))]:
        assert refusal(call, *args).code is ErrorCode.NOT_RUNNING
    fake.load()
    assert sink.events[-1] == ("state", None)
    assert fake.snapshot()["config"] == DEMO_STATION.name


def test_every_call_is_recorded_in_order(fake: FakeBackend) -> None:
    fake.select(1, 1, 1, "tx", True)
    fake.stop(1)
    assert fake.calls == [("select", (1, 1, 1, "tx", True)), ("stop", (1,))]


# ---- any well-typed request is served or refused with a reason ------------------------------

SMALL = st.sampled_from([0, 1, 2, 3]) | st.integers(min_value=0, max_value=2_147_483_647)
KHZ = st.sampled_from([0.0, 1800.0, 3550.5, 7000.0, 7300.0, 14025.0, 14350.0, 29700.0]) \
    | st.floats(min_value=0, max_value=1e9)
CALLS = st.one_of(
    st.tuples(st.just("frequency"), SMALL, SMALL, KHZ, st.none() | KHZ),
    st.tuples(st.just("select"), SMALL, SMALL, st.integers(0, 9),
              st.sampled_from(["both", "tx", "rx"]), st.booleans()),
    st.tuples(st.just("function"), SMALL, SMALL, SMALL),
    st.tuples(st.just("relative"), SMALL, SMALL, st.sampled_from([1, -1]), st.none()),
    st.tuples(st.just("relative"), SMALL, SMALL, st.none(), SMALL),
    st.tuples(st.just("layout"), SMALL, SMALL, st.integers(1, 1000), st.integers(1, 1000)),
    st.tuples(st.just("rotate"), SMALL, st.floats(min_value=-360, max_value=720)),
    st.tuples(st.just("stop"), SMALL),
    st.tuples(st.just("set_transmitting"), st.just(1) | st.just(2), st.just(1), st.booleans()),
)


@settings(max_examples=100, deadline=None)  # the wide search: benchmarks/bench_properties.py
@given(st.lists(CALLS, max_size=40))
def test_any_sequence_of_well_typed_calls_is_served_or_refused_with_a_code(
    calls: list[tuple[Any, ...]],
) -> None:
    sink = RecordingSink()
    fake = FakeBackend(sink=sink)
    for name, *args in calls:
        try:
            getattr(fake, name)(*args)
        except RequestError as e:
            assert e.message
        snapshot = fake.snapshot()
        json.dumps(snapshot, allow_nan=False)
        used = [a for r in snapshot["radios"] for a in {r["tx"], r["rx"]} if a is not None]
        assert len(used) == len(set(used)), f"two radios share an antenna: {snapshot['radios']}"
    for kind, entry in sink.events:
        json.dumps(entry, allow_nan=False)
