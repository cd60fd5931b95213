"""The rotator manager with Test and Electrical rotators, views, errors and the API."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Callable
from dataclasses import replace

import pytest
import pytest_asyncio
from helpers import FakeClock

import moas_gui.hw.rotators as rotators_package
from moas_gui.config.model import Antenna, Config, Rotator, RotatorControl
from moas_gui.hw.rotators import RotatorError, RotatorManager, RotatorView, Timing

FAST = Timing(test_tick=0.05, reconnect_min=0.05, reconnect_max=0.2, reply_timeout=0.5,
              connect_timeout=0.5)


class Recorder:
    """Collects every view the manager publishes.  Given a fake clock, waiting for a view
    moves that clock on, a tick at a time; otherwise it waits in real time."""

    def __init__(self, clock: FakeClock | None = None) -> None:
        self.views: list[RotatorView] = []
        self.clock = clock or FakeClock()
        self._fake = clock is not None
        self._changed = asyncio.Event()

    @property
    def fake(self) -> bool:
        """True when waiting moves the fake clock on (False: real time)."""
        return self._fake

    def __call__(self, view: RotatorView) -> None:
        self.views.append(view)
        self._changed.set()

    def of(self, rotator_id: int) -> list[RotatorView]:
        return [v for v in self.views if v.id == rotator_id]

    async def wait_for(self, test: Callable[[RotatorView], bool], timeout: float = 5.0,
                       since: int = 0) -> RotatorView:
        """The first view (from number ``since`` on) that passes ``test`` within
        ``timeout`` seconds."""
        if not self._fake:
            async with asyncio.timeout(timeout):
                while True:
                    for view in self.views[since:]:
                        if test(view):
                            return view
                    self._changed.clear()
                    await self._changed.wait()
        deadline = self.clock.now() + timeout
        while True:
            for view in self.views[since:]:
                if test(view):
                    return view
            if self.clock.now() >= deadline:
                raise TimeoutError(f"no such view within {timeout} s")
            await self.clock.advance(FAST.test_tick)


def make_rotator(**fields: object) -> Rotator:
    base: dict[str, object] = {"id": 2, "short_name": "10 side", "ccw_limit": 0,
                               "rotation": 300, "control": RotatorControl.TEST}
    base.update(fields)
    return Rotator(**base)  # type: ignore[arg-type]


@pytest_asyncio.fixture
async def recorder() -> Recorder:
    return Recorder(FakeClock())


@pytest_asyncio.fixture
async def manager(recorder: Recorder) -> AsyncIterator[RotatorManager]:
    four_square = [
        Antenna(id=10 + i, short_name=name, rotator=1, offset=offset)
        for i, (name, offset) in enumerate([("NE", 45), ("SE", 135), ("SW", 225), ("NW", 315)])
    ]
    system = Antenna(id=20, short_name="4SQ", rotator=1, in_use=(10, 11))
    calls: list[tuple[int, int]] = []

    def select(rotator_id: int, heading: int) -> object:
        if heading == 99:
            raise RuntimeError("antenna NE is in use by station 2")
        calls.append((rotator_id, heading))
        return "changes"

    manager = RotatorManager(
        [
            make_rotator(),
            Rotator(id=1, short_name="4-square", control=RotatorControl.ELECTRICAL),
            make_rotator(id=3, short_name="Hidden", invisible=True, rotation=360),
        ],
        on_change=recorder, antennas=[*four_square, system], select_direction=select,
        timing=replace(FAST, clock=recorder.clock),
    )
    manager.select_calls = calls  # type: ignore[attr-defined]
    await manager.start()
    yield manager
    await manager.close()


# ---- views ----------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_views_follow_the_client_protocol_and_hide_invisible_rotators(
    manager: RotatorManager,
) -> None:
    views = manager.views()
    assert [v.id for v in views] == [2, 1]
    assert views[0].to_json() == {"id": 2, "short": "10 side", "heading": 0, "target": None,
                                  "moving": False, "online": True, "long": "10 side",
                                  "ccw_limit": 0, "rotation": 300, "has_stop": False,
                                  "electrical": False}
    assert manager.view(3).short == "Hidden"


@pytest.mark.asyncio
async def test_a_rotator_without_a_name_is_called_by_its_number() -> None:
    manager = RotatorManager([Rotator(id=7)], timing=FAST)
    assert manager.views()[0].short == "Rotator 7"


# ---- the Test rotator -----------------------------------------------------------------

@pytest.mark.asyncio
async def test_test_rotator_turns_at_ten_degrees_a_second_and_reports_on_the_way(
    manager: RotatorManager, recorder: Recorder
) -> None:
    clock = recorder.clock
    began = clock.now()
    await manager.rotate(2, 6)
    assert manager.view(2).target == 6 and manager.view(2).moving
    done = await recorder.wait_for(lambda v: v.id == 2 and v.heading == 6 and not v.moving)
    took = clock.now() - began
    assert 0.55 <= took <= 1.2
    assert done.target is None
    on_the_way = [v.heading for v in recorder.of(2) if v.moving]
    assert len({h for h in on_the_way if h is not None and 0 < h < 6}) >= 2


@pytest.mark.asyncio
async def test_test_rotator_stops_where_it_is(
    manager: RotatorManager, recorder: Recorder
) -> None:
    await manager.rotate(2, 100)
    await recorder.wait_for(lambda v: v.id == 2 and v.heading is not None and v.heading >= 3)
    await manager.stop(2)
    stopped = manager.view(2)
    assert not stopped.moving and stopped.target is None
    assert stopped.heading is not None and 3 <= stopped.heading <= 6
    await recorder.clock.advance(0.2)
    assert manager.view(2).heading == stopped.heading


@pytest.mark.asyncio
async def test_test_rotator_clamps_a_heading_outside_its_travel(
    manager: RotatorManager, recorder: Recorder, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.INFO, "moas_gui.hw.rotators")
    await manager.rotate(2, 2)
    await recorder.wait_for(lambda v: v.id == 2 and v.heading == 2 and not v.moving)
    await manager.rotate(2, 355)  # travel 0..300: 355 is 5 from north, 55 from 300
    assert manager.view(2).target == 0 and manager.view(2).moving
    assert "cannot point at 355 degrees; turning to the end of its travel (0)" in caplog.text
    await recorder.wait_for(lambda v: v.id == 2 and v.heading == 0 and not v.moving)


@pytest.mark.asyncio
async def test_a_new_request_during_a_turn_replans_from_where_the_rotator_is(
    manager: RotatorManager, recorder: Recorder
) -> None:
    await manager.rotate(2, 200)
    await recorder.wait_for(lambda v: v.id == 2 and v.heading is not None and v.heading >= 2)
    await manager.rotate(2, 0)
    back = await recorder.wait_for(lambda v: v.id == 2 and v.heading == 0 and not v.moving)
    assert back.target is None


# ---- the Electrical rotator -----------------------------------------------------------

@pytest.mark.asyncio
async def test_electrical_rotator_calls_the_selection_and_takes_the_closest_direction(
    manager: RotatorManager, recorder: Recorder
) -> None:
    await manager.rotate(1, 100)
    assert manager.select_calls == [(1, 100)]  # type: ignore[attr-defined]
    view = manager.view(1)
    assert view.heading == 135 and not view.moving and view.online
    assert recorder.of(1)[-1].heading == 135


@pytest.mark.asyncio
async def test_electrical_refusal_becomes_unavailable_and_keeps_the_heading(
    manager: RotatorManager,
) -> None:
    await manager.rotate(1, 300)
    with pytest.raises(RotatorError) as caught:
        await manager.rotate(1, 99)
    assert caught.value.code == "unavailable"
    assert "in use by station 2" in caught.value.message
    assert manager.view(1).heading == 315


@pytest.mark.asyncio
async def test_electrical_direction_changed_elsewhere_is_shown(manager: RotatorManager) -> None:
    manager.note_direction(1, 225)
    assert manager.view(1).heading == 225


@pytest.mark.asyncio
async def test_electrical_without_a_selection_callback_is_unavailable() -> None:
    manager = RotatorManager([Rotator(id=1, control=RotatorControl.ELECTRICAL)], timing=FAST)
    await manager.start()
    try:
        with pytest.raises(RotatorError, match="no way to select") as caught:
            await manager.rotate(1, 90)
        assert caught.value.code == "unavailable"
        await manager.stop(1)  # nothing to stop: fine
    finally:
        await manager.close()


# ---- requests that do not wait ---------------------------------------------------------

@pytest.mark.asyncio
async def test_start_rotate_turns_in_the_background(
    manager: RotatorManager, recorder: Recorder
) -> None:
    manager.start_rotate(2, 3)
    await recorder.wait_for(lambda v: v.id == 2 and v.heading == 3 and not v.moving)
    manager.start_rotate(2, 100)
    await recorder.wait_for(lambda v: v.id == 2 and v.moving)
    manager.start_stop(2)
    await recorder.wait_for(lambda v: v.id == 2 and not v.moving and v.target is None,
                            since=len(recorder.views) - 1)


@pytest.mark.asyncio
async def test_start_rotate_raises_at_once_what_it_can_know(manager: RotatorManager) -> None:
    with pytest.raises(RotatorError) as caught:
        manager.start_rotate(42, 10)
    assert caught.value.code == "not_found"
    with pytest.raises(RotatorError) as caught:
        manager.start_rotate(2, "east")
    assert caught.value.code == "bad_request"
    with pytest.raises(RotatorError) as caught:
        manager.start_rotate(1, 99)  # the engine refuses the electrical selection
    assert caught.value.code == "unavailable"
    manager.start_rotate(1, 200)
    assert manager.view(1).heading == 225


@pytest.mark.asyncio
async def test_start_rotate_of_an_unusable_rotator_raises_unavailable() -> None:
    manager = RotatorManager([make_rotator(rotation=0)], timing=FAST)
    await manager.start()
    try:
        with pytest.raises(RotatorError, match="Rotation must be") as caught:
            manager.start_rotate(2, 10)
        assert caught.value.code == "unavailable"
    finally:
        await manager.close()


# ---- errors ---------------------------------------------------------------------------

@pytest.mark.asyncio
@pytest.mark.parametrize(("rotator", "heading", "code"), [
    (42, 90, "not_found"),
    ("2", 90, "bad_request"),
    (2, "north", "bad_request"),
    (2, True, "bad_request"),
    (2, float("nan"), "bad_request"),
    (2, float("inf"), "bad_request"),
])
async def test_bad_requests_get_a_code_and_a_sentence(
    manager: RotatorManager, rotator: object, heading: object, code: str
) -> None:
    with pytest.raises(RotatorError) as caught:
        await manager.rotate(rotator, heading)
    assert caught.value.code == code
    assert len(caught.value.message) > 10
    assert manager.view(2).online


@pytest.mark.asyncio
async def test_stop_of_an_unknown_rotator_is_not_found(manager: RotatorManager) -> None:
    with pytest.raises(RotatorError) as caught:
        await manager.stop(9)
    assert caught.value.code == "not_found" and "9" in caught.value.message


@pytest.mark.asyncio
async def test_headings_beyond_one_turn_are_folded(
    manager: RotatorManager, recorder: Recorder
) -> None:
    await manager.rotate(3, 365)
    assert manager.view(3).target == 5
    await manager.rotate(3, -10)
    assert manager.view(3).target == 350


@pytest.mark.asyncio
@pytest.mark.parametrize(("fields", "reason"), [
    ({"rotation": 0}, "Rotation must be"),
    ({"control": RotatorControl.SERIAL, "model": "Nonesuch Deluxe", "comm_port": "COM3"},
     "Model 'Nonesuch Deluxe'"),
    ({"control": RotatorControl.SERIAL, "model": "Yaesu"}, "CommPort is missing"),
    ({"control": RotatorControl.SERIAL, "model": "Yaesu", "comm_port": "COM 3"}, "one word"),
    ({"control": RotatorControl.ROTATOR_GENIUS, "address": "host:99999"}, "port '99999' is not a number"),
    ({"control": RotatorControl.ROTATOR_GENIUS, "port": 3}, "Port must be 1 or 2"),
    ({"control": RotatorControl.HAMLIB, "address": ""}, "address is empty"),
])
async def test_unusable_configuration_is_offline_and_says_why_while_others_carry_on(
    fields: dict[str, object], reason: str, caplog: pytest.LogCaptureFixture
) -> None:
    broken = Rotator(id=5, short_name="Broken", **fields)  # type: ignore[arg-type]
    manager = RotatorManager([broken, make_rotator()], timing=FAST, start_moas_rotator=False)
    await manager.start()
    try:
        assert not manager.view(5).online
        assert reason in caplog.text and "Rotator 5 (Broken)" in caplog.text
        with pytest.raises(RotatorError, match=reason) as caught:
            await manager.rotate(5, 10)
        assert caught.value.code == "unavailable"
        await manager.rotate(2, 1)
        assert manager.view(2).online and manager.view(2).target == 1
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_a_failing_change_callback_is_logged_and_does_not_stop_the_rotator(
    caplog: pytest.LogCaptureFixture,
) -> None:
    def broken(view: RotatorView) -> None:
        raise RuntimeError("client went away")

    clock = FakeClock()
    manager = RotatorManager([make_rotator()], on_change=broken,
                             timing=replace(FAST, clock=clock))
    await manager.start()
    try:
        await manager.rotate(2, 1)
        await clock.advance(0.3)
        assert manager.view(2).heading == 1
        assert "change callback failed for rotator 2 (10 side)" in caplog.text
    finally:
        await manager.close()


@pytest.mark.asyncio
async def test_from_config_takes_rotators_antennas_and_start_moas_rotator() -> None:
    config = Config(
        rotators=(Rotator(id=1, control=RotatorControl.ELECTRICAL),
                  Rotator(id=4, control=RotatorControl.SERIAL, model="RotorEZ",
                          comm_port="COM4")),
        antennas=(Antenna(id=1, rotator=1, offset=90), Antenna(id=2, rotator=1, offset=270)),
        start_moas_rotator=False,
    )
    manager = RotatorManager.from_config(config, timing=FAST)
    assert manager.local_program is None
    assert manager.drivers[1].directions == (90.0, 270.0)  # type: ignore[attr-defined]


def test_the_public_names_are_frozen() -> None:
    assert sorted(rotators_package.__all__) == sorted([
        "RotatorError", "RotatorManager",
        "RotatorStatus", "RotatorView", "Timing", "Travel", "Turn", "angular_distance",
        "antenna_heading", "closest_direction", "normalize", "plan_turn", "rotator_heading_for",
    ])
    for name in rotators_package.__all__:
        assert hasattr(rotators_package, name)


def test_the_timing_test_hook_changes_the_delays_it_names() -> None:
    from moas_gui.hw.rotators.base import timing_from_hook

    timing = timing_from_hook(" reconnect_min=0.05, restart_min=0.1,restart_max=2 ,")
    assert (timing.reconnect_min, timing.restart_min, timing.restart_max) == (0.05, 0.1, 2.0)
    assert replace(timing, reconnect_min=0.5, restart_min=1.0, restart_max=30.0) == Timing()
    for text, why in [("reconnect=1", "'reconnect' is not a rotator delay"),
                      ("clock=1", "'clock' is not a rotator delay"),
                      ("restart_min=soon", "'soon' is not a number of seconds"),
                      ("reply_timeout=0", "a delay must be a positive number"),
                      ("reply_timeout=nan", "a delay must be a positive number")]:
        with pytest.raises(ValueError, match=why):
            timing_from_hook(text)


def test_the_manager_restarts_its_program_after_the_timings_waits() -> None:
    serial = Rotator(id=1, control=RotatorControl.SERIAL, model="Yaesu", comm_port="COM3",
                     address="127.0.0.1")
    manager = RotatorManager([serial], timing=Timing(restart_min=0.1, restart_max=0.4))
    assert manager.local_program is not None
    assert (manager.local_program.restart_min, manager.local_program.restart_max) == (0.1, 0.4)


def test_moas_server_takes_the_timing_test_hook_from_its_environment(
        capsys: pytest.CaptureFixture[str]) -> None:
    from moas_gui.cli import server
    from moas_gui.hw.rotators.base import TIMING_HOOK, rotator_timing_from_environment

    assert rotator_timing_from_environment({}) is None
    timing = rotator_timing_from_environment({TIMING_HOOK: "restart_min=0.1"})
    assert timing == Timing(restart_min=0.1)
    args = server._parser().parse_args(["--headless", "station.moas"])
    assert server._options(args).rotator_timing is None
    args.rotator_timing = timing
    assert server._options(args).rotator_timing == timing
    with pytest.raises(ValueError, match=f"^{TIMING_HOOK}: 'restart=0.1': 'restart' is not"):
        rotator_timing_from_environment({TIMING_HOOK: "restart=0.1"})


def test_moas_server_stops_at_a_timing_hook_it_cannot_take(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    from moas_gui.cli import server
    from moas_gui.hw.rotators.base import TIMING_HOOK

    monkeypatch.setenv(TIMING_HOOK, "restart_min=-1")
    assert server.main(["--headless", "--new-instance", "station.moas"]) == 2
    assert capsys.readouterr().err == (f"moas-server: {TIMING_HOOK}: 'restart_min=-1': a delay "
                                       "must be a positive number of seconds\n")
