"""The program's driver against every controller emulator, over real pseudo-terminals,
on the bench's fake clock (tests/rotator_program/pty_bench.py): polls, quiet times, timeouts, retries
and turns take no real time, the bytes still go through the pseudo-terminals."""

from __future__ import annotations

import dataclasses
import functools
import logging
from collections.abc import Iterator
from pathlib import Path

import pytest
from pty_bench import PtyBench

from moas_gui.hw.rotators.controllers.base import OutOfRange
from moas_gui.hw.rotators.controllers.dcu1 import DCU1Codec
from moas_gui.hw.rotators.controllers.models import MODELS, find_model
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort
from moas_gui.rotator_program.driver import ControllerDriver
from moas_gui.rotator_program.serial_link import PortError, split_port
from moas_gui.testing.faulty_controller import FaultyController

SPEED = 200.0
TURN_SPEED = 100.0
"""For the turn that a stop must cut short: 1.7 s on the clock."""
START = 100.0


@pytest.fixture
def bench() -> Iterator[PtyBench]:
    with PtyBench() as running:
        yield running


def driver_on(bench: PtyBench, rotator: int, model: str, port: str, poll_ms: int,
              reports: Reports, **options: object) -> ControllerDriver:
    """A driver opening its port through the bench, on the bench's clock."""
    options.setdefault("opener", bench.open)
    return ControllerDriver(rotator, find_model(model), port, poll_ms, reports,
                            clock=bench.clock, **options)  # type: ignore[arg-type]


class Reports:
    """What a driver reported, in order."""

    def __init__(self) -> None:
        self.items: list[tuple[int, int]] = []

    def __call__(self, rotator: int, degrees: int) -> None:
        self.items.append((rotator, degrees))

    @property
    def last(self) -> int | None:
        return self.items[-1][1] if self.items else None


def emulator_state(host: EmulatorHost, port: ServedPort) -> tuple[float, bool]:
    return host.call(port, lambda e, now: (e.azimuth, e.busy))


DRIVEN = [m.name for m in MODELS if m.info.has_readback]


