"""The back-off every link shares: its pauses and its loop, without waiting."""

from __future__ import annotations

import asyncio
from itertools import islice

from moas_gui.client import Backoff as ClientBackoff
from moas_gui.hw.rotators.base import Timing
from moas_gui.retry import Backoff, keep_trying


def test_pauses_grow_by_the_factor_up_to_the_most() -> None:
    assert list(islice(Backoff(0.5, 2.0, 8.0).delays(), 7)) == [0.5, 1, 2, 4, 8, 8, 8]


def test_the_rotators_and_the_client_use_the_same_backoff() -> None:
    assert ClientBackoff is Backoff
    assert list(islice(Timing(reconnect_min=0.5, reconnect_max=3.0).reconnect.delays(), 4)) == \
        [0.5, 1.0, 2.0, 3.0]


def test_an_attempt_that_gets_through_starts_the_pauses_again() -> None:
    outcomes = iter([False, False, False, True, False, False])
    paused: list[float] = []

    async def attempt() -> bool:
        return next(outcomes)

    async def pause(seconds: float) -> None:
        paused.append(seconds)

    async def run() -> None:
        await keep_trying(attempt, Backoff(1.0, 2.0, 10.0), pause=pause,
                          stopped=lambda: len(paused) == 6)

    asyncio.run(run())
    assert paused == [1.0, 2.0, 4.0, 1.0, 2.0, 4.0]


def test_stopping_after_an_attempt_skips_the_pause() -> None:
    calls: list[str] = []

    async def attempt() -> bool:
        calls.append("attempt")
        return False

    async def pause(seconds: float) -> None:
        calls.append("pause")

    asyncio.run(keep_trying(attempt, Backoff(), pause=pause, stopped=lambda: bool(calls)))
    assert calls == ["attempt"]
