"""Generated stations for the property suite: random radios, antennas, systems and
functions, each a valid configuration."""

from __future__ import annotations

import random
from collections.abc import Sequence
from typing import Any

from engine_invariants import BANDS

from moas_gui.config.model import (
    AlternateRule,
    Antenna,
    Config,
    ControlRange,
    FrequencyRange,
    Function,
    Radio,
    RadioRef,
    StationRelays,
    Switch,
    SwitchPort,
    System,
)


def generated_station(rng: random.Random) -> Config:
    """A random station: 2-4 main radios (one switch, or two with every radio on both), a sub
    receiver, single- and multi-band antennas, TX-only and RX-only antennas, a shared
    beverage system, a stack with components, conflicts, fast pairs and inhibits."""
    n_radios = rng.randint(2, 4)
    two_switches = rng.random() < 0.3
    refs = [RadioRef(1 + i // 2, 1 + i % 2) for i in range(n_radios)]
    sub = 3 if rng.random() < 0.5 else None
    relay_refs = refs + ([RadioRef(1, sub)] if sub is not None else [])

    def relays(base: int) -> tuple[StationRelays, ...]:
        return tuple(StationRelays(station=r.station, radio=r.radio,
                                   relays=frozenset({(base + 7 * i) % 60}))
                     for i, r in enumerate(relay_refs))

    def control(bands: Sequence[tuple[float, float]], base: int) -> tuple[ControlRange, ...]:
        return tuple(ControlRange(FrequencyRange(lo, hi), relays(base)) for lo, hi in bands)

    antennas: list[Antenna] = []
    ident = 0
    for _ in range(rng.randint(3, 7)):
        bands = rng.sample(BANDS, rng.randint(1, 3))
        kind = rng.random()
        antennas.append(Antenna(
            id=ident, short_name=f"A{ident}", control=control(bands, ident),
            conflicts=(ident,), tx_only=kind < 0.1, no_select=0.1 <= kind < 0.15,
            shared_tx=kind > 0.7))
        ident += 1
    fast_all = tuple(range(ident + 10))
    # a stack: Top (s), Bot (s+1), Both (s+2) with components
    s = ident
    stack_band = [rng.choice(BANDS)]
    stack = (s, s + 1, s + 2)
    for k, name in enumerate(("Top", "Bot", "Both")):
        antennas.append(Antenna(id=s + k, short_name=name, control=control(stack_band, s + k),
                                conflicts=stack, fast=stack,
                                in_use=(s, s + 1) if name == "Both" else ()))
    ident += 3
    # shared beverages on one coax (low bands), RX only
    bev = (ident, ident + 1)
    for k in range(2):
        antennas.append(Antenna(id=ident + k, short_name=f"Bev{k}", rx_only=True,
                                control=control(BANDS[:2], ident + k), conflicts=bev,
                                fast=fast_all))
    ident += 2
    antennas = [a if a.fast else Antenna(**{**_fields(a), "fast": fast_all}) for a in antennas]
    systems = [System(id=1, additive_antennas=(s, s + 1), exclusive_antennas=(s + 2,)),
               System(id=2, shared_antennas=bev, shared=True)]
    a, b = refs[0], refs[1]
    functions = [
        Function(id=1, name="Share", int_params=(2,)),
        Function(id=2, name="Partner", int_params=(a.station, a.radio, b.station, b.radio)),
        Function(id=3, name="Extra", int_params=(a.station, a.radio, 50)),
        Function(id=4, name="Extra", int_params=(a.station, a.radio, b.station, b.radio, 51),
                 string_params=("Transfer",)),
        Function(id=5, name="Relay", int_params=(52, a.station, a.radio, 0, 1),
                 string_params=("S",)),
        Function(id=6, name="Relay", int_params=(53,)),
        Function(id=7, name="Inhibit", int_params=(b.station, b.radio, 1)),
        Function(id=8, name="AltActive", int_params=(b.station, b.radio, a.station, a.radio)),
        Function(id=9, name="RXTX"),
        Function(id=10, name="AntennaSwap", int_params=(a.station, a.radio, b.station, b.radio)),
    ]
    radios = []
    interlock = rng.random() < 0.6
    for i, ref in enumerate(refs):
        others = [o for o in refs if o != ref]
        always = tuple(o for o in others if rng.random() < 0.3
                       or interlock and {ref, o} == {refs[0], refs[1]})
        switches = (SwitchPort(1, i + 1),) + ((SwitchPort(2, i + 1),) if two_switches else ())
        radios.append(Radio(station=ref.station, radio=ref.radio, switches=switches,
                            always=always, out_of_band=True, inhibit_buss=(1,) if i == 2 else (),
                            sub_receiver=sub if i == 0 else None,
                            alternate=(AlternateRule(antenna=ident - 1),) if i == 1 else ()))
    switches = [Switch(1, "emulator", indicate_tr=True)] + (
        [Switch(2, "emulator", indicate_tr=True)] if two_switches else [])
    return Config(antennas=tuple(antennas), systems=tuple(systems), functions=tuple(functions),
                  radios=tuple(radios), switches=tuple(switches),
                  protect_same_band=rng.random() < 0.3)


def _fields(a: Antenna) -> dict[str, Any]:
    return {f: getattr(a, f) for f in a.__slots__}  # type: ignore[attr-defined]



__all__ = ["generated_station"]
