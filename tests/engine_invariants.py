"""The manual's rules as checks on an engine's state, written from the configuration and the
public views alone, and random operator evenings to drive them (stations: ``engine_stations.py``).

Used by the property suite (``test_engine_rules_properties.py``) and by the benchmark-sized
property job (``benchmarks/bench_engine_properties.py``).
"""

from __future__ import annotations

import random
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from moas_gui.config.model import (
    Antenna,
    Config,
    Radio,
    RadioRef,
    RotatorControl,
)
from moas_gui.engine import Engine, EngineError
from moas_gui.engine.views import RadioView

BANDS = ((1800.0, 2000.0), (3500.0, 4000.0), (7000.0, 7300.0), (14000.0, 14350.0),
         (21000.0, 21450.0), (28000.0, 29700.0))
FREQUENCIES = (1799.5, 1801.0, 1830.0, 1999.0, 2000.0, 2001.0, 3500.0, 3550.0, 3999.0,
               4000.0, 5000.0, 7025.0, 7300.0, 13999.0, 14000.0, 14175.0, 14351.0, 21025.0,
               21300.0, 28500.0, 29700.0, 50100.0)

Op = tuple[Any, ...]


# -- the configuration, read independently of the engine -------------------------------------

@dataclass(frozen=True)
class Facts:
    """What the rules need from a configuration, computed without the engine's index."""

    cfg: Config
    ants: dict[int, Antenna]
    group: dict[int, frozenset[int]]
    """Antenna -> its alternate-path group (5.8)."""
    parts: dict[int, frozenset[frozenset[int]]]
    """Antenna -> its physical components, each named by its path group (InUse, 5.3)."""
    shared_capable: dict[int, int]
    """Antenna -> the shared-capable system it is a member of."""
    shared_members: dict[int, int]
    """Antenna -> the system in whose SharedAntennas it is listed."""
    receivers: frozenset[RadioRef]
    """Sub and alternate receivers (they only receive)."""
    family: dict[RadioRef, RadioRef]
    """Every radio -> its main radio."""
    subs: dict[RadioRef, RadioRef] = field(default_factory=dict)
    """Sub receiver -> its main radio (6.10 ``SubReceiver``)."""
    persist: frozenset[RadioRef] = frozenset()
    """Sub receivers with ``PersistSubReceiver`` (on the main radio's entry or their own)."""
    partner_lists: frozenset[frozenset[RadioRef]] = frozenset()
    """Pairs partnered by ``Partner`` lists."""
    partner_functions: tuple[tuple[int, frozenset[RadioRef]], ...] = ()
    """Partner functions and the pair each toggles."""
    memo: dict[tuple[Any, ...], Any] = field(default_factory=dict, compare=False, repr=False)
    """Answers already worked out (they depend on the configuration alone): the checks ask
    the same questions after every event of an evening."""

    @staticmethod
    def of(cfg: Config) -> Facts:
        ants = {a.id: a for a in cfg.antennas}
        group: dict[int, set[int]] = {a: {a} for a in ants}
        for a in ants.values():
            for b in a.alternate:
                if b in ants:
                    merged = group[a.id] | group[b]
                    for m in merged:
                        group[m] = merged
        frozen = {a: frozenset(g) for a, g in group.items()}
        parts = {a.id: frozenset(frozen[c] for c in (a.in_use or (a.id,)) if c in frozen)
                 for a in ants.values()}
        capable: dict[int, int] = {}
        shared_members: dict[int, int] = {}
        for s in cfg.systems:
            if s.shared_antennas:
                for a in (*s.shared_antennas, *s.exclusive_antennas, *s.additive_antennas):
                    capable[a] = s.id
                for a in s.shared_antennas:
                    shared_members[a] = s.id
        receivers: set[RadioRef] = set()
        family: dict[RadioRef, RadioRef] = {}
        for r in cfg.radios:
            family.setdefault(r.ref, r.ref)
            for n in (r.sub_receiver, r.alt_receiver):
                if n is not None:
                    receivers.add(RadioRef(r.station, n))
                    family[RadioRef(r.station, n)] = r.ref
        subs = {RadioRef(r.station, r.sub_receiver): r.ref for r in cfg.radios
                if r.sub_receiver is not None and r.sub_receiver != r.radio}
        persist = frozenset(sub for sub, main in subs.items()
                            if _radio(cfg, main).persist_sub_receiver
                            or (cfg.radio(sub.station, sub.radio) or Radio(0, 0))
                            .persist_sub_receiver)
        lists = frozenset(frozenset((r.ref, p)) for r in cfg.radios for p in r.partner
                          if p != r.ref)
        functions = tuple((f.id, frozenset((RadioRef(*f.int_params[:2]),
                                            RadioRef(*f.int_params[2:4]))))
                          for f in cfg.functions
                          if f.name == "Partner" and len(f.int_params) >= 4)
        return Facts(cfg, ants, frozen, parts, capable, shared_members, frozenset(receivers),
                     family, subs, persist, lists, functions)

    def conflict(self, a: int, b: int) -> bool:
        """Configured conflicts (either direction), or one physical antenna shared by the two
        selections (a component or an alternate path) that may not be used twice."""
        key = ("conflict", a, b)
        known = self.memo.get(key)
        if known is None:
            known = self.memo[key] = self._conflict(a, b)
        return bool(known)

    def conflicting(self, a: int) -> tuple[int, ...]:
        """The antennas (in the configuration's order) that :meth:`conflict` with ``a``."""
        key = ("conflicting", a)
        known = self.memo.get(key)
        if known is None:
            known = self.memo[key] = tuple(b for b in self.ants if self.conflict(a, b))
        return known  # type: ignore[no-any-return]

    def _conflict(self, a: int, b: int) -> bool:
        if b in self.ants[a].conflicts or a in self.ants[b].conflicts:
            return True
        for comp in self.parts[a] & self.parts[b]:
            if any(c in self.ants[c].conflicts for c in comp):
                return True
        return False

    def fast(self, a: int, b: int) -> bool:
        return b in self.ants[a].fast or a in self.ants[b].fast

    def covers(self, ref: RadioRef, antenna: int, khz: float | None) -> bool:
        key = ("covers", ref, antenna, khz)
        known = self.memo.get(key)
        if known is None:
            known = self.memo[key] = self._covers(ref, antenna, khz)
        return bool(known)

    def _covers(self, ref: RadioRef, antenna: int, khz: float | None) -> bool:
        ant = self.ants[antenna]
        for cr in ant.control:
            usable = any(s.applies_to(ref.station, ref.radio) for s in cr.stations)
            if usable and (khz is None and cr.range.lower is None and cr.range.upper is None
                           or khz is not None and cr.range.contains(khz)):
                return True
        return False

    def band(self, ref: RadioRef, khz: float) -> tuple[float, float] | None:
        """The narrowest run of contiguous ranges (gaps up to 1 kHz), among all antennas the
        radio can use, that holds ``khz`` (5.4: "it also checks contiguous frequency
        ranges")."""
        best: tuple[float, float] | None = None
        for ant in self.ants.values():
            ranges = sorted(
                (cr.range.lower if cr.range.lower is not None else float("-inf"),
                 cr.range.upper if cr.range.upper is not None else float("inf"))
                for cr in ant.control
                if any(s.applies_to(ref.station, ref.radio) for s in cr.stations))
            runs: list[list[float]] = []
            for lo, hi in ranges:
                if runs and lo <= runs[-1][1] + 1:
                    runs[-1][1] = max(runs[-1][1], hi)
                else:
                    runs.append([lo, hi])
            for lo, hi in runs:
                if lo <= khz <= hi and (best is None or hi - lo < best[1] - best[0]):
                    best = (lo, hi)
        return best

    def entry(self, ref: RadioRef, antenna: int, khz: float | None) -> Any:
        """The Stations entry (6.4.2) serving ``ref`` on ``antenna`` at ``khz``: the most
        specific one of the range holding ``khz`` (None when no range holds it)."""
        for cr in self.ants[antenna].control:
            if khz is None or not cr.range.contains(khz):
                continue
            best, score = None, -1
            for e in cr.stations:
                if e.applies_to(ref.station, ref.radio):
                    here = (e.station is not None) + (e.radio is not None)
                    if here > score:
                        best, score = e, here
            if best is not None:
                return best
        return None

    def rides_silent(self, sub: RadioRef) -> bool:
        """A sub receiver riding on its main radio's port (no ``Switches`` port of its own)
        without ``PersistSubReceiver``: its relays are dropped while the main radio transmits
        (6.10)."""
        return sub in self.subs and not self.switches_of(sub) and sub not in self.persist

    def partners_now(self, e: Engine) -> set[frozenset[RadioRef]]:
        """Pairs that are partners now: the ``Partner`` lists, each toggled by a Partner
        function naming the same pair (6.6.9)."""
        pairs = set(self.partner_lists)
        for fid, pair in self.partner_functions:
            if e.function_on(fid):
                pairs.add(pair)
            else:
                pairs.discard(pair)
        return pairs

    def switches_of(self, ref: RadioRef) -> dict[int, list[int]]:
        """Switch -> the radio's ports on it (one answer shared by every caller: read it,
        never change it)."""
        key = ("switches", ref)
        known = self.memo.get(key)
        if known is None:
            known = self.memo[key] = self._switches_of(ref)
        return known  # type: ignore[no-any-return]

    def _switches_of(self, ref: RadioRef) -> dict[int, list[int]]:
        r = self.cfg.radio(ref.station, ref.radio)
        only = self.cfg.switches[0].id if len(self.cfg.switches) == 1 else None
        out: dict[int, list[int]] = {}
        for sp in r.switches if r else ():
            w = sp.switch or only
            if w is not None:
                out.setdefault(w, []).append(sp.port)
        return out


