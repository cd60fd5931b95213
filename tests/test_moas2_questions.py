"""Which question a reply answers: in order, late answers dropped, a lost
question forgotten after its time."""

from __future__ import annotations

import asyncio

import pytest

from moas_gui.hw.moas2.errors import PortError
from moas_gui.hw.moas2.messages import Pong, RelayStatus, UnitIdReply
from moas_gui.hw.moas2.questions import Answer, Questions

RELAYS_A = RelayStatus(frozenset({1}))
RELAYS_B = RelayStatus(frozenset({2}))


@pytest.mark.asyncio
async def test_answers_go_to_the_oldest_question_of_their_kind() -> None:
    loop = asyncio.get_running_loop()
    questions = Questions()
    unit, first, second = (loop.create_future() for _ in range(3))
    questions.ask(UnitIdReply, unit, 10.0)
    questions.ask(RelayStatus, first, 10.0)
    questions.ask(RelayStatus, second, 10.0)
    assert questions.answer(RELAYS_A, 0.0) is Answer.ANSWERED
    assert questions.answer(RELAYS_B, 0.0) is Answer.ANSWERED
    assert (first.result(), second.result()) == (RELAYS_A, RELAYS_B)
    assert not unit.done()
    assert questions.answer(Pong(True), 0.0) is Answer.UNASKED
    assert len(questions) == 1


@pytest.mark.asyncio
async def test_the_answer_of_a_question_given_up_is_dropped_not_passed_on() -> None:
    loop = asyncio.get_running_loop()
    questions = Questions()
    given_up, waiting = loop.create_future(), loop.create_future()
    questions.ask(RelayStatus, given_up, 10.0)
    given_up.cancel()  # its asker timed out
    questions.ask(RelayStatus, waiting, 10.0)
    assert questions.answer(RELAYS_A, 5.0) is Answer.LATE
    assert not waiting.done()
    assert questions.answer(RELAYS_B, 5.0) is Answer.ANSWERED
    assert waiting.result() == RELAYS_B


@pytest.mark.asyncio
async def test_a_question_given_up_is_forgotten_after_its_time() -> None:
    loop = asyncio.get_running_loop()
    questions = Questions()
    lost, waiting = loop.create_future(), loop.create_future()
    questions.ask(RelayStatus, lost, 10.0)  # the box never heard it
    lost.cancel()
    questions.ask(RelayStatus, waiting, 20.0)
    assert questions.answer(RELAYS_B, 10.5) is Answer.ANSWERED
    assert waiting.result() == RELAYS_B


@pytest.mark.asyncio
async def test_a_question_still_awaited_is_never_forgotten() -> None:
    loop = asyncio.get_running_loop()
    questions = Questions()
    waiting = loop.create_future()
    questions.ask(RelayStatus, waiting, 1.0)
    assert questions.answer(RELAYS_A, 99.0) is Answer.ANSWERED


@pytest.mark.asyncio
async def test_the_end_of_a_session_fails_every_waiting_asker() -> None:
    loop = asyncio.get_running_loop()
    questions = Questions()
    waiting = loop.create_future()
    questions.ask(UnitIdReply, waiting, 10.0)
    questions.end(PortError("gone"))
    with pytest.raises(PortError):
        waiting.result()
    assert len(questions) == 0
    assert questions.answer(UnitIdReply("100", 1), 0.0) is Answer.UNASKED
