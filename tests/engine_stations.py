"""Generated stations for the property suite: random radios, antennas, systems and
functions, each a valid configuration."""

from __future__ import annotations

import random
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from engine_invariants import BANDS, FREQUENCIES, Op, operations

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

MULTIOP_SHARE = 0.4
"""The share of generated stations built by :func:`multiop_station`."""


def generated_station(rng: random.Random) -> Config:
    """A random station: 40 % of them a multi-operator station (:func:`multiop_station`),
    the others 2-4 main radios (one switch, or two with every radio on both), a sub
    receiver, single- and multi-band antennas, TX-only and RX-only antennas, a shared
    beverage system, a stack with components, conflicts, fast pairs and inhibits."""
    if rng.random() < MULTIOP_SHARE:
        return multiop_station(rng)
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


SUB_KINDS = ("own port", "riding with PersistSubReceiver", "riding without PersistSubReceiver")
"""The three kinds of sub receiver (6.10) whose partner alternates differ (issue 39)."""


def multiop_station(rng: random.Random, shared_alternates: bool = False,
                    partner_subs: bool = False) -> Config:
    """A random multi-operator station using what big stations rely on (5.8, 5.9, 5.12,
    5.13, 6.10): shared transmit antennas (some transmit-only) with a receive antenna per
    radio (some wired to the radio's RX-antenna input), the interlock 5.12 asks for
    (``Always`` both ways, an inhibit buss or ``SameBand`` both ways; now and then none,
    which the engine must then refuse), partners by ``Partner`` lists or by the Partner
    function, an antenna reached by two paths on two feeds, ``Alternate`` rules with and
    without ``AltActive`` (and the AltActive function; half of the rules' alternates a
    ``SharedTX`` antenna the interlocked radios transmit on), now and then every radio
    interlocked with every other (three or more on one antenna), and sub receivers with and
    without a port of their own, with ``UseMainFreq`` and ``PersistSubReceiver`` on the main radio's
    entry or on the sub receiver's.

    With ``shared_alternates`` every main radio has an ``Alternate`` rule for any radio
    transmitting on a ``SharedTX`` antenna, at any frequency, whose alternate is a ``SharedTX``
    antenna (none transmit-only), and the radios are interlocked (issue 29's stations).

    With ``partner_subs`` the first two radios are partners by ``Partner`` lists and
    interlocked, each with a sub receiver of one of the three kinds (:data:`SUB_KINDS`,
    chosen for each: a port of its own, riding on the main radio's port with or without
    ``PersistSubReceiver``; issue 39's stations)."""
    n = rng.randint(2, 4)
    mains = [RadioRef(1, i + 1) for i in range(n)]
    two_switches = rng.random() < 0.2
    sub_port = rng.random() < 0.5
    subs = {mains[0]: RadioRef(1, 5)}
    if rng.random() < 0.4 or partner_subs:
        subs[mains[1]] = RadioRef(1, 6)
    kinds = {sub: rng.choice(SUB_KINDS) for sub in subs.values()} if partner_subs else {}
    everyone = mains + list(subs.values())
    bands = rng.sample(BANDS, rng.randint(1, 3))

    def entries(base: int, rx_input: float = 0.0) -> tuple[StationRelays, ...]:
        return tuple(StationRelays(station=r.station, radio=r.radio,
                                   relays=frozenset({(base + 3 * i) % 60}),
                                   radio_rx_antenna=rng.random() < rx_input)
                     for i, r in enumerate(everyone))

    def control(ranges: Sequence[tuple[float, float]], base: int,
                rx_input: float = 0.0) -> tuple[ControlRange, ...]:
        return tuple(ControlRange(FrequencyRange(lo, hi), entries(base + k, rx_input))
                     for k, (lo, hi) in enumerate(ranges))

    antennas: list[Antenna] = []
    shared_tx = list(range(rng.randint(1, 2)))
    receive = list(range(len(shared_tx), len(shared_tx) + n))
    ordinary = list(range(receive[-1] + 1, receive[-1] + 1 + rng.randint(2, 3)))
    path_a, path_b = ordinary[-1] + 1, ordinary[-1] + 2
    fast_rx = tuple(receive) + (path_a, path_b)
    for a in shared_tx:
        antennas.append(Antenna(
            id=a, short_name=f"STX{a}", shared_tx=True,
            tx_only=rng.random() < 0.5 and not (shared_alternates or partner_subs),
            control=control(bands, 10 * a), conflicts=tuple(shared_tx),
            fast=fast_rx + tuple(shared_tx)))
    for k, a in enumerate(receive):
        antennas.append(Antenna(
            id=a, short_name=f"RX{k + 1}", rx_only=rng.random() < 0.7,
            control=control(bands, 10 * a, rx_input=0.3), conflicts=(a,),
            fast=tuple(shared_tx) + tuple(receive)))
    for a in ordinary:
        own = rng.sample(BANDS, rng.randint(1, 2))
        antennas.append(Antenna(
            id=a, short_name=f"A{a}", control=control(own, 10 * a), conflicts=(a,),
            fast=tuple(shared_tx) + tuple(receive) + (path_a, path_b),
            no_select=rng.random() < 0.1))
    # one antenna on two feeds (5.8): the first path shares a feed with the first ordinary
    # antenna, the second with the last one
    path_bands = rng.sample(BANDS, rng.randint(1, 2))
    for a, mate, other in ((path_a, ordinary[0], path_b), (path_b, ordinary[-1], path_a)):
        antennas.append(Antenna(
            id=a, short_name=f"P{a}", control=control(path_bands, 10 * a), conflicts=(a, mate),
            alternate=(other,), fast=tuple(shared_tx) + tuple(receive)))
    antennas = [ant if ant.id not in (ordinary[0], ordinary[-1]) else Antenna(**{
        **_fields(ant), "conflicts": ant.conflicts + ((path_a,) if ant.id == ordinary[0]
                                                      else (path_b,))}) for ant in antennas]
    a, b = mains[0], mains[1]
    interlock = rng.choice(("always", "always", "buss", "same_band", "none"))
    partner_by = rng.choice(("list", "function", "none"))
    flags_on_sub = rng.random() < 0.3
    alt_rule_radio = mains[rng.randrange(n)]
    everyone_locked = rng.random() < 0.4 or shared_alternates
    shared_alternate = rng.random() < 0.5 or shared_alternates
    if (shared_alternates or partner_subs) and interlock == "none":
        interlock = "always"
    if partner_subs:
        partner_by = "list"
    """The Alternate rule's antenna is a SharedTX antenna another radio may hold (issue 29)."""
    functions = [
        Function(id=1, name="AltActive", int_params=(alt_rule_radio.station, alt_rule_radio.radio,
                                                     a.station, a.radio)),
        Function(id=2, name="Inhibit", int_params=(b.station, b.radio, 1)),
        Function(id=3, name="RXTX"),
        Function(id=4, name="AntennaSwap", int_params=(a.station, a.radio, b.station, b.radio)),
    ]
    if partner_by == "function":
        functions.append(Function(id=5, name="Partner",
                                  int_params=(a.station, a.radio, b.station, b.radio)))
    radios = []
    next_port = n + 1
    for i, ref in enumerate(mains):
        pair = [o for o in (a, b) if o != ref] if ref in (a, b) else []
        # three or more radios on one shared antenna: now and then every radio interlocked
        third = [o for o in mains if o != ref and (everyone_locked or rng.random() < 0.25)]
        always = tuple(pair if interlock == "always" else []) + tuple(
            o for o in third if o not in pair)
        same_band = tuple(pair) if interlock == "same_band" else ()
        buss = (1,) if interlock == "buss" and ref in (a, b) or i == 2 and rng.random() < 0.5 \
            else ()
        partner = tuple(pair) if partner_by == "list" else ()
        sub = subs.get(ref)
        persist = sub is not None and rng.random() < 0.5
        if sub is not None and partner_subs:
            persist = kinds[sub] == SUB_KINDS[1] or kinds[sub] == SUB_KINDS[0] and persist
        main_freq = sub is not None and rng.random() < (0.8 if partner_subs else 0.5)
        rules: tuple[AlternateRule, ...] = ()
        if ref == alt_rule_radio or shared_alternates:
            lo, hi = rng.choice(bands)
            covering = receive + [ant.id for ant in antennas if ant.id in ordinary + [path_a]
                                  and any(c.range.contains(lo + 1) for c in ant.control)]
            rules = (AlternateRule(
                range=FrequencyRange(lo, hi) if rng.random() < 0.7 else FrequencyRange(),
                this_antennas=tuple(rng.sample(receive + shared_tx, rng.randint(0, 2))),
                other_antennas=tuple(rng.sample(shared_tx + ordinary, rng.randint(0, 2))),
                antenna=rng.choice(shared_tx if shared_alternate else covering)),)
            if shared_alternates:
                rules = (replace(rules[0], range=FrequencyRange(), this_antennas=(),
                                 other_antennas=tuple(shared_tx)),)
        alt_active = tuple(o for o in mains if o != ref and rng.random() < 0.5) \
            if rules and rng.random() < 0.5 else ()
        switches = (SwitchPort(1, i + 1),) + ((SwitchPort(2, i + 1),) if two_switches else ())
        radios.append(Radio(
            station=ref.station, radio=ref.radio, switches=switches, always=always,
            same_band=same_band, inhibit_buss=buss, partner=partner, out_of_band=True,
            sub_receiver=sub.radio if sub else None,
            persist_sub_receiver=persist and not flags_on_sub,
            use_main_freq=main_freq and not flags_on_sub, alternate=rules,
            alt_active=alt_active))
        if sub is not None:
            own: tuple[SwitchPort, ...] = ()
            if (kinds[sub] == SUB_KINDS[0] if partner_subs else sub_port) and next_port <= 6:
                own = (SwitchPort(1, next_port),)
                next_port += 1
            radios.append(Radio(station=sub.station, radio=sub.radio, switches=own,
                                persist_sub_receiver=persist and flags_on_sub,
                                use_main_freq=main_freq and flags_on_sub))
    switches = [Switch(1, "emulator", indicate_tr=True)] + (
        [Switch(2, "emulator", indicate_tr=True)] if two_switches else [])
    return Config(antennas=tuple(antennas), functions=tuple(functions), radios=tuple(radios),
                  switches=tuple(switches), protect_same_band=rng.random() < 0.2)


