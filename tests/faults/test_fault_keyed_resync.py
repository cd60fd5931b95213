"""Safety across re-sync (issue 19): the server never resets the box, nor moves a
transmitting station's relays, on its own -- across a restart, a cable pulled and
plugged back, a stall, and a noisy line.  Against ``moas-emulator`` in its own process
on a pseudo-terminal, keyed through its control socket, checked on its own record of
every relay change and reset with each station's key state (see
:mod:`keyed_resync`).

The first four tests are the issue's reproductions, each with station 1 keyed; then a
fixed-seed share of the random walk of ``benchmarks/bench_resync_model.py``; then the
walk without faults (keys and band changes only), and the checker itself on a box's
record.

The reproductions' servers write their state every ``QUICK_SAVES`` (each waits for a
change to be saved before its fault); the random walk with faults keeps the real
second, as the benchmark's walk does, since how stale a restart finds the file is part
of what it explores."""

from __future__ import annotations

import asyncio
import contextlib
from pathlib import Path

import pytest
from fault_harness import FAULT_MARKS, QUICK_SAVES, SWITCH_TIMING, reference_relays
from helpers import until
from keyed_resync import STALL_S, STEPS, ModelRun, Rig, violations

from moas_gui.config import load_config
from moas_gui.engine import Engine
from moas_gui.hw.moas2.emulator.stepped import SteppedBox

pytestmark = [mark for mark in FAULT_MARKS if mark.name != "asyncio"]
"""The checker's own test is not a coroutine; the others each carry the asyncio mark."""

HOLD_21 = frozenset({0, 20})
"""Station 1's relays for radio 1 on 21.2 MHz (the tribander's 15 m relays)."""
HOLD_14 = frozenset({0, 19})
"""... and on 14.2 MHz."""

SOME_PINGS = 10 * SWITCH_TIMING.ping_interval


async def keyed_with_a_held_change(rig: Rig) -> None:
    """The issue's steps 1-3: radio 1 on 21.2 MHz (relays 0 and 20), station 1 keyed,
    radio 1 moved to 14.2 MHz: the box holds the change (wait mode), the server has
    saved it."""
    assert rig.box is not None
    rig.band(1, 21200.0)
    await rig.saved(1, 21200.0)
    await rig.holds_what_the_engine_says()
    assert rig.box.station_relays(1) == HOLD_21
    await rig.box.key(1, True)
    rig.band(1, 14200.0)
    await rig.saved(1, 14200.0)

    async def held() -> bool:
        assert rig.box is not None
        pending = (await rig.box.status())["stations"][0]["pending"]
        return "T0" in pending

    for _ in range(200):
        if await held():
            break
        await asyncio.sleep(0.05)
    assert await held(), "the box never got the change to hold"
    assert rig.box.station_relays(1) == HOLD_21
    assert await rig.check() == []


async def unkeyed_the_change_goes_through(rig: Rig) -> None:
    """Station 1 unkeyed: the held change is carried out and the box holds what the
    engine says; nothing broke the rule meanwhile."""
    assert rig.box is not None
    await rig.box.key(1, False)
    await rig.holds_what_the_engine_says()
    assert rig.box.station_relays(1) == HOLD_14
    assert await rig.check() == [], rig.server_log()


def keyed_rule_kept(found: list[str], rig: Rig) -> None:
    assert found == [], "\n".join(found) + "\n--- the server:\n" + rig.server_log()


@pytest.mark.asyncio
async def test_restart_with_a_change_held_under_a_keyed_station(tmp_path: Path) -> None:
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        await keyed_with_a_held_change(rig)
        await rig.restart()  # kill -9, and started again
        await rig.switch_ok()
        await asyncio.sleep(SOME_PINGS)
        keyed_rule_kept(await rig.check(), rig)
        await unkeyed_the_change_goes_through(rig)


@pytest.mark.asyncio
async def test_cable_replugged_under_a_keyed_station_with_a_held_change(
        tmp_path: Path) -> None:
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        await keyed_with_a_held_change(rig)
        assert rig.cable is not None and rig.client is not None
        told = len(rig.client.told)
        rig.cable.unplug()
        await until(lambda: rig.client is not None
                    and "unresponsive" in rig.client.switch_news(1, told),
                    what="the client told the switch is unresponsive")
        rig.cable.plug()
        await rig.switch_ok()
        await asyncio.sleep(SOME_PINGS)
        keyed_rule_kept(await rig.check(), rig)
        await unkeyed_the_change_goes_through(rig)


@pytest.mark.asyncio
async def test_server_stalled_under_a_keyed_station_with_a_held_change(
        tmp_path: Path) -> None:
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        await keyed_with_a_held_change(rig)
        rig.stall()  # SIGSTOP: a laptop suspended, a virtual machine paused
        await rig.resume()  # SIGCONT after longer than every link timeout
        await asyncio.sleep(STALL_S)
        await rig.switch_ok()
        await asyncio.sleep(SOME_PINGS)
        keyed_rule_kept(await rig.check(), rig)
        await unkeyed_the_change_goes_through(rig)


