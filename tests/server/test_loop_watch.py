"""The server watches its own event loop: a callback that blocks the real loop of a
running :class:`ServerApp` writes one Warning line naming what blocked, the status's
largest lag grows, and a second block within the minute writes no second line."""

from __future__ import annotations

import asyncio
import logging
import time

import pytest
from helpers import EXAMPLES, until

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.hw.moas2.link import LinkTiming
from moas_gui.log_limit import LogLimiter
from moas_gui.loop_watch import LoopWatch

FAST = LinkTiming(ping_interval=0.2, answer_timeout=1.0, retry_first=0.1, retry_max=0.5)


def block_the_loop(seconds: float) -> None:
    """What no code on the loop may do: wait without yielding."""
    time.sleep(seconds)


def lag_lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records
            if r.name == "moas_gui.loop_watch" and r.levelno == logging.WARNING]


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_a_blocked_loop_is_logged_once_a_minute_and_its_lag_shown(
        caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="moas_gui.loop_watch")
    server = ServerApp(ServerOptions(bind="127.0.0.1", tcp_port=0, udp_port=0,
                                     udp_bind="127.0.0.1", start_rotator_program=False,
                                     switch_timing=FAST))
    try:
        assert (await server.open(EXAMPLES / "small-station.moas")).ok
        await until(lambda: server.loop_watch.turns >= 3, timeout=30,
                    what="the watch's timer running")
        before = server.status.loop_lag_ms
        assert lag_lines(caplog) == []
        loop = asyncio.get_running_loop()
        loop.call_soon(block_the_loop, 0.5)  # five times the Warning's threshold
        await until(lambda: server.status.loop_lag_ms > max(before, 100), timeout=30,
                    what="the status showing the lag")
        first = server.status.loop_lag_ms
        await until(lambda: lag_lines(caplog), timeout=30, what="the lag's log line")
        (line,) = lag_lines(caplog)
        assert "ms late" in line and "block_the_loop" in line, line
        assert f"the largest since start: {server.loop_watch.largest_ms} ms" in line
        assert "loop lag" in server.status.summary
        # another, longer, within the minute: the largest grows, the log stays quiet
        loop.call_soon(block_the_loop, 1.0)
        await until(lambda: server.status.loop_lag_ms > first, timeout=30,
                    what="the status showing the larger lag")
        assert len(lag_lines(caplog)) == 1
    finally:
        await server.close()
    assert not server.loop_watch.running


@pytest.mark.asyncio
async def test_a_stall_the_thread_could_not_see_says_so(
        caplog: pytest.LogCaptureFixture) -> None:
    # the watching thread looks only once the timer is a look (50 ms) overdue: a shorter
    # stall, logged here (a 20 ms timer, a 10 ms threshold, every line let through),
    # says it was not seen rather than name whatever runs next
    caplog.set_level(logging.WARNING, logger="moas_gui.loop_watch")
    watch = LoopWatch(every=0.02, log_over=0.005, limiter=LogLimiter(interval=0.0))
    watch.start()

    async def unseen_stall() -> bool:
        # a 30 ms block: 5-30 ms late, never 70 ms since the timer last ran -- unless
        # the machine is so busy that the timer itself is late: then try again
        turns = watch.turns
        asyncio.get_running_loop().call_soon(block_the_loop, 0.03)
        await until(lambda: watch.turns > turns + 1, timeout=30)
        return any("was not seen" in line for line in lag_lines(caplog))

    try:
        await until(lambda: watch.turns >= 2, timeout=30)
        for _ in range(10):
            if await unseen_stall():
                break
    finally:
        watch.stop()
    assert watch.largest >= 0.005
    assert any("was not seen" in line for line in lag_lines(caplog)), lag_lines(caplog)


@pytest.mark.realtime  # waits on the real clock: deadlines, keepalives, rates
@pytest.mark.asyncio
async def test_the_watching_thread_wakes_about_once_a_period_on_a_quiet_loop() -> None:
    # a quiet server pays for every wake of the thread (issue 41: the quiet band change):
    # it sleeps until the timer would be overdue, so about one wake a period of the timer;
    # polling every look (50 ms) would wake four times a 200 ms period
    watch = LoopWatch(every=0.2)
    watch.start()
    try:
        await until(lambda: watch.turns >= 10, timeout=60)
    finally:
        watch.stop()
    assert 0 < watch.wakes <= 2 * watch.turns, (watch.wakes, watch.turns)