def frequencies_for(cfg: Config, only_configured: bool = False) -> tuple[float, ...]:
    """The property suite's frequencies plus, per configured range, its edges and a frequency
    inside it: so that random evenings put radios on one band often (where shared transmit
    antennas, partners and alternate rules matter).  With ``only_configured``, the latter
    alone."""
    extra = set()
    for ant in cfg.antennas:
        for cr in ant.control:
            lo, hi = cr.range.lower, cr.range.upper
            if lo is not None and hi is not None:
                extra.update((lo, hi, round(lo + (hi - lo) * 0.3, 1), round(lo + (hi - lo) * 0.6, 1)))
    return (() if only_configured else FREQUENCIES) + tuple(sorted(extra))


def partner_sub_evening(cfg: Config, rng: random.Random, count: int) -> list[Op]:
    """An evening on a station of issue 39 (``multiop_station(rng, partner_subs=True)``):
    frequencies in its configured ranges, and a quarter of the events presses that put the
    partners on a shared transmit antenna or a receive antenna and their sub receivers on a
    receive antenna, so that a sub receiver often listens where its main radio does."""
    shared = [a.id for a in cfg.antennas if a.shared_tx]
    receive = [a.id for a in cfg.antennas if a.short_name.startswith("RX")]
    partners = [r.ref for r in cfg.radios if r.partner]
    subs = [RadioRef(r.station, r.sub_receiver) for r in cfg.radios
            if r.partner and r.sub_receiver is not None]
    out: list[Op] = []
    for op in operations(cfg, rng, count, frequencies_for(cfg, only_configured=True)):
        if op == ("run", "stop"):
            continue  # the switches stay running (a stopped evening refuses every press)
        if rng.random() >= 0.4:
            out.append(op)
            continue
        who = rng.choice(partners + subs)
        if who in subs or rng.random() < 0.4:
            out.append(("select", (who.station, who.radio), rng.choice(receive), "rx", False))
        else:
            out.append(("select", (who.station, who.radio), rng.choice(shared),
                        rng.choice(("tx", "both")), False))
    return out