# -- the checks ----------------------------------------------------------------------------

def _held(v: RadioView) -> list[tuple[str, int]]:
    out = []
    if v.tx is not None:
        out.append(("tx", v.tx))
    if v.rx is not None and v.rx != v.tx:
        out.append(("rx", v.rx))
    return out


def violations(e: Engine, facts: Facts, counts: Counter[str] | None = None) -> list[str]:
    """Every rule broken by the engine's state now (empty when all hold).  ``counts`` gets,
    per rule of :func:`multiop_violations`, how many checks actually ran."""
    problems = _basic_violations(e, facts)
    problems += multiop_violations(e, facts, Counter() if counts is None else counts)
    return problems


def _basic_violations(e: Engine, facts: Facts) -> list[str]:
    cfg = facts.cfg
    views = {RadioRef(v.station, v.radio): v for v in e.radios()}
    states = e.switch_states()
    problems: list[str] = []
    alt_receivers = {RadioRef(r.station, r.alt_receiver) for r in cfg.radios
                     if r.alt_receiver is not None}
    holders = [(ref, v) for ref, v in views.items() if ref not in alt_receivers]

    # No two radios hold the same or conflicting antennas (5.5, 5.8, 5.3), unless the manual
    # permits it (a shared member in shared mode, shared TX of interlocked radios).
    for i, (ra, va) in enumerate(holders):
        for rb, vb in holders[i + 1:]:
            if facts.family[ra] == facts.family[rb]:
                continue
            for _, a in _held(va):
                for _, b in _held(vb):
                    if facts.conflict(a, b) and not e.may_share(ra, a, rb, b):
                        problems.append(f"{ra} on {a} and {rb} on {b} conflict")

    # A shared system in shared mode has one member for all its users (5.10).
    for s in cfg.systems:
        if not s.shared_antennas or not e.system_shared(s.id):
            continue
        used = {(ref, a) for ref, v in holders for _, a in _held(v)
                if facts.shared_members.get(a) == s.id}
        members = {a for _, a in used}
        if len(members) > 1:
            problems.append(f"shared system {s.id} split between members {sorted(members)}: "
                            f"{sorted(used)}")

    for ref, v in views.items():
        main = ref not in facts.receivers
        # TXOnly never receives, RXOnly never transmits (1.1.11).
        if v.rx is not None and facts.ants[v.rx].tx_only:
            problems.append(f"{ref} receives on transmit-only {v.rx}")
        if v.tx is not None and facts.ants[v.tx].rx_only:
            problems.append(f"{ref} transmits on receive-only {v.tx}")
        if not main and v.tx is not None:
            problems.append(f"receiver {ref} has a transmit antenna {v.tx}")
        # Different TX and RX antennas are fast with each other (1.1.3, 5.6).
        if v.tx is not None and v.rx is not None and v.tx != v.rx and \
                not facts.fast(v.tx, v.rx):
            problems.append(f"{ref} transmits on {v.tx} and receives on {v.rx}, not fast")
        # A radio without an antenna covering its transmit frequency is inhibited (F 6, 7).
        if main and v.khz is not None and v.tx_khz is not None:
            covered = v.tx is not None and facts.covers(ref, v.tx, v.tx_khz)
            if not covered and not v.inhibited:
                problems.append(f"{ref} has no antenna covering {v.tx_khz} but is not inhibited")
            r = cfg.radio(ref.station, ref.radio)
            if not covered and r is not None and not (r.inhibit_only_on_transmit
                                                      and not v.transmitting):
                for w, ports in facts.switches_of(ref).items():
                    for p in ports:
                        if p not in states[w].inhibited:
                            problems.append(f"{ref} uncovered but switch {w} port {p} is not "
                                            "inhibited")

    # Always (and configured inhibit buss) inhibits apply while the other transmits (5.11),
    # through every switch that sees both radios; with no such switch nothing is claimed.
    busses_fixed = not any(f.name == "Inhibit" for f in cfg.functions)
    for t, vt in views.items():
        if not vt.transmitting or t in facts.receivers:
            continue
        tsw = facts.switches_of(t)
        for r in cfg.radios:
            ref = r.ref
            if ref == t or ref in facts.receivers:
                continue
            always = t in r.always or (busses_fixed and bool(
                set(r.inhibit_buss) & set(_radio(cfg, t).inhibit_buss)))
            rsw = facts.switches_of(ref)
            common = set(tsw) & set(rsw)
            if always and common:
                for w in common:
                    for tp in tsw[w]:
                        missing = [p for p in rsw[w] if p != tp
                                   and p not in states[w].inhibit_others[tp - 1]]
                        if missing:
                            problems.append(f"{ref} not inhibited on switch {w} while {t} "
                                            "transmits")
                if not views[ref].inhibited:
                    problems.append(f"{ref} view not inhibited while {t} transmits")
            if not common and f"while {t} transmits" in views[ref].note:
                problems.append(f"{ref} claims an inhibit by {t}, which no switch can apply")

    # A radio never listens on an antenna conflicting with the one another radio transmits
    # on (5.12, 5.13, 5.9): every switch seeing both moves it to its alternate (``@``), and
    # the alternate does not conflict either.
    for t, vt in views.items():
        if not vt.transmitting or vt.tx is None or t in facts.receivers:
            continue
        tsw = facts.switches_of(t)
        for ref, v in views.items():
            if ref in facts.receivers or facts.family[ref] == facts.family[t] or v.rx is None:
                continue
            if not facts.conflict(v.rx, vt.tx) or (
                    v.rx == vt.tx and facts.shared_members.get(v.rx) is not None
                    and e.system_shared(facts.shared_members[v.rx])):
                continue
            if v.alt is not None and facts.conflict(v.alt, vt.tx):
                problems.append(f"{ref}'s alternate {v.alt} conflicts with {vt.tx}, on which "
                                f"{t} transmits")
            for w, ports in facts.switches_of(ref).items():
                for tp in tsw.get(w, ()):
                    missing = [p for p in ports if p != tp
                               and p not in states[w].use_alternate[tp - 1]]
                    if missing:
                        problems.append(f"{ref} listens on {v.rx} on switch {w} while {t} "
                                        f"transmits on {vt.tx}")

    # The Relay and Extra functions' relays are held while on (6.6.6, 6.6.8).
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None
    for f in cfg.functions:
        p = f.int_params
        if f.name == "Relay" and p and e.function_on(f.id):
            owner = RadioRef(p[1], p[2]) if len(p) >= 3 else None
            w, local = p[0] // 100 + 1, p[0] % 100
            if w in states and not (owner in views and views[owner].transmitting) \
                    and local not in states[w].station0:
                problems.append(f"Relay function {f.id} is on but relay {p[0]} is off")
        if f.name == "Extra" and len(p) >= 3 and e.function_on(f.id) \
                and e.function_status(p[0], p[1], f.id)[0]:
            ref = RadioRef(p[0], p[1])
            if ref in views and not views[ref].transmitting:
                w, local = p[-1] // 100 + 1, p[-1] % 100
                for sw, ports in facts.switches_of(ref).items():
                    if sw == w or (only is not None and sw == only):
                        for port in ports:
                            if local not in states[sw].station(port).extra:
                                problems.append(f"Extra function {f.id} is on but relay "
                                                f"{p[-1]} is not among port {port}'s extras")

    # ProtectSameBand: two main radios are never connected on one band (1.1.16, F step 1).
    if cfg.protect_same_band:
        mains = [(ref, v) for ref, v in views.items() if ref not in facts.receivers
                 and v.khz is not None and (v.tx is not None or v.rx is not None)]
        for i, (ra, va) in enumerate(mains):
            for rb, vb in mains[i + 1:]:
                if _may_share_band(cfg, facts, ra, rb):
                    continue
                assert va.khz is not None and vb.khz is not None
                band = facts.band(ra, va.khz)
                other = facts.band(rb, vb.khz)
                if band is not None and band[0] <= vb.khz <= band[1] or \
                        other is not None and other[0] <= va.khz <= other[1]:
                    problems.append(f"{ra} at {va.khz} and {rb} at {vb.khz} on one band")

    # After any change no radio is left uncovered while a free covering antenna exists
    # (appendix F, last paragraph).
    for ref, v in views.items():
        if ref in alt_receivers or v.khz is None or v.note.endswith("already on this band"):
            continue
        main = ref not in facts.receivers
        mine = [a for a in ((v.tx, v.rx) if main else (v.rx,))]
        if all(a is not None and facts.covers(ref, a, v.khz) for a in mine):
            continue
        for a, ant in facts.ants.items():
            if not ant.enabled or ant.no_select or ant.tx_only or ant.rx_only \
                    or a in facts.shared_capable or not facts.covers(ref, a, v.khz):
                continue
            if main and v.transmitting:
                continue
            taken = any(facts.conflict(a, b) for other, vo in holders
                        if facts.family[other] != facts.family[ref] for _, b in _held(vo))
            if not taken:
                problems.append(f"{ref} at {v.khz} has {v.tx}/{v.rx} while {a} is free")
                break
    return problems


