"""The switch link and answers that come late, or from a box that is not ours:
an emulated box whose answer to one question is held back past the link's
answer timeout and sent in front of the next answer of the same kind (in the
test's process, on a fake clock); a port another link holds, and a port that
leads to another box (real pseudo-terminals, on the real clock).  Nothing here
waits for luck: a held answer is sent only when the next question of its kind
arrives, however slow the machine."""

from __future__ import annotations

import asyncio
import logging
import os
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from helpers import FakeClock, advance_until, until
from test_moas2_link import FAST, STATE_A, STATE_B, Served, make_link_to
from test_moas2_link_clock import BoxPort, link_to

from moas_gui.hw.moas2.link import LinkStatus, SwitchLink
from moas_gui.hw.moas2.messages import (
    BoxStatus,
    PolarityStatus,
    Pong,
    RelayStatus,
    TRState,
    UnitIdReply,
)
from moas_gui.hw.moas2.replies import encode_reply
from moas_gui.hw.moas2.timing import REAL_TIMING


class LateBox(BoxPort):
    """An emulated box that holds back its answer to the first ``question`` it hears
    (optionally replacing it by ``instead``) and sends it just before its answer to the
    next ``question``: an answer that arrives after its asker gave up, in front of the
    answer to a later question."""

    def __init__(self, clock: FakeClock, question: bytes, *, unit_id: int = 0,
                 instead: bytes | None = None, skip: int = 0) -> None:
        super().__init__(clock, unit_id)
        self.question = question
        self.skip = skip
        """Answers to ``question`` let through before the one held back."""
        self.instead = instead
        self.heard = 0
        self.held: bytes | None = None
        self._partial = b""
        self._current = b""

    def write(self, data: bytes) -> None:
        self.received += data
        *commands, self._partial = (self._partial + data).split(b";")
        for command in commands:
            self._current = command + b";"
            self.box.receive(self._current)
            self._current = b""

    def _said(self, out: bytes) -> None:
        if self._current == self.question:
            self.heard += 1
            if self.heard <= self.skip:
                self.say(out)
                return
            if self.heard == self.skip + 1:
                self.held = self.instead if self.instead is not None else out
                return
            if self.held is not None:
                out, self.held = self.held + out, None
        self.say(out)


