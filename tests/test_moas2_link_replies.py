"""The switch link and answers that come late, or from a box that is not ours:
an emulated box on a real pseudo-terminal whose answer to one question is held
back past the link's answer timeout and sent in front of the next answer of the
same kind.  Nothing here waits for luck: a held answer is sent only when the
next question of its kind arrives, however slow the machine."""

from __future__ import annotations

import asyncio
import logging
from collections.abc import AsyncIterator, Callable
from dataclasses import replace
from pathlib import Path

import pytest
import pytest_asyncio
from helpers import until
from test_moas2_link import FAST, STATE_A, STATE_B, Served, make_link_to

from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.emulator.serve import PtyEndpoint, make_link, remove_link
from moas_gui.hw.moas2.link import LinkStatus, SwitchLink
from moas_gui.hw.moas2.messages import Pong, UnitIdReply
from moas_gui.hw.moas2.replies import encode_reply

pytestmark = pytest.mark.realtime

QUICK = replace(FAST, answer_timeout=0.5)
"""A held answer makes its asker time out: no need to wait long for that."""


class LateBox:
    """An emulated box on a pseudo-terminal that holds back its answer to the first
    ``question`` it hears (optionally replacing it by ``instead``) and sends it just
    before its answer to the next ``question``: an answer that arrives after its
    asker gave up, in front of the answer to a later question."""

    def __init__(self, link: Path, question: bytes, *, unit_id: int = 0,
                 instead: bytes | None = None) -> None:
        self.link = link
        self.question = question
        self.instead = instead
        self.box = EmulatedBox(EmulatorModel(unit_id=unit_id))
        self.endpoint = PtyEndpoint()
        self.received = bytearray()
        self.heard = 0
        self.held: bytes | None = None
        self._partial = b""
        self._current = b""
        self.endpoint.start(asyncio.get_running_loop(), self._heard)
        self.box.attach(self._said)
        make_link(self.endpoint.path, link)

    def _heard(self, data: bytes) -> None:
        self.received += data
        *commands, self._partial = (self._partial + data).split(b";")
        for command in commands:
            self._current = command + b";"
            self.box.receive(self._current)
            self._current = b""

    def _said(self, out: bytes) -> None:
        if self._current == self.question:
            self.heard += 1
            if self.heard == 1:
                self.held = self.instead if self.instead is not None else out
                return
            if self.held is not None:
                out, self.held = self.held + out, None
        self.endpoint.write(out)

    @property
    def relays(self) -> frozenset[int]:
        return self.box.view().relays

    def stop(self) -> None:
        remove_link(self.link, self.endpoint.path)
        self.box.close()
        self.endpoint.close()


@pytest_asyncio.fixture
async def late_units(tmp_path: Path) -> AsyncIterator[LateBox]:
    # Unit 2 on the port; the first unit-id question is answered late, and the late
    # answer says unit 1: it came from the box the port led to when it was asked.
    box = LateBox(tmp_path / "moas", b":;", unit_id=2,
                  instead=encode_reply(UnitIdReply("100", 1)))
    yield box
    box.stop()


@pytest.mark.asyncio
async def test_a_late_unit_id_of_another_box_does_not_confirm_this_one(
    late_units: LateBox, caplog: pytest.LogCaptureFixture
) -> None:
    link, _ = make_link_to(late_units, echo=1, timing=QUICK)  # type: ignore[arg-type]
    link.apply(STATE_A)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2")
    link.connect()
    try:
        # the first question goes unanswered; the second gets the late ":1001;"
        # and then its own ":1002;"; the third is answered at once
        await until(lambda: late_units.received.count(b":;") >= 3
                    or b"*0;" in late_units.received, what="three sessions")
        assert b"*0;" not in late_units.received, "a box with unit 2 was driven"
        await until(lambda: any(r.levelno == logging.ERROR for r in caplog.records))
        assert late_units.relays == frozenset()
        assert not link.ready
        errors = [r.getMessage() for r in caplog.records if r.levelno == logging.ERROR]
        assert "unit 2" in errors[0] and "Echo is 1" in errors[0]
    finally:
        await link.close()


@pytest.mark.asyncio
async def test_a_late_answer_goes_to_nobody_rather_than_to_the_next_asker(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    box = LateBox(tmp_path / "moas", b"|;")
    link, _ = make_link_to(box, timing=QUICK)  # type: ignore[arg-type]
    link.apply(STATE_A)
    caplog.set_level(logging.DEBUG, "moas_gui.hw.moas2.link")
    link.connect()
    try:
        await until(lambda: link.status is LinkStatus.OK)
        await until(lambda: box.relays == {1, 2, 8})
        assert await link.ask_relays() is None  # held back: the asker gives up
        link.apply(STATE_B)
        await until(lambda: box.relays == {5, 8})
        # the box now sends the late {1, 2, 8} and then {5, 8}: only the latter answers
        assert await link.ask_relays() == {5, 8}
        late = [r for r in caplog.records if "late answer" in r.getMessage()]
        assert late and all(r.levelno == logging.DEBUG for r in late)
        assert link.status is LinkStatus.OK
    finally:
        await link.close()
        box.stop()


@pytest.mark.asyncio
async def test_a_second_link_cannot_open_a_port_in_use(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    served = Served(tmp_path / "moas1")
    served.start()
    first, _ = make_link_to(served)
    second, statuses = make_link_to(served)
    first.apply(STATE_A)
    second.apply(STATE_B)
    caplog.set_level(logging.WARNING, "moas_gui.hw.moas2")
    first.connect()
    try:
        await until(lambda: first.status is LinkStatus.OK)
        await until(lambda: served.relays == {1, 2, 8})
        asked = served.received.count(b":;")
        second.connect()
        await until(lambda: statuses == [LinkStatus.UNRESPONSIVE])
        message = next(r.getMessage() for r in caplog.records if "cannot open" in r.getMessage())
        assert "moas1" in message and "lock" in message
        await asyncio.sleep(3 * FAST.retry_max)  # it keeps trying, and keeps failing
        assert served.received.count(b":;") == asked
        assert served.relays == {1, 2, 8}
    finally:
        await second.close()
        await first.close()
        served.stop()


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
    link = SwitchLink(1, "pipe", 1, timing=QUICK, transport=pipe)
    link.apply(STATE_A)
    link.connect()
    try:
        await until(lambda: len(pipe.sessions) == 2, what="a second session")
        await until(lambda: pipe.is_open and pipe.written.count(b":;") == 2)
        # the first session's answer, read before its port was closed, handed over now
        old_on_data, old_on_lost = pipe.sessions[0]
        old_on_data(encode_reply(UnitIdReply("100", 1)) + encode_reply(Pong(False)))
        await until(lambda: len(pipe.sessions) == 3 or b"*0;" in pipe.written,
                    what="a third session")
        assert b"*0;" not in pipe.written, "driven on the word of an ended session"
        old_on_lost("the first session's port went away")  # nothing to the third session
        # this session's own answers do confirm the box
        on_data, _ = pipe.sessions[-1]
        await until(lambda: pipe.written.count(b":;") == 3)
        on_data(encode_reply(UnitIdReply("100", 1)))
        await until(lambda: pipe.written.endswith(b"';"))
        on_data(encode_reply(Pong(False)))
        await until(lambda: b"*0;" in pipe.written)
        await until(lambda: link.ready)
    finally:
        await link.close()