MULTIOP_RULES = ("one physical antenna", "alternate not held", "shared TX listener",
                 "sub receiver relays", "switch conflict table", "RadioRXAntenna",
                 "receiver off transmit antenna", "alternate slot table",
                 "shared alternate armed", "partner alternate beside sub",
                 "(riding sub, partner's antenna given)",
                 "(sub with its own port, alternate elsewhere)",
                 "(sub with PersistSubReceiver, alternate elsewhere)")
"""The rules :func:`multiop_violations` checks, by the name their counts go under."""


def multiop_violations(e: Engine, facts: Facts, counts: Counter[str]) -> list[str]:
    """The rules of shared transmit antennas, partners, alternate paths, alternate antennas
    and sub receivers, each written from the manual's text."""
    cfg = facts.cfg
    views = {RadioRef(v.station, v.radio): v for v in e.radios()}
    states = e.switch_states()
    alt_receivers = {RadioRef(r.station, r.alt_receiver) for r in cfg.radios
                     if r.alt_receiver is not None}
    holders = [(ref, v) for ref, v in views.items() if ref not in alt_receivers]
    problems: list[str] = []
    partners = facts.partners_now(e)

    # 5.8: "Since the two paths to the 15 meter antenna use different relays the MOAS server
    # considers them to be different antennas. The configuration file specifies that they are
    # alternates for each other"; 1.1.1: "The operator will not be able to select that antenna
    # unless it is configured to be shared."  Two paths are one antenna: never held by two
    # radios at once when it is used by one radio at a time (lists itself in Conflicts).
    for i, (ra, va) in enumerate(holders):
        for rb, vb in holders[i + 1:]:
            if facts.family[ra] == facts.family[rb]:
                continue
            for _, x in _held(va):
                for _, y in _held(vb):
                    g = facts.group[x]
                    if len(g) < 2 and len(facts.group[y]) < 2:
                        continue
                    counts["one physical antenna"] += 1
                    if g != facts.group[y]:
                        continue
                    exclusive = any(m in facts.ants[m].conflicts for m in g)
                    if exclusive and not e.may_share(ra, x, rb, y):
                        problems.append(f"{ra} on {x} and {rb} on {y}: two paths of one "
                                        "antenna (5.8)")

    # 5.9: "If the alternate antenna is not available it will select no antenna for the
    # receiving station."  An alternate is never an antenna another radio holds (or one
    # conflicting with it), except the partner's receive antenna, which 5.13 gives: "the
    # radio will instead be connected to the partner's receive antenna".
    for ref, v in holders:
        if v.alt is None or ref in facts.receivers:
            continue
        counts["alternate not held"] += 1
        for other, vo in holders:
            if facts.family[other] == facts.family[ref]:
                continue
            for role, b in _held(vo):
                if not facts.conflict(v.alt, b) or e.may_share(ref, v.alt, other, b):
                    continue
                if frozenset((ref, other)) in partners and role == "rx" and b == v.alt:
                    continue
                main = facts.subs.get(other)
                if main is not None and frozenset((ref, main)) in partners \
                        and facts.rides_silent(other) and views[main].rx == v.alt:
                    continue  # silent while the partner transmits (issue 39's rule below)
                problems.append(f"{ref}'s alternate {v.alt} is {b}, held by {other} (5.9)")

    # 5.13: "Normally if a radio is receiving on a transmit antenna it will be disconnected
    # when another radio transmits on it. If the stations are partners and certain conditions
    # are met the radio will instead be connected to the partner's receive antenna": "There
    # are two stations using the shared transmit antenna. This is not available if more than
    # two radios are using the antenna"; "The other partner has an antenna which can be used.
    # It must be able to be connected to the partner and it must be fast."  (1.1.14: "It can
    # also be configured so that the operator can select an alternate antenna": the
    # alternate receiver's antenna.)
    for ref, v in holders:
        if ref in facts.receivers or v.rx is None:
            continue
        triggers = [(t, vt) for t, vt in holders
                    if vt.transmitting and vt.tx is not None
                    and facts.family[t] != facts.family[ref] and t not in facts.receivers
                    and facts.conflict(v.rx, vt.tx)
                    and e.may_share(ref, v.rx, t, vt.tx)
                    and (facts.ants[v.rx].shared_tx or facts.ants[vt.tx].shared_tx)]
        if not triggers:
            continue
        counts["shared TX listener"] += 1
        r = _radio(cfg, ref)
        manual = views[RadioRef(ref.station, r.alt_receiver)].rx \
            if r.alt_receiver is not None else None
        for t, vt in triggers:
            assert vt.tx is not None
            group = facts.group[vt.tx]
            users = sum(1 for o, vo in holders if o not in facts.receivers
                        and any(a in group for _, a in _held(vo)))
            # "can be used": nobody but the partner holds it (a sub receiver of the partner
            # still listening on it while the partner transmits makes it unavailable, 5.9)
            free = _partner_rx_free(e, facts, holders, ref, t, vt)
            conditions = (frozenset((ref, t)) in partners and users == 2 and free
                          and vt.rx is not None and vt.rx != vt.tx
                          and not facts.conflict(vt.rx, vt.tx)
                          and not facts.ants[vt.rx].tx_only and facts.ants[vt.rx].enabled
                          and facts.covers(ref, vt.rx, v.khz)
                          and (v.tx is None or v.tx == vt.rx or facts.fast(v.tx, vt.rx)))
            if v.alt is not None and v.alt != manual and not (conditions and v.alt == vt.rx):
                problems.append(f"{ref} listens on {v.rx} while {t} transmits on {vt.tx}; its "
                                f"alternate is {v.alt}, not none or the partner's receive "
                                "antenna (5.13)")
            # the switch has one alternate per port: every radio holding a transmit antenna
            # this one's receive antenna conflicts with would switch it (transmitting now or
            # not), so 5.13 decides alone only when the partner is the one such radio
            holding = [o for o, vo in holders
                       if facts.family[o] != facts.family[ref] and o not in facts.receivers
                       and vo.tx is not None and facts.conflict(v.rx, vo.tx)
                       and e.may_share(ref, v.rx, o, vo.tx)]
            if conditions and holding == [t] and v.alt != vt.rx:
                problems.append(f"{ref} and its partner {t} meet 5.13's conditions, but its "
                                f"alternate is {v.alt}, not {vt.rx}")

    # 6.10: "PersistSubReceiver ... True if the sub receiver relays should remain set during
    # transmit"; 1.1.12: "A sub receiver can be configured as an additional radio" (one that
    # receives: it never transmits).
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None
    for sub, main in facts.subs.items():
        v = views.get(sub)
        if v is None:
            continue
        counts["sub receiver relays"] += 1
        persist = sub in facts.persist
        if v.tx is not None:
            problems.append(f"sub receiver {sub} transmits on {v.tx}")
        own = facts.switches_of(sub)
        for w, ports in own.items():
            for p in ports:
                port = states[w].station(p)
                if v.rx is None:
                    if port.rx != 63 or port.tx != 63:
                        problems.append(f"sub receiver {sub} has no antenna but port {p} holds "
                                        f"{port.tx}/{port.rx}")
                    continue
                if port.rx == 63:
                    problems.append(f"sub receiver {sub} listens on {v.rx} but port {p} holds "
                                    "nothing")
                if persist and (port.tx != port.rx or port.tx_relays != port.rx_relays):
                    problems.append(f"sub receiver {sub} with PersistSubReceiver: port {p} "
                                    f"transmit {port.tx} {sorted(port.tx_relays)} differs from "
                                    f"receive {port.rx} {sorted(port.rx_relays)}")
                if not persist and (port.tx != 63 or port.tx_relays):
                    problems.append(f"sub receiver {sub}: port {p} transmits on {port.tx}")
        if own or v.rx is None:
            continue
        entry = facts.entry(sub, v.rx, v.khz)
        if entry is None:
            continue
        relays = entry.rx_relays if entry.rx_relays is not None else entry.relays
        for w, ports in facts.switches_of(main).items():
            mine = {x % 100 for x in relays if x // 100 + 1 == w or only == w and x < 100}
            for p in ports:
                port = states[w].station(p)
                if not mine <= port.rx_relays:
                    problems.append(f"sub receiver {sub} listens on {v.rx} but {main}'s port "
                                    f"{p} lacks relays {sorted(mine - port.rx_relays)}")
                if persist and port.tx != 63 and not mine <= port.tx_relays:
                    problems.append(f"sub receiver {sub} with PersistSubReceiver: {main}'s "
                                    f"port {p} drops relays {sorted(mine - port.tx_relays)} "
                                    "during transmit")

    problems += _partner_alternate_beside_sub(e, facts, views, states, partners, counts)

    # The switch is a safety layer (1.1.4: "the operator will not be able to select them";
    # 1.1.2 hot switch protection happens in the box): the table it is sent forbids, per
    # slot, every conflict the engine relies on.  For every antenna a radio holds, the slot
    # another radio on that switch would take a conflicting antenna through conflicts with
    # it, unless the two may share them now.  (A sub receiver without a port of its own
    # rides on its main radio's port: the box sees that port only, so the main radio's
    # pairs are the ones it can enforce.)
    shares: dict[tuple[RadioRef, int, RadioRef, int], bool] = {}  # the same on every switch
    for w, state in states.items():
        on_w = [(ref, v) for ref, v in holders if w in facts.switches_of(ref)]
        for ra, va in on_w:
            for _, x in _held(va):
                sa = e.slot_of(w, x, ra.station, ra.radio, as_partner_alt=False)
                if sa is None:
                    continue
                for rb, _vb in on_w:
                    if facts.family[rb] == facts.family[ra]:
                        continue
                    for y in facts.conflicting(x):
                        sb = e.slot_of(w, y, rb.station, rb.radio, as_partner_alt=False)
                        if sb is None:
                            continue
                        shared = shares.get((ra, x, rb, y))
                        if shared is None:
                            shared = shares[ra, x, rb, y] = e.may_share(ra, x, rb, y)
                        if shared:
                            continue
                        counts["switch conflict table"] += 1
                        if (min(sa, sb), max(sa, sb)) not in state.conflicts:
                            problems.append(f"switch {w}: {ra} holds {x} (slot {sa}); the table "
                                            f"would let {rb} take conflicting {y} (slot {sb})")

    problems += _receivers_off_transmit_antennas(e, facts, holders, states, counts)

    # 6.4: "The radio RX antenna is designed to handle switching of receive antennas that are
    # connected to the radio's RX antenna. The information is passed to the client".
    for ref, v in views.items():
        if v.rx is None or v.khz is None or ref in alt_receivers:
            continue
        entry = facts.entry(ref, v.rx, v.khz)
        if entry is None:
            continue
        counts["RadioRXAntenna"] += 1
        if v.radio_rx_antenna != entry.radio_rx_antenna:
            problems.append(f"{ref} on {v.rx} at {v.khz}: radio_rx_antenna is "
                            f"{v.radio_rx_antenna}, the configuration says "
                            f"{entry.radio_rx_antenna}")
    return problems


def _partner_rx_free(e: Engine, facts: Facts, holders: list[tuple[RadioRef, RadioView]],
                     ref: RadioRef, t: RadioRef, vt: RadioView) -> bool:
    """5.13's "The other partner has an antenna which can be used": nobody but the partner
    ``t`` holds its receive antenna (or a conflicting one), save ``t``'s sub receiver when it
    rides on ``t``'s port without ``PersistSubReceiver`` (6.10: its relays drop while ``t``
    transmits, which is when ``ref`` listens there)."""
    rx = vt.rx
    return rx is not None and not any(
        facts.conflict(rx, b) and not e.may_share(ref, rx, o, b)
        for o, vo in holders if o != t and facts.family[o] != facts.family[ref]
        and not (facts.subs.get(o) == t and facts.rides_silent(o))
        for _, b in _held(vo))


def _partner_alternate_beside_sub(e: Engine, facts: Facts, views: dict[RadioRef, RadioView],
                                  states: dict[int, Any], partners: set[frozenset[RadioRef]],
                                  counts: Counter[str]) -> list[str]:
    """Issue 39, after every event, for a radio whose partner's sub receiver listens on (or
    next to) the partner's receive antenna while the partner holds a transmit antenna the
    radio's receive antenna conflicts with (5.13):

    * a sub receiver with a port of its own or ``PersistSubReceiver`` keeps listening while
      the partner transmits (6.10: "True if the sub receiver relays should remain set during
      transmit"): the antenna is in use (1.1.4), so the alternate is not on it (5.9);
    * one riding on the partner's port without it is silent exactly then: when 5.13's other
      conditions hold and the partner is the only radio that would switch this one, the
      alternate is the partner's receive antenna ("The other partner has an antenna which
      can be used"), and on every switch the box switches it in only while one of the
      partner's ports transmits, a port whose transmit relays leave out the sub receiver's.
    """
    problems: list[str] = []
    only = facts.cfg.switches[0].id if len(facts.cfg.switches) == 1 else None
    for sub, t in facts.subs.items():
        vs, vt = views.get(sub), views.get(t)
        if vs is None or vt is None or vs.rx is None or vt.rx is None or vt.tx is None:
            continue
        for ref, v in views.items():
            if frozenset((ref, t)) not in partners or ref in facts.receivers or v.rx is None \
                    or not facts.conflict(vs.rx, vt.rx):
                continue
            triggers = [o for o, vo in views.items()
                        if o not in facts.receivers and facts.family[o] != facts.family[ref]
                        and vo.tx is not None and facts.conflict(v.rx, vo.tx)
                        and e.may_share(ref, v.rx, o, vo.tx)]
            if t not in triggers:
                continue
            counts["partner alternate beside sub"] += 1
            if not facts.rides_silent(sub):
                why = "its own port" if facts.switches_of(sub) else "PersistSubReceiver"
                counts[f"(sub with {why}, alternate elsewhere)"] += 1
                if v.alt is not None and facts.conflict(v.alt, vs.rx) \
                        and not e.may_share(ref, v.alt, sub, vs.rx):
                    problems.append(f"{ref}'s alternate {v.alt} is where {t}'s sub receiver "
                                    f"{sub} listens ({vs.rx}), which keeps listening while {t} "
                                    f"transmits ({why}; 5.9, 1.1.4)")
                continue
            if v.alt is not None and v.alt == vt.rx:
                counts["(riding sub, partner's antenna given)"] += 1
            if _conditions_513(e, facts, views, ref, v, t, vt) and triggers == [t] \
                    and v.alt != vt.rx:
                problems.append(f"{ref} and its partner {t} meet 5.13's conditions beside {t}'s "
                                f"sub receiver {sub}, riding on its port without "
                                f"PersistSubReceiver, but the alternate is {v.alt}, not {vt.rx}")
            if v.alt is None or not facts.conflict(v.alt, vs.rx):
                continue
            entry = facts.entry(sub, vs.rx, vs.khz)
            relays = set() if entry is None else (
                entry.rx_relays if entry.rx_relays is not None else entry.relays)
            main_entry = facts.entry(t, vt.tx, vt.tx_khz)
            relays = set(relays) - set(() if main_entry is None else main_entry.relays)
            t_sw = facts.switches_of(t)
            for w, ports in facts.switches_of(ref).items():
                state = states[w]
                mine = {x % 100 for x in relays if x // 100 + 1 == w or only == w and x < 100}
                for p in ports:
                    if state.station(p).alt == 63:
                        continue
                    by = [tp for tp in range(1, 7) if p in state.use_alternate[tp - 1]]
                    if any(tp not in t_sw.get(w, []) for tp in by):
                        problems.append(f"switch {w}: {ref}'s alternate {v.alt}, where {t}'s sub "
                                        f"receiver {sub} listens, is switched in while ports "
                                        f"{by} transmit, not only {t}'s")
                    for tp in by:
                        if mine & state.station(tp).tx_relays:
                            problems.append(f"switch {w}: {t}'s port {tp} keeps {sub}'s relays "
                                            f"{sorted(mine)} while transmitting, when {ref} "
                                            f"listens on {v.alt}")
    return problems


def _conditions_513(e: Engine, facts: Facts, views: dict[RadioRef, RadioView], ref: RadioRef,
                    v: RadioView, t: RadioRef, vt: RadioView) -> bool:
    """5.13's conditions for ``ref`` and its partner ``t``: "There are two stations using the
    shared transmit antenna"; "The other partner has an antenna which can be used. It must be
    able to be connected to the partner and it must be fast" (the partner's sub receiver
    riding on its port without ``PersistSubReceiver`` does not use it then)."""
    assert vt.tx is not None
    rx = vt.rx
    if rx is None or rx == vt.tx or facts.conflict(rx, vt.tx):
        return False
    group = facts.group[vt.tx]
    holders = [(o, vo) for o, vo in views.items() if o not in facts.receivers
               or o in facts.subs]
    users = sum(1 for o, vo in holders if o not in facts.receivers
                and any(a in group for _, a in _held(vo)))
    ant = facts.ants[rx]
    return (users == 2 and _partner_rx_free(e, facts, holders, ref, t, vt)
            and not ant.tx_only and ant.enabled and facts.covers(ref, rx, v.khz)
            and (v.tx is None or v.tx == rx or facts.fast(v.tx, rx)))


def _shared(facts: Facts, a: int) -> bool:
    """An antenna radios may share: ``SharedTX``, one conflicting with a ``SharedTX`` antenna,
    or a shared-capable system's member."""
    return a in facts.shared_capable or any(
        facts.ants[b].shared_tx and facts.conflict(a, b) for b in facts.ants)


def _receivers_off_transmit_antennas(e: Engine, facts: Facts,
                                     holders: list[tuple[RadioRef, RadioView]],
                                     states: dict[int, Any], counts: Counter[str]) -> list[str]:
    """5.9: the alternate antenna exists for "cases where there might be a problem, such as a
    damaged receiver front end, if a station transmits on an antenna while another station
    is listening"; 5.13: "Normally if a radio is receiving on a transmit antenna it will be
    disconnected when another radio transmits on it"; 5.12's permission is that "only one
    can transmit at a time", not that one listens while the other transmits.

    No receiver is switched onto an antenna another radio transmits on: per switch, for
    every port of a radio transmitting now and every port of another radio receiving there,
    what the box connects the receiver to (its alternate while the transmitter is listed for
    it, else its receive antenna) does not conflict with the transmit antenna -- the 5.13
    partner receive antenna included, which its conditions keep apart from the partner's
    transmit antenna.  And the table is a safety layer of its own: every alternate slot a
    port holds conflicts with the transmit slot of every other radio on that switch whose
    transmit antenna conflicts with the alternate."""
    problems: list[str] = []
    for w, state in states.items():
        on_w = [(ref, v, facts.switches_of(ref)[w]) for ref, v in holders
                if w in facts.switches_of(ref)]
        for rr, vr, r_ports in on_w:
            for p in r_ports:
                alt_slot = state.station(p).alt
                if alt_slot == 63 or vr.alt is None:
                    continue
                for rt, vt, _t_ports in on_w:
                    if facts.family[rt] == facts.family[rr] or vt.tx is None:
                        continue
                    counts["alternate slot table"] += 1
                    if not facts.conflict(vr.alt, vt.tx):
                        continue
                    st = e.slot_of(w, vt.tx, rt.station, rt.radio, as_partner_alt=False)
                    if st is not None and (min(alt_slot, st), max(alt_slot, st)) \
                            not in state.conflicts:
                        problems.append(f"switch {w}: port {p}'s alternate {vr.alt} (slot "
                                        f"{alt_slot}) is not forbidden with {rt}'s transmit "
                                        f"{vt.tx} (slot {st})")
        for rt, vt, t_ports in on_w:
            if not vt.transmitting or vt.tx is None:
                continue
            for rr, vr, r_ports in on_w:
                if facts.family[rr] == facts.family[rt] or vr.transmitting:
                    continue
                for p in r_ports:
                    moved = any(p in state.use_alternate[tp - 1] for tp in t_ports)
                    if moved:
                        port = state.station(p)
                        listening = vr.alt if port.alt != 63 and port.alt_relays else None
                        wanted = [rule.antenna for rule in _radio(facts.cfg, rr).alternate
                                  if rule.antenna is not None and rule.antenna in facts.ants]
                        if any(_shared(facts, a) for a in wanted) or (
                                vr.alt is not None and _shared(facts, vr.alt)):
                            counts["shared alternate armed"] += 1
                    else:
                        listening = vr.rx
                    counts["receiver off transmit antenna"] += 1
                    if listening is not None and facts.conflict(listening, vt.tx):
                        problems.append(f"switch {w}: {rr} (port {p}) listens on {listening} "
                                        f"while {rt} transmits on {vt.tx} (5.9, 5.13)")
    return problems


def _radio(cfg: Config, ref: RadioRef) -> Radio:
    r = cfg.radio(ref.station, ref.radio)
    assert r is not None
    return r


def _may_share_band(cfg: Config, facts: Facts, a: RadioRef, b: RadioRef) -> bool:
    ra, rb = _radio(cfg, a), _radio(cfg, b)
    related = (b in ra.always or a in rb.always or b in ra.same_band or a in rb.same_band
               or bool(set(ra.inhibit_buss) & set(rb.inhibit_buss))
               or any(f.name == "Inhibit" for f in cfg.functions))
    return related and bool(set(facts.switches_of(a)) & set(facts.switches_of(b)))


# -- random evenings -----------------------------------------------------------------------

def operations(cfg: Config, rng: random.Random, count: int,
               frequencies: Sequence[float] = FREQUENCIES, keyed: float = 0.5) -> Iterator[Op]:
    """``count`` random operator events for ``cfg``, frequencies from ``frequencies``; a
    T/R event is a key-down with probability ``keyed``."""
    e = Engine(cfg)
    radios = [(v.station, v.radio) for v in e.radios()]
    mains = [(r.station, r.radio) for r in cfg.radios]
    antennas = [a.id for a in cfg.antennas]
    ports = sorted({(s.id, p) for s in cfg.switches for p in range(1, 7)})
    radio_ports = sorted({(sp.switch or cfg.switches[0].id, sp.port)
                          for r in cfg.radios for sp in r.switches})
    functions = [f.id for f in cfg.functions]
    electrical = [r.id for r in cfg.rotators if r.control is RotatorControl.ELECTRICAL]
    for _ in range(count):
        x = rng.random()
        if x < 0.35:
            yield ("freq", rng.choice(mains), rng.choice(frequencies),
                   rng.choice((None, None, None, 3.0, -250.0)))
        elif x < 0.40:
            yield ("freq", rng.choice(radios), rng.choice(frequencies), None)
        elif x < 0.62:
            yield ("select", rng.choice(radios), rng.choice(antennas),
                   rng.choice(("both", "both", "tx", "rx")), rng.random() < 0.2)
        elif x < 0.80:
            yield ("tr", rng.choice(radio_ports if rng.random() < 0.9 else ports),
                   rng.random() < keyed)
        elif x < 0.87:
            yield ("relative", rng.choice(radios), rng.choice((1, -1)))
        elif x < 0.97 and functions:
            yield ("function", rng.choice(radios), rng.choice(functions))
        elif electrical and x < 0.99:
            yield ("direction", rng.choice(electrical), rng.randrange(360))
        else:
            yield ("run", "stop" if rng.random() < 0.3 else "start")


def apply(e: Engine, op: Op, now: float) -> Any:
    kind = op[0]
    if kind == "freq":
        (s, r), khz, split = op[1], op[2], op[3]
        return e.set_frequency(s, r, khz, None if split is None else khz + split, now=now)
    if kind == "select":
        (s, r), a, target, exclusive = op[1:]
        return e.select(s, r, a, target, exclusive, now=now)
    if kind == "tr":
        (w, p), on = op[1], op[2]
        return e.set_transmitting(w, p, on, now=now)
    if kind == "relative":
        (s, r), step = op[1], op[2]
        return e.relative(s, r, step=step, now=now)
    if kind == "function":
        (s, r), fid = op[1], op[2]
        return e.run_function(s, r, fid, now=now)
    if kind == "direction":
        return e.select_direction(op[1], op[2], now=now)
    return e.stop() if op[1] == "stop" else e.start()


def snapshot(e: Engine) -> tuple[object, ...]:
    return (e.radios(), tuple(sorted(e.switch_states().items())), e.running)


def run_evening(cfg: Config, ops: Sequence[Op], facts: Facts | None = None,
                counts: Counter[str] | None = None, applied: Counter[str] | None = None) -> int:
    """Apply ``ops``, checking every rule after each; raise AssertionError naming the first
    broken one with the events that led there.  Returns the number of events refused.
    ``applied`` gets, per rule, how many events it ran at least one check after."""
    facts = facts or Facts.of(cfg)
    e = Engine(cfg)
    now = 0.0
    refused = 0
    for i, op in enumerate(ops):
        now += 0.7
        before = snapshot(e)
        try:
            apply(e, op, now)
        except EngineError as err:
            refused += 1
            assert err.message
            assert snapshot(e) == before, f"refused {op} changed the state"
            continue
        here: Counter[str] = Counter()
        problems = violations(e, facts, here)
        assert not problems, f"after {list(ops[:i + 1])[-8:]}: {problems}"
        if counts is not None:
            counts.update(here)
        if applied is not None:
            applied.update(here.keys())
    return refused


def replay_matches(cfg: Config, ops: Sequence[Op]) -> bool:
    """The same events give the same result."""
    results = []
    for _ in range(2):
        e = Engine(cfg)
        now = 0.0
        for op in ops:
            now += 0.7
            try:
                apply(e, op, now)
            except EngineError:
                pass
        results.append(snapshot(e))
    return results[0] == results[1]


__all__ = ["MULTIOP_RULES", "Facts", "apply", "multiop_violations", "operations", "replay_matches",
           "run_evening", "violations"]
