"""The switch link's timers on a fake clock: pings, the answer timeout, the
retries' back-off, with the real durations (a ping a second, three seconds of
silence, retries after 0.5 s, 1 s, 2 s ... 8 s), against an emulated box in the
test's process on the same clock.  Time moves only when the test moves it, so
nothing here waits for it; the pseudo-terminal and pyserial path, on the real
clock, is ``test_moas2_link.py``'s."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from dataclasses import replace

import pytest
from helpers import FakeClock, advance_until, until
from switch_support import Heard
from test_moas2_link import STATE_A, STATE_B

from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.errors import PortError
from moas_gui.hw.moas2.link import LinkStatus, SwitchLink
from moas_gui.hw.moas2.timing import REAL_TIMING

REAL = REAL_TIMING


class BoxPort:
    """An emulated box on the test's fake clock, reached in-process: what the link writes
    reaches the box at once, what the box says reaches the link in the next turn of the
    event loop, as bytes read from a port do.  A test can silence the box (it hears but
    says nothing), or put bytes of its own on the line."""

    description = "an in-process box"

    def __init__(self, clock: FakeClock, unit_id: int = 0) -> None:
        self.clock = clock
        self.box = EmulatedBox(EmulatorModel(unit_id=unit_id), clock=clock)
        self.box.attach(self._said)
        self.received = bytearray()
        self.silent = False
        self.opened: list[float] = []
        """When the link opened the port, on the fake clock."""
        self._to_link: Callable[[bytes], None] | None = None

    def open(self, on_data: Callable[[bytes], None], on_lost: Callable[[str], None]) -> None:
        loop = asyncio.get_running_loop()

        def to_link(data: bytes) -> None:
            loop.call_soon(on_data, data)

        self._to_link = to_link
        self.opened.append(self.clock.now())

    def write(self, data: bytes) -> None:
        if self._to_link is None:
            raise PortError("the in-process box is not open")
        self.received += data
        self.box.receive(data)

    def close(self) -> None:
        self._to_link = None

    def say(self, data: bytes) -> None:
        """Bytes on the line to the computer, whoever sends them."""
        if self._to_link is not None:
            self._to_link(data)

    def _said(self, data: bytes) -> None:
        if not self.silent:
            self.say(data)

    @property
    def relays(self) -> frozenset[int]:
        return self.box.view().relays


def link_to(port: BoxPort, clock: FakeClock, echo: int | None = None,
            **kw: object) -> tuple[SwitchLink, list[LinkStatus]]:
    statuses: list[LinkStatus] = []
    link = SwitchLink(1, "in-process", echo, listener=Heard(status=statuses.append),
                      transport=port, clock=clock, **kw)  # type: ignore[arg-type]
    return link, statuses


@pytest.mark.asyncio
async def test_pings_keep_the_link_ok() -> None:
    clock = FakeClock()
    port = BoxPort(clock)
    link, statuses = link_to(port, clock)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        pinged = port.received.count(b"';")
        await clock.advance(REAL.answer_timeout * 1.5)
        assert statuses == [LinkStatus.OK]
        assert port.received.count(b"';") - pinged == 4  # one a second
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_silence_is_unresponsive_after_the_answer_timeout_and_retries_double(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = FakeClock()
    port = BoxPort(clock)
    told: list[tuple[LinkStatus, float]] = []
    link = SwitchLink(1, "in-process", transport=port, clock=clock,
                      listener=Heard(status=lambda s: told.append((s, clock.now()))))
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        port.silent = True
        silent_from = clock.now()
        await clock.advance(REAL.answer_timeout)
        assert link.status is LinkStatus.OK, "not before the answer timeout"
        await advance_until(clock, lambda: len(port.opened) == 7, what="six attempts")
        assert [status for status, _ in told] == [LinkStatus.OK, LinkStatus.UNRESPONSIVE]
        gone = told[1][1]
        # judged at the first ping after the limit: within one ping interval of it
        assert REAL.answer_timeout < gone - silent_from <= REAL.answer_timeout + REAL.ping_interval
        # each attempt: the pause, then the unit id asked and unanswered for the answer timeout
        attempts = port.opened[1:]
        ends = [gone] + [start + REAL.answer_timeout for start in attempts[:-1]]
        pauses = [round(start - end, 6) for start, end in zip(attempts, ends, strict=True)]
        assert pauses == [0.5, 1.0, 2.0, 4.0, 8.0, 8.0]
        assert port.received.count(b":;") == 7
        warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
        assert len(warnings) == 1 and "stopped answering (nothing for 3.0 s)" in \
            warnings[0].getMessage()
        port.silent = False
        await advance_until(clock, lambda: link.status is LinkStatus.OK, limit=REAL.retry_max + 5)
        assert [status for status, _ in told][1:] == [LinkStatus.UNRESPONSIVE, LinkStatus.OK]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_box_that_stops_answering_is_unresponsive_and_reloaded_when_back() -> None:
    clock = FakeClock()
    port = BoxPort(clock)
    link, statuses = link_to(port, clock)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: port.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)  # checked, after the relays
        port.silent = True  # it hears but says nothing
        await advance_until(clock, lambda: link.status is LinkStatus.UNRESPONSIVE)
        link.apply(STATE_B)
        port.box.model.feed(b"*0;", port.box.now())  # and it lost power meanwhile
        port.silent = False
        await advance_until(clock, lambda: link.status is LinkStatus.OK)
        await advance_until(clock, lambda: port.relays == {5, 8})
        assert statuses == [LinkStatus.OK, LinkStatus.UNRESPONSIVE, LinkStatus.OK]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_garbage_from_the_box_is_skipped_and_logged_at_debug(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = FakeClock()
    port = BoxPort(clock)
    link, statuses = link_to(port, clock)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        port.say(b"\xff\x00garbage;=+-!9Z;<1")
        link.apply(STATE_A)
        await until(lambda: port.relays == {1, 2, 8})
        await clock.advance(REAL.answer_timeout * 2)
        assert statuses == [LinkStatus.OK]
        skipped = [r for r in caplog.records if "skipped" in r.message]
        assert skipped and all(r.levelno == logging.DEBUG for r in skipped)
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_stop_turns_every_relay_off_and_start_restores_the_latest() -> None:
    clock = FakeClock()
    port = BoxPort(clock)
    link, statuses = link_to(port, clock)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: port.relays == {1, 2, 8})
        # the relays are on before the link has checked the box: wait for that too
        await until(lambda: link.status is LinkStatus.OK)
        link.stop()
        assert link.status is LinkStatus.STOPPED
        await advance_until(clock, lambda: port.relays == frozenset())
        await advance_until(clock, lambda: not port.box.view().active)
        link.apply(replace(STATE_B, active=False))  # what the engine wants while stopped
        await clock.advance(REAL.answer_timeout * 1.5)  # pings answered "inactive" meanwhile
        assert port.relays == frozenset()
        assert link.status is LinkStatus.STOPPED, "an inactive box is what a stopped link wants"
        link.start()
        await advance_until(clock, lambda: port.relays == {5, 8})
        assert statuses == [LinkStatus.OK, LinkStatus.STOPPED, LinkStatus.OK]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_the_emulator_port_name_runs_the_box_on_the_links_clock() -> None:
    clock = FakeClock()
    link = SwitchLink(3, "emulator", echo=12, clock=clock)
    assert link.emulator is not None and link.emulator.clock is clock
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        pinged = link.bytes_written
        await clock.advance(REAL.answer_timeout * 2)
        assert link.status is LinkStatus.OK
        assert link.bytes_written - pinged == 6 * len(b"';")
    finally:
        await link.close()
