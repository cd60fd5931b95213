"""The fake clock the tests move by hand: sleepers wake in order, at once."""

from __future__ import annotations

import asyncio

import pytest

from moas_gui.clock import LOOP_CLOCK, FakeClock, timeout


@pytest.mark.asyncio
async def test_sleepers_wake_in_the_order_of_their_ends_and_see_that_time() -> None:
    clock = FakeClock(100.0)
    woke: list[tuple[str, float]] = []

    async def sleeper(name: str, seconds: float) -> None:
        await clock.sleep(seconds)
        woke.append((name, clock.now()))

    tasks = [asyncio.create_task(sleeper(n, s)) for n, s in [("c", 3), ("a", 1), ("b", 2)]]
    await asyncio.sleep(0)
    assert clock.sleepers == 3
    await clock.advance(2.5)
    assert woke == [("a", 101.0), ("b", 102.0)] and clock.now() == 102.5
    await clock.advance(10)
    assert woke[-1] == ("c", 103.0) and clock.now() == 112.5
    # a fake day passes without waiting (were it waited for, the test's timeout would end it)
    await clock.advance(86_400)
    assert clock.now() == 86_512.5
    await asyncio.gather(*tasks)


@pytest.mark.asyncio
async def test_a_loop_that_sleeps_runs_every_step_within_an_advance() -> None:
    clock = FakeClock()
    ticks: list[float] = []

    async def ticking() -> None:
        while True:
            await clock.sleep(0.2)
            ticks.append(round(clock.now(), 6))

    task = asyncio.create_task(ticking())
    await clock.advance(1.0)
    assert ticks == [0.2, 0.4, 0.6, 0.8, 1.0]
    task.cancel()


@pytest.mark.asyncio
async def test_the_loop_clock_is_the_event_loops() -> None:
    loop = asyncio.get_running_loop()
    before = loop.time()
    assert before <= LOOP_CLOCK.now() <= loop.time()
    began = loop.time()
    await LOOP_CLOCK.sleep(0.01)
    assert loop.time() - began >= 0.009


@pytest.mark.asyncio
async def test_a_timeout_on_the_fake_clock_ends_a_wait_when_its_time_has_come() -> None:
    clock = FakeClock()
    never = asyncio.get_running_loop().create_future()
    ended: list[float] = []

    async def waiting() -> None:
        try:
            async with timeout(clock, 3.0):
                await never
        except TimeoutError:
            ended.append(clock.now())

    task = asyncio.create_task(waiting())
    await clock.advance(2.9)
    assert ended == [] and not task.done()
    await clock.advance(0.2)
    assert ended == [3.0] and task.done()
    assert never.cancelled(), "the abandoned wait is called off, as asyncio.wait_for does"


@pytest.mark.asyncio
async def test_a_wait_done_in_time_is_not_cut_short_later() -> None:
    clock = FakeClock()
    answer = asyncio.get_running_loop().create_future()

    async def asking() -> object:
        async with timeout(clock, 1.0):
            result = await answer
        await clock.sleep(5.0)  # long after the limit: nothing cancels this
        return result

    task = asyncio.create_task(asking())
    await clock.advance(0.5)
    answer.set_result("pong")
    await clock.advance(10.0)
    assert task.result() == "pong"


@pytest.mark.asyncio
async def test_a_timeout_on_the_loop_clock_is_asyncios() -> None:
    loop = asyncio.get_running_loop()
    began = loop.time()
    with pytest.raises(TimeoutError):
        async with timeout(LOOP_CLOCK, 0.02):
            await asyncio.Event().wait()
    assert loop.time() - began >= 0.019
