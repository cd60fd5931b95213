"""A restart finds the box holding newer antennas than the saved state for more than one
station: the engine takes them all in one operation, and the box ends up holding the
engine's state (the model walk's seed 7, step 466).

The real engine (``examples/small-station.moas``: two radios of one station on switch
stations 1 and 2) behind a real switch link to the emulated box.  The saved state has
radio 1 on the All-band vertical at 1830 kHz and radio 2 on the 80 m dipole at 3700 kHz;
the box, driven on after the last save, holds the Tribander for radio 1 and the vertical
for radio 2, both stations keyed.  Taken one port at a time, the restart rule ran
between the two: radio 1, left on a Tribander that does not cover 1830 kHz, got the
vertical back (radio 2 had not taken it yet), then radio 2 took the vertical too; the
engine wanted both stations on one antenna, which the box refused.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import pytest
from helpers import until
from switch_support import Heard

from moas_gui.config import load_config
from moas_gui.engine import Engine
from moas_gui.engine.switchstate import SwitchState
from moas_gui.hw.moas2.emulator.box import EmulatedBox
from moas_gui.hw.moas2.emulator.model import EmulatorModel
from moas_gui.hw.moas2.link import LinkOptions, LinkTiming, SwitchLink
from moas_gui.hw.moas2.sync import initialise
from moas_gui.hw.moas2.transport import EmulatorTransport

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FAST = LinkTiming(ping_interval=0.05, answer_timeout=2.0, retry_first=0.05, retry_max=0.2)
TRIBANDER, DIPOLE_80, VERTICAL = 0, 2, 3
NONE3 = (63, 63, 63)


def small_station(radio1_khz: float, radio2_khz: float) -> Engine:
    engine = Engine(load_config(EXAMPLES / "small-station.moas").unwrap())
    engine.set_frequency(1, 1, radio1_khz)
    engine.set_frequency(1, 2, radio2_khz)
    return engine


def pairs(engine: Engine) -> tuple[tuple[int | None, int | None], ...]:
    return tuple((v.tx, v.rx) for v in (engine.radio_view(1, 1), engine.radio_view(1, 2)))


def loaded_relays(state: SwitchState) -> frozenset[int]:
    """The relays a box freshly loaded with ``state`` closes, no station keyed."""
    model = EmulatorModel()
    model.feed(initialise(state).encode(), 0.0)
    return frozenset(model.relays())


def test_the_engine_takes_every_port_a_switch_holds_anew_in_one_operation() -> None:
    engine = small_station(1830, 3700)
    assert pairs(engine) == ((VERTICAL, VERTICAL), (DIPOLE_80, DIPOLE_80))
    slot: dict[int, int] = {}
    for a in (TRIBANDER, VERTICAL):
        found = engine.slot_of(1, a, 1, 1, as_partner_alt=False)
        assert found is not None
        slot[a] = found
    changes = engine.keep_switch_antennas(1, {1: (slot[TRIBANDER], slot[TRIBANDER]),
                                              2: (slot[VERTICAL], slot[VERTICAL])})
    # radio 1's Tribander does not cover 1830 kHz, but the vertical it would go back
    # to is radio 2's now: nothing moves either radio off what the box holds
    assert pairs(engine) == ((TRIBANDER, TRIBANDER), (VERTICAL, VERTICAL))
    stations = engine.switch_states()[1].stations
    assert (stations[0].tx, stations[1].tx) == (slot[TRIBANDER], slot[VERTICAL])
    assert sum("kept the antennas switch 1 holds" in line for line in changes.log) == 2
    assert not any("freed it" in line for line in changes.log)


def test_a_radio_the_saved_state_has_on_an_antenna_the_box_holds_for_another_yields_it(
) -> None:
    # only port 2 is taken from the box (its vertical), while the saved state still has
    # radio 1 on the vertical: radio 1 loses it and is selected again (the 80 m dipole
    # radio 2 left, the nearest: nothing else covers 1830 kHz), so the engine never
    # wants both stations on the vertical
    engine = small_station(1830, 3700)
    vertical = engine.slot_of(1, VERTICAL, 1, 2, as_partner_alt=False)
    assert vertical is not None
    engine.keep_switch_antennas(1, {2: (vertical, vertical)})
    assert pairs(engine) == ((DIPOLE_80, DIPOLE_80), (VERTICAL, VERTICAL))
    assert engine.switch_states()[1].stations[1].tx == vertical
    assert engine.switch_states()[1].stations[0].tx != vertical


@pytest.mark.asyncio
async def test_a_restart_adopting_two_keyed_stations_leaves_the_box_holding_the_engines_state(
) -> None:
    saved = small_station(1830, 3700)  # the state file, older than what the box holds
    later = small_station(14200, 1830)  # what the box was driven to after the last save
    held, holds = saved.switch_states()[1], later.switch_states()[1]
    assert (holds.stations[0].tx, holds.stations[1].tx) == (TRIBANDER, VERTICAL)
    model = EmulatorModel()
    model.feed(initialise(holds).encode(), 0.0)
    model.set_tr(1, True, 0.0)
    model.set_tr(2, True, 0.0)
    box = EmulatedBox(model)
    engine = saved  # restored from the saved state
    adopted: list[dict[int, tuple[int, int, int]]] = []

    def adopt(ports: Mapping[int, tuple[int, int, int]], transmitting: frozenset[int]) -> None:
        assert transmitting == {1, 2}
        adopted.append(dict(ports))
        engine.keep_switch_antennas(1, {port: (s[0], s[1]) for port, s in ports.items()})

    link = SwitchLink(1, "emulator", transport=EmulatorTransport(box),
                      options=LinkOptions(timing=FAST, held=held, seen=[
                          (VERTICAL, VERTICAL, 63), (DIPOLE_80, DIPOLE_80, 63)] + [NONE3] * 4),
                      listener=Heard(adopt=adopt, wanted=lambda: engine.switch_states()[1]))
    link.apply(held)
    link.connect()
    try:
        await until(lambda: link.ready, what="the link ready")
        assert adopted == [{1: (TRIBANDER, TRIBANDER, 63), 2: (VERTICAL, VERTICAL, 63)}]
        assert pairs(engine) == ((TRIBANDER, TRIBANDER), (VERTICAL, VERTICAL))
        assert link.sent == engine.switch_states()[1]
        box.set_tr(1, False)
        box.set_tr(2, False)
        # the vertical's relays for radio 2 follow its (saved) 3700 kHz, once unkeyed
        wanted = loaded_relays(engine.switch_states()[1])
        await until(lambda: frozenset(model.relays()) == wanted,
                    what="the box holding the engine's state")
        assert await link.ask_relays() == wanted
        assert not link.errors
    finally:
        await link.close()
