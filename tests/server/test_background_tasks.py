"""``aio.BackgroundTasks``, the owner of tasks started for callers that cannot wait:
each task's error reaches the owner's ``failed``, :meth:`idle` waits for every task (those
started meanwhile too) and :meth:`close` cancels what still runs and returns only once it
has ended."""

from __future__ import annotations

import asyncio

import pytest

from moas_gui.aio import BackgroundTasks


class Failures:
    def __init__(self) -> None:
        self.seen: list[tuple[str, str]] = []

    def __call__(self, what: str, error: BaseException) -> None:
        self.seen.append((what, str(error)))


@pytest.mark.asyncio
async def test_an_error_reaches_the_owner_and_a_cancellation_does_not() -> None:
    failures = Failures()
    tasks = BackgroundTasks(failures)

    async def broken() -> None:
        raise RuntimeError("the rotator is gone")

    async def forever() -> None:
        await asyncio.Event().wait()

    tasks.spawn(broken(), "turning rotator 1")
    waiting = tasks.spawn(forever(), "stopping rotator 2")
    assert waiting.get_name() == "stopping rotator 2"
    while len(tasks) > 1:  # until broken() has ended
        await asyncio.sleep(0)
    assert failures.seen == [("turning rotator 1", "the rotator is gone")]
    await tasks.close()
    assert waiting.cancelled() and len(tasks) == 0
    assert failures.seen == [("turning rotator 1", "the rotator is gone")]


@pytest.mark.asyncio
async def test_idle_waits_for_tasks_started_while_it_waits() -> None:
    tasks = BackgroundTasks(Failures())
    done: list[str] = []

    async def second() -> None:
        await asyncio.sleep(0)
        done.append("second")

    async def first() -> None:
        await asyncio.sleep(0)
        tasks.spawn(second(), "second")
        done.append("first")

    tasks.spawn(first(), "first")
    await tasks.idle()
    assert done == ["first", "second"] and len(tasks) == 0


@pytest.mark.asyncio
async def test_close_returns_only_once_a_task_that_resists_one_cancel_has_ended() -> None:
    tasks = BackgroundTasks(Failures())
    ended = asyncio.Event()

    async def stubborn() -> None:
        try:
            await asyncio.Event().wait()
        except asyncio.CancelledError:
            await asyncio.sleep(0)  # tidying up takes a turn of its own
            ended.set()
            raise

    task = tasks.spawn(stubborn(), "stubborn")
    await asyncio.sleep(0)
    await tasks.close()
    assert ended.is_set() and task.done()