@pytest.mark.asyncio
async def test_noisy_line_under_a_keyed_station_with_nothing_held(tmp_path: Path) -> None:
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        assert rig.box is not None and rig.cable is not None and rig.client is not None
        rig.band(1, 21200.0)
        await rig.saved(1, 21200.0)
        await rig.holds_what_the_engine_says()
        await rig.box.key(1, True)  # nothing pending: the box holds what it was told
        told = len(rig.client.told)
        # the line goes quiet until the switch is unresponsive ...
        rig.cable.spoil("silence")
        await until(lambda: rig.client is not None
                    and "unresponsive" in rig.client.switch_news(1, told),
                    what="the client told the switch is unresponsive")
        # ... then loses only the box status replies while the link checks the box again
        asked = rig.cable.to_box.count(b'"B;')
        rig.cable.spoil("no box status")
        with contextlib.suppress(AssertionError):  # a link may check it another way
            await until(lambda: rig.cable is not None
                        and rig.cable.to_box.count(b'"B;') > asked,
                        timeout=5, what="the link asked the box status again")
        await asyncio.sleep(2 * SWITCH_TIMING.answer_timeout)
        rig.cable.spoil("")
        await rig.switch_ok()
        await asyncio.sleep(SOME_PINGS)
        keyed_rule_kept(await rig.check(), rig)
        assert rig.box.station_relays(1) == HOLD_21
        await rig.box.key(1, False)
        await rig.holds_what_the_engine_says()
        keyed_rule_kept(await rig.check(), rig)


@pytest.mark.asyncio
async def test_restart_finding_both_stations_keyed_on_antennas_newer_than_the_saved_state(
        tmp_path: Path) -> None:
    """A ``kill -9`` before the state was saved (the model walk's seed 7): the saved state
    has radio 1 on the vertical (1.83 MHz) and radio 2 on the 80 m dipole; the box
    holds the tribander for radio 1 and the vertical for radio 2, both keyed.  The new
    server adopts both stations together, so the box ends up holding its state."""
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        assert rig.box is not None
        rig.band(1, 1830.0)
        await rig.saved(1, 1830.0)
        rig.band(2, 3700.0)
        await rig.saved(2, 3700.0)
        await rig.holds_what_the_engine_says()
        rig.block_state(True)  # nothing newer reaches the state file
        engine = Engine(load_config(rig.station.config).unwrap())  # what the server does
        engine.set_frequency(1, 1, 1830.0)
        engine.set_frequency(1, 2, 3700.0)
        for radio, khz in ((1, 14200.0), (2, 1830.0)):  # the tribander, then the vertical
            rig.band(radio, khz)
            engine.set_frequency(1, radio, khz)
            newer = reference_relays(engine.switch_states()[1])
            await until(lambda newer=newer: rig.box is not None and rig.box.relays == newer,
                        what=f"the box holding radio {radio} on {khz} kHz")
        assert (engine.radio_view(1, 1).tx, engine.radio_view(1, 2).tx) == (0, 3)
        assert rig.box.station_relays(1) == HOLD_14
        assert rig.saved_khz(1) == 1830.0 and rig.saved_khz(2) == 3700.0
        await rig.box.key(1, True)
        await rig.box.key(2, True)
        rig.state_blocked = False  # the new server may write it (the killed one never did)
        await rig.restart()  # kill -9, and started again on the older state
        await rig.switch_ok()
        await asyncio.sleep(SOME_PINGS)
        keyed_rule_kept(await rig.check(), rig)
        assert rig.box.station_relays(1) == HOLD_14
        await rig.box.key(1, False)
        await rig.box.key(2, False)
        await rig.holds_what_the_engine_says()
        keyed_rule_kept(await rig.check(), rig)
        await rig.settle()
        keyed_rule_kept(await rig.check(), rig)


@pytest.mark.asyncio
async def test_random_keys_band_changes_and_faults_keep_the_rule(tmp_path: Path) -> None:
    """A fixed-seed share of the random walk (the benchmark runs 10,000 steps)."""
    async with Rig.up(tmp_path) as rig:
        run = ModelRun(rig, seed=15, pause=0.1)
        figures = await run.run(30)
        assert figures.steps == 30
        assert figures.faults > 0
        print(figures.report())
        assert figures.violations == [], figures.report() + "\n--- the server:\n" + \
            rig.server_log()


@pytest.mark.asyncio
async def test_keys_and_band_changes_without_faults_keep_the_rule(tmp_path: Path) -> None:
    """The walk with no fault at all: the rule holds and every held change is carried
    out (the checker finds nothing where there is nothing to find)."""
    async with Rig.up(tmp_path, QUICK_SAVES) as rig:
        kinds = {kind: weight for kind, weight in STEPS.items()
                 if kind in ("key", "band", "settle")}
        run = ModelRun(rig, seed=7, kinds=kinds, pause=0.05)
        figures = await run.run(40)
        assert figures.done["band"] > 5 and figures.done["key"] > 3
        assert figures.violations == [], figures.report()
        assert rig.box is not None
        assert rig.box.resets() == [], "no load resets the box, the first included"
        print(figures.report())


@pytest.mark.parametrize("mode", ["wait", "interrupt"])
def test_the_checker_finds_a_reset_and_a_move_under_a_key_and_allows_interrupt_mode(
        mode: str) -> None:
    box = SteppedBox(active=True)
    box.send("&1;!1B112;!2B234;" + ("/I1;" if mode == "interrupt" else ""))
    box.settle()
    box.key(1, True, at=1)
    box.send("!1B156;", at=2)  # held in wait mode; an interrupt in interrupt mode
    box.wait(100)
    box.send("*0;*1;", at=200)
    box.key(1, False, at=300)
    found = violations(list(box.model.record))
    resets = [v for v in found if "*0; reached the box while station 1 was keyed" in v]
    moved = [v.split(": ", 1)[1] for v in found if "relays moved" in v]
    assert len(resets) == 1 and len(found) == 2
    # the box's own interrupt (1 2 to 5 6) is allowed; the reset's opening is not
    before = "1 2" if mode == "wait" else "5 6"
    assert moved == [f"station 1 is keyed and its relays moved from {before} to none"]