def features(cfg: Config) -> set[str]:
    """Which of the multi-operator features a configuration uses (for the benchmark)."""
    found: set[str] = set()
    subs = {RadioRef(r.station, r.sub_receiver): r for r in cfg.radios if r.sub_receiver}
    if any(a.shared_tx for a in cfg.antennas):
        found.add("SharedTX")
    if any(r.partner for r in cfg.radios):
        found.add("Partner list")
    if any(f.name == "Partner" for f in cfg.functions):
        found.add("Partner function")
    if any(a.alternate for a in cfg.antennas):
        found.add("alternate paths")
    if any(r.alternate for r in cfg.radios):
        found.add("Alternate rules")
    if any(r.alt_active for r in cfg.radios) or any(f.name == "AltActive"
                                                     for f in cfg.functions):
        found.add("AltActive")
    for r in cfg.radios:
        if r.ref in subs:
            found.add("sub receiver with port" if r.switches else "sub receiver without port")
            persist = r.persist_sub_receiver or subs[r.ref].persist_sub_receiver
            found.add(SUB_KINDS[0] if r.switches else SUB_KINDS[1] if persist else SUB_KINDS[2])
        if r.use_main_freq:
            found.add("UseMainFreq")
        if r.persist_sub_receiver:
            found.add("PersistSubReceiver")
    if any(s.radio_rx_antenna for a in cfg.antennas for c in a.control for s in c.stations):
        found.add("RadioRXAntenna")
    return found


def _fields(a: Antenna) -> dict[str, Any]:
    return {f: getattr(a, f) for f in a.__slots__}  # type: ignore[attr-defined]



__all__ = ["MULTIOP_SHARE", "SUB_KINDS", "features", "frequencies_for", "generated_station", "multiop_station",
           "partner_sub_evening"]