@pytest.mark.asyncio
@pytest.mark.parametrize("name", DRIVEN)
async def test_driver_reads_turns_and_stops_each_model(bench: PtyBench, name: str) -> None:
    model = find_model(name)
    host = bench.host
    served = bench.add(model.make_emulator(START, TURN_SPEED, bench.clock.now()))
    reports = Reports()
    driver = driver_on(bench, 3, name, served.path, 100, reports)
    driver.start()
    try:
        await bench.until(lambda: reports.last == START, what="the first heading")
        assert reports.items[0] == (3, 100)
        driver.rotate(130)
        await bench.until(lambda: reports.last == 130, what="the heading after the turn")
        assert len(reports.items) >= 2
        # A turn, then a stop before it is over.
        driver.rotate(300)
        await bench.until(lambda: emulator_state(host, served)[1], what="the turn to start")
        driver.stop()
        await bench.until(lambda: not emulator_state(host, served)[1], what="the stop")
        stopped = emulator_state(host, served)[0]
        assert abs(stopped - 300) > 1
        # The controller reads out its own resolution (RC2800: tenths, rounded as it
        # prints them), so the whole degree reported is within one of the true stop.
        await bench.until(lambda: reports.last is not None and abs(reports.last - stopped) < 1,
                          what=f"the heading where it stopped ({stopped:.2f})")
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_dcu1_heading_is_reported_when_the_turn_should_be_over(bench: PtyBench) -> None:
    served = bench.add(find_model("DCU1").make_emulator(START, 400.0, bench.clock.now()))
    reports = Reports()
    codec = DCU1Codec(speed=400.0, settle=0.1)
    driver = driver_on(bench, 1, "DCU1", served.path, 100, reports, codec=codec)
    driver.start()
    try:
        await bench.until(lambda: driver.connected)
        await bench.advance(0.2)
        assert reports.items == []  # a DCU-1 cannot tell where it is
        driver.rotate(150)
        await bench.until(lambda: reports.last == 150, what="the estimated heading")
        assert driver.estimated
        assert emulator_state(bench.host, served)[0] == pytest.approx(150.0)
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_a_vanished_port_is_logged_retried_and_used_again(
        bench: PtyBench, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.rotator_program")
    link = str(tmp_path / "ttyROT")
    served = bench.add(find_model("Yaesu").make_emulator(START, now=bench.clock.now()),
                       link=link)
    reports = Reports()
    driver = driver_on(bench, 2, "Yaesu", link, 100, reports, retry=0.1)
    driver.start()
    try:
        await bench.until(lambda: reports.last == 100)
        bench.host.remove(served)
        await bench.until(lambda: not driver.connected, what="the driver to notice")
        with pytest.raises(PortError, match="not open"):
            driver.rotate(10)
        lost = [r.getMessage() for r in caplog.records if "failed" in r.getMessage()]
        assert lost and lost[0].startswith(f"rotator 2 (Yaesu on {link}): port {link} failed")
        # The adapter comes back (same name), with the antenna somewhere else.
        bench.add(find_model("Yaesu").make_emulator(222.0, now=bench.clock.now()), link=link)
        await bench.until(lambda: reports.last == 222, what="the heading after reconnecting")
        assert any("port open again" in r.getMessage() for r in caplog.records)
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_a_port_that_does_not_exist_is_retried_quietly(
        bench: PtyBench, tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.DEBUG, logger="moas_gui.rotator_program")
    missing = str(tmp_path / "nothing")
    driver = driver_on(bench, 4, "RotorEZ", missing, 100, Reports(), retry=0.05)
    driver.start()
    try:
        await bench.until(lambda: sum("still cannot open" in r.getMessage()
                                      for r in caplog.records) >= 3)
        warnings = [r for r in caplog.records if r.levelno == logging.WARNING]
        assert len(warnings) == 1
        assert warnings[0].getMessage().startswith(
            f"rotator 4 (RotorEZ on {missing}): cannot open {missing}")
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_garbage_from_a_controller_is_logged_and_the_headings_still_come(
        bench: PtyBench, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.rotator_program")
    faulty = FaultyController(
        find_model("Prosistel D").make_emulator(START, SPEED, bench.clock.now()))
    faulty.noise = b"\xff\x00garbage"
    served = bench.add(faulty)
    reports = Reports()
    driver = driver_on(bench, 5, "Prosistel D", served.path, 100, reports)
    driver.start()
    try:
        await bench.until(lambda: reports.last == 100)
        driver.rotate(120)
        await bench.until(lambda: reports.last == 120)
        bad = [r.getMessage() for r in caplog.records if "ignored" in r.getMessage()]
        assert len(bad) == 1  # once per 5 s, however much comes
        assert bad[0].startswith(f"rotator 5 (Prosistel D on {served.path}): ignored 9 bytes")
        assert "garbage" in bad[0]
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_a_controller_that_stops_answering_is_reported_and_polled_on(
        bench: PtyBench, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger="moas_gui.rotator_program")
    faulty = FaultyController(find_model("RC2800P-X").make_emulator(START, now=bench.clock.now()))
    served = bench.add(faulty)
    reports = Reports()
    codec = find_model("RC2800P-X").codec()
    codec.info = dataclasses.replace(codec.info, reply_timeout=0.2)  # quicker than its 1 s
    driver = driver_on(bench, 6, "RC2800P-X", served.path, 100, reports, codec=codec)
    driver.start()
    try:
        await bench.until(lambda: reports.last == 100)
        faulty.silent = True
        await bench.until(lambda: not driver.answering, timeout=8.0,
                          what="the silence to be noticed")
        silent = [r.getMessage() for r in caplog.records if "not answering" in r.getMessage()]
        assert silent == [(f"rotator 6 (RC2800P-X on {served.path}): the controller is not "
                          "answering (3 questions without a reply); still trying")]
        heard = len(faulty.heard)
        faulty.silent = False
        await bench.until(lambda: driver.answering, timeout=4.0,
                          what="the controller to answer")
        assert len(faulty.heard) > heard  # it kept asking
        assert any("answers again" in r.getMessage() for r in caplog.records)
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_a_burst_of_turns_sends_only_the_last(bench: PtyBench) -> None:
    faulty = FaultyController(find_model("Yaesu").make_emulator(START, SPEED, bench.clock.now()))
    served = bench.add(faulty)
    reports = Reports()
    driver = driver_on(bench, 7, "Yaesu", served.path, 1000, reports)
    driver.start()
    try:
        await bench.until(lambda: reports.last == 100)
        for degrees in (110, 120, 130, 140):
            driver.rotate(degrees)
        await bench.until(lambda: b"M" in bytes(faulty.heard))
        await bench.advance(0.1)
        assert bytes(faulty.heard).count(b"M") == 1 and b"M140\r" in bytes(faulty.heard)
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_a_heading_out_of_the_model_range_is_refused_before_sending(
        bench: PtyBench) -> None:
    served = bench.add(find_model("RotorEZ").make_emulator(START, now=bench.clock.now()))
    driver = driver_on(bench, 8, "RotorEZ", served.path, 100, Reports())
    driver.start()
    try:
        await bench.until(lambda: driver.connected)
        with pytest.raises(OutOfRange, match="RotorEZ: heading 400 is outside 0..360"):
            driver.rotate(400)
    finally:
        await driver.close()


@pytest.mark.asyncio
async def test_the_reader_thread_works_where_the_loop_cannot_watch_the_port(
        bench: PtyBench) -> None:
    served = bench.add(find_model("GS-232A").make_emulator(START, SPEED, bench.clock.now()))
    reports = Reports()
    opener = functools.partial(bench.open, use_thread=True)
    driver = driver_on(bench, 9, "GS-232A", served.path + "@4800", 100, reports, opener=opener)
    driver.start()
    try:
        await bench.until(lambda: reports.last == 100)
        driver.rotate(111)
        await bench.until(lambda: reports.last == 111)
    finally:
        await driver.close()


def test_a_port_name_may_carry_its_speed() -> None:
    assert split_port("COM14@4800") == ("COM14", 4800)
    assert split_port("/dev/ttyUSB0") == ("/dev/ttyUSB0", None)
    assert split_port("socket://10.0.0.5:4001") == ("socket://10.0.0.5:4001", None)
    assert split_port("odd@name") == ("odd@name", None)