@pytest.mark.asyncio
async def test_a_late_unit_id_of_another_box_does_not_confirm_this_one(
    caplog: pytest.LogCaptureFixture,
) -> None:
    # Unit 2 on the port; the first unit-id question is answered late, and the late
    # answer says unit 1: it came from the box the port led to when it was asked.
    clock = FakeClock()
    late_units = LateBox(clock, b":;", unit_id=2, instead=encode_reply(UnitIdReply("100", 1)))
    link, _ = link_to(late_units, clock, echo=1)
    link.apply(STATE_A)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        # the first question goes unanswered; the second gets the late ":1001;"
        # and then its own ":1002;"; the third is answered at once
        await advance_until(clock, lambda: late_units.received.count(b":;") >= 3
                            or b"*0;" in late_units.received, what="three sessions")
        assert b"*0;" not in late_units.received, "a box with unit 2 was driven"
        await advance_until(clock, lambda: any(r.levelno == logging.ERROR
                                               for r in caplog.records))
        assert late_units.relays == frozenset()
        assert not link.ready
        errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
        assert "unit 2" in errors[0] and "Echo is 1" in errors[0]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_late_answer_goes_to_nobody_rather_than_to_the_next_asker(
    caplog: pytest.LogCaptureFixture,
) -> None:
    clock = FakeClock()
    box = LateBox(clock, b"|;", skip=1)  # the first is the link's own, on connecting
    link, _ = link_to(box, clock)
    link.apply(STATE_A)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: box.relays == {1, 2, 8})
        asking = asyncio.create_task(link.ask_relays())
        await clock.advance(REAL_TIMING.answer_timeout)
        assert await asking is None  # held back: the asker gives up
        link.apply(STATE_B)
        await until(lambda: box.relays == {5, 8})
        # the box now sends the late {1, 2, 8} and then {5, 8}: only the latter answers
        assert await link.ask_relays() == {5, 8}
        late = [r for r in caplog.records if "late answer" in r.getMessage()]
        assert late and all(r.levelno == logging.DEBUG for r in late)
        assert link.status is LinkStatus.OK
    finally:
        await link.close()


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_a_second_link_cannot_open_a_port_in_use(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    served = Served(tmp_path / "moas1")
    served.start()
    first, _ = make_link_to(served)
    clock = FakeClock()  # the second link's retries: the port's lock is real
    second, statuses = make_link_to(served, clock=clock)
    first.apply(STATE_A)
    second.apply(STATE_B)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    first.connect()
    try:
        await until(lambda: first.status is LinkStatus.OK)
        await until(lambda: served.relays == {1, 2, 8})
        asked = served.received.count(b":;")
        second.connect()
        await until(lambda: statuses == [LinkStatus.UNRESPONSIVE])
        refused = [r for r in caplog.records if "cannot open" in r.getMessage()]
        message = refused[0].getMessage()
        assert "moas1" in message and "lock" in message and refused[0].levelno == logging.WARNING
        await clock.advance(3 * FAST.retry_max)  # it keeps trying, and keeps failing
        refused = [r for r in caplog.records if "cannot open" in r.getMessage()]
        assert len(refused) >= 4 and all(r.levelno == logging.DEBUG for r in refused[1:])
        assert served.received.count(b":;") == asked
        assert served.relays == {1, 2, 8}
    finally:
        await second.close()
        await first.close()
        served.stop()


@pytest.mark.realtime
@pytest.mark.asyncio
async def test_without_echo_a_box_with_another_unit_id_than_the_first_is_not_driven(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    ours = Served(tmp_path / "moas1", unit_id=3)
    ours.start()
    theirs = Served(tmp_path / "moas1", unit_id=5)
    link, _ = make_link_to(ours)  # no Echo in the configuration
    link.apply(STATE_A)
    caplog.set_level(logging.ERROR, "moas_gui.hw.moas2")
    link.connect()
    try:
        await until(lambda: ours.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)
        ours.stop()
        await until(lambda: link.status is LinkStatus.UNRESPONSIVE)
        theirs.start()  # the same port name now leads to another box (another unit)
        await until(lambda: theirs.received.count(b":;") >= 2 or b"*0;" in theirs.received,
                    what="two sessions")
        assert b"*0;" not in theirs.received
        assert theirs.relays == frozenset()
        errors = [r.getMessage() for r in caplog.records]
        assert len(errors) == 1, "the refusal is logged once, not at every retry"
        assert "unit 5" in errors[0] and "unit 3" in errors[0]
        theirs.stop()
        ours.start()  # the first box back on the port is driven again
        await until(lambda: ours.relays == {1, 2, 8})
        await until(lambda: link.status is LinkStatus.OK)
    finally:
        await link.close()
        ours.stop()



class Pipe:
    """A port whose two ends a test holds: it keeps every session's callbacks, so a
    test can deliver bytes the way a reader thread does that read them before the
    port was closed."""

    description = "a test pipe"

    def __init__(self) -> None:
        self.sessions: list[tuple[Callable[[bytes], None], Callable[[str], None]]] = []
        self.written = bytearray()
        self.is_open = False

    def open(self, on_data: Callable[[bytes], None], on_lost: Callable[[str], None]) -> None:
        self.sessions.append((on_data, on_lost))
        self.is_open = True

    def write(self, data: bytes) -> None:
        self.written += data

    def close(self) -> None:
        self.is_open = False


@pytest.mark.asyncio
async def test_bytes_of_an_ended_session_are_dropped() -> None:
    pipe = Pipe()
    clock = FakeClock()
    link = SwitchLink(1, "pipe", 1, transport=pipe, clock=clock)
    link.apply(STATE_A)
    link.connect()
    try:
        await advance_until(clock, lambda: len(pipe.sessions) == 2, what="a second session")
        await until(lambda: pipe.is_open and pipe.written.count(b":;") == 2)
        # the first session's answer, read before its port was closed, handed over now
        old_on_data, old_on_lost = pipe.sessions[0]
        old_on_data(encode_reply(UnitIdReply("100", 1)) + encode_reply(Pong(False)))
        await advance_until(clock, lambda: len(pipe.sessions) == 3 or b'"B;' in pipe.written,
                            what="a third session")
        assert b'"B;' not in pipe.written, "confirmed on the word of an ended session"
        old_on_lost("the first session's port went away")  # nothing to the third session
        # this session's own answers do confirm the box
        on_data, _ = pipe.sessions[-1]
        await until(lambda: pipe.written.count(b":;") == 3)
        on_data(encode_reply(UnitIdReply("100", 1)))
        await until(lambda: pipe.written.endswith(b"';"))
        on_data(encode_reply(Pong(False)))
        # confirmed: what does it hold?  An inactive box, every station receiving
        await until(lambda: pipe.written.endswith(b'|;'))
        on_data(encode_reply(Pong(False)) + encode_reply(BoxStatus(
            (TRState.RECEIVE,) * 6, (63,) * 6, (63,) * 6, (63,) * 6))
            + encode_reply(PolarityStatus(frozenset())) + encode_reply(RelayStatus(frozenset())))
        await until(lambda: b"*1;" in pipe.written)  # loaded as values and activated
        assert b"*0;" not in pipe.written
        on_data(encode_reply(Pong(True)))
        await until(lambda: link.ready)
    finally:
        await link.close()


class FlakyOpen(Pipe):
    """A port whose first opens fail in a way nobody foresaw (not a PortError)."""

    def __init__(self, failures: int) -> None:
        super().__init__()
        self.failures = failures

    def open(self, on_data: Callable[[bytes], None], on_lost: Callable[[str], None]) -> None:
        if self.failures:
            self.failures -= 1
            raise RuntimeError("a failure nobody foresaw")
        super().open(on_data, on_lost)


@pytest.mark.asyncio
async def test_an_unforeseen_failure_ends_the_session_not_the_link(
        caplog: pytest.LogCaptureFixture) -> None:
    # found by the keyed re-sync walk: an error of another kind than the port's own
    # (pyserial's termios.error on a port that just went away) used to end the link's
    # task for good, and the switch was never driven again
    pipe = FlakyOpen(failures=2)
    clock = FakeClock()
    link = SwitchLink(1, "pipe", 1, transport=pipe, clock=clock)
    link.connect()
    try:
        await advance_until(clock, lambda: len(pipe.sessions) == 1, what="a session after two")
        assert sum("the session failed; will retry" in r.getMessage()
                   for r in caplog.records) == 2
    finally:
        await link.close()


@pytest.mark.skipif(sys.platform == "win32", reason="termios is POSIX")
def test_a_termios_error_on_opening_is_a_port_error(monkeypatch: pytest.MonkeyPatch,
                                                    tmp_path: Path) -> None:
    import termios

    import serial  # type: ignore[import-untyped]

    from moas_gui.hw.moas2.errors import PortError
    from moas_gui.hw.moas2.transport import SerialTransport

    def flush_fails(self: object) -> None:
        raise termios.error(5, "Input/output error")

    master, slave = os.openpty()
    try:
        monkeypatch.setattr(serial.Serial, "reset_input_buffer", flush_fails)
        transport = SerialTransport(os.ttyname(slave))

        async def open_it() -> None:
            transport.open(lambda data: None, lambda reason: None)

        with pytest.raises(PortError, match="Input/output error"):
            asyncio.run(open_it())
    finally:
        os.close(master)
        os.close(slave)
