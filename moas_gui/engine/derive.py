"""What follows from the radios' antennas: inhibits and alternate receive antennas.

Inhibit by the server (the switch's "inhibit by command"), per radio, when:

* its frequency is known and it has no transmit antenna, or its transmit
  antenna does not cover its transmit frequency (appendix F steps 1, 6, 7;
  this project applies it whatever ``OutOfBand`` says, for safety);
* its frequency is not known yet and ``OutOfBand`` is set;
* its transmit antenna has ``Inhibit`` set.

With ``InhibitOnlyOnTransmit`` the inhibit is asserted only while the radio
transmits.  Radio-to-radio inhibits (Always, SameBand, inhibit busses) are
loaded into the switch (``~``) and it applies them itself.

Alternate receive antennas, per radio, from three sources in this order:

1. Shared transmit antennas (5.12, 5.13): when another radio transmits on an
   antenna this radio's receive antenna conflicts with, this radio must not
   listen there.  It moves to its partner's receive antenna when the partner
   conditions hold, else to its alternate receiver's antenna, else to none.
2. ``Alternate`` rules (6.10.2) for the other radios that match them.
3. ``AltActive`` radios with the antenna of the alternate receiver.

The switch has one alternate antenna per station: when sources disagree, the
first wins and triggers wanting something else are dropped (for source 1,
disagreeing triggers all get "none").

An alternate is never an antenna another radio holds (5.9: "If the alternate
antenna is not available it will select no antenna for the receiving
station"): one that conflicts with another radio's transmit antenna becomes
"none" whatever the sharing rules permit (5.12 lets interlocked radios take
turns transmitting on a ``SharedTX`` antenna, not listen on it while the other
transmits), and one that conflicts with another radio's receive antenna
becomes "none" unless the sharing rules permit the pair.  The one exception
is the partner's receive antenna while the partner transmits (5.13), which is
why that radio gets it; when the partner's sub receiver listens on that
antenna too, it is in use by another station (1.1.4, 1.1.12) and the
alternate is "none".
"""

from __future__ import annotations

from moas_gui.config.model import AlternateRule, RadioRef

from .index import ConfigIndex, IndexedRadio, RadioKind
from .ranges import describe_khz
from .rules import permitted, related, unusable, users
from .state import RadioState, State


def inhibit_reason(ix: ConfigIndex, st: State, ref: RadioRef) -> str:
    """Why the server inhibits ``ref`` now (empty when it does not)."""
    info = ix.radios[ref]
    if info.kind is not RadioKind.MAIN:
        return ""
    rs = st.radios[ref]
    if rs.khz is None and rs.tx is None:
        return "no frequency reported yet" if info.radio.out_of_band else ""
    if rs.tx is None:
        return "no transmit antenna" + (f": {rs.note}" if rs.note else "")
    tx_freq = rs.tx_freq
    if not info.covers(rs.tx, tx_freq):
        return f"{ix.name(rs.tx)} does not cover {describe_khz(tx_freq)}"
    if ix.antennas[rs.tx].inhibit:
        return f"{ix.name(rs.tx)} is set to inhibit transmit"
    return ""


def partner_alternate(ix: ConfigIndex, st: State, ref: RadioRef, other: RadioRef) -> int | None:
    """5.13: the partner's receive antenna, when every condition of the manual holds (the
    caller then asks :func:`available`: an antenna the partner's own sub receiver listens on
    is in use by another station, 1.1.4 and 1.1.12, so it is not "one which can be used")."""
    if st.partners.get(ref) != other:
        return None
    me, them = st.radios[ref], st.radios[other]
    shared = them.tx
    if shared is None or them.rx is None or them.rx == shared:
        return None
    if them.transmitting and ix.conflict(them.rx, shared):
        # "The other partner has an antenna which can be used": one that conflicts with the
        # antenna the partner transmits on cannot be used while it transmits.  Until the
        # partner is seen transmitting it stays the prepared alternate: the switch's table
        # (its slot conflicts with the partner's transmit slot) then refuses it by itself.
        return None
    canon = ix.canon[shared]
    count = 0
    for r in ix.mains:
        rs = st.radios[r]
        if any(a is not None and ix.canon[a] == canon for a in (rs.tx, rs.rx)):
            count += 1
    if count != 2:
        return None
    if unusable(ix, st, ix.radios[ref], them.rx, me.khz, "rx") is not None:
        return None
    if me.tx is not None and me.tx != them.rx and not ix.is_fast(me.tx, them.rx):
        return None
    return them.rx


def available(ix: ConfigIndex, st: State, ref: RadioRef, want: int | None,
              partner: RadioRef | None = None) -> int | None:
    """``want`` when no radio outside ``ref``'s family transmits on it or on anything
    conflicting with it, and none receives on it (or on a conflicting antenna) without the
    manual's permission, else None.

    A transmit antenna of another radio is never available, shared or not: 5.12's
    permission is for radios taking turns to transmit ("only one can transmit at a time"),
    and an alternate is exactly what ``ref`` listens on while another radio transmits (5.9:
    "if a station transmits on an antenna while another station is listening").  The
    receive antenna of ``partner`` is exempt: 5.13 gives it to ``ref`` while the partner
    transmits (:func:`partner_alternate` has judged it against the partner's transmit
    antenna, and the switch's table forbids the pair).  The partner's sub receiver is not
    exempt: listening there, it uses the antenna (1.1.4)."""
    if want is None:
        return None
    for other, role, y in users(ix, st, ref):
        if other == partner and role == "rx":
            continue
        if not ix.conflict(want, y):
            continue
        if role == "tx" and other != partner:
            return None
        if not permitted(ix, st, ref, other, want, y):
            return None
    return want


Wanted = list[tuple[RadioRef, int | None]]
"""Trigger radios, each with the alternate it asks for (None: no antenna)."""


def alternates(ix: ConfigIndex, st: State
               ) -> dict[RadioRef, tuple[int | None, frozenset[RadioRef]]]:
    """Per main radio: its alternate receive antenna and the radios that switch it there."""
    out: dict[RadioRef, tuple[int | None, frozenset[RadioRef]]] = {}
    for ref in ix.mains:
        info = ix.radios[ref]
        rs = st.radios[ref]
        alt_radio = st.radios.get(info.alt) if info.alt is not None else None
        manual = alt_radio.rx if alt_radio is not None else None
        safety: Wanted = []
        others: Wanted = []
        if rs.rx is not None:
            safety = _shared_tx_alternates(ix, st, ref, rs.rx, manual)
            allowed = st.alt_active.get(ref)
            for rule in info.radio.alternate:
                others.extend(_rule_alternates(ix, st, ref, info, rs, rs.rx, rule, allowed))
            if allowed is not None and manual is not None:
                free = available(ix, st, ref, manual)
                others.extend((t, free) for t in sorted(allowed) if t in ix.radios
                              and not related(ix, ref, t))
        if not safety and not others:
            out[ref] = (available(ix, st, ref, manual), frozenset())
        else:
            out[ref] = _first_source_wins(safety, others)
    return out


def _shared_tx_alternates(ix: ConfigIndex, st: State, ref: RadioRef, rx: int,
                          manual: int | None) -> Wanted:
    """Source 1 (5.12, 5.13): each unrelated radio transmitting on an antenna that
    conflicts with ``rx`` by permission sends ``ref`` to its partner's receive antenna
    when the partner conditions hold, else to the alternate receiver's antenna, each
    only when available."""
    safety: Wanted = []
    for t in ix.mains:
        if related(ix, ref, t):
            continue
        ts = st.radios[t]
        if ts.tx is not None and ix.conflict(rx, ts.tx) and permitted(
                ix, st, ref, t, rx, ts.tx):
            want = partner_alternate(ix, st, ref, t)
            if want is not None:
                want = available(ix, st, ref, want, partner=t)
            else:
                want = available(ix, st, ref, manual)
            safety.append((t, want))
    return safety


def _rule_alternates(ix: ConfigIndex, st: State, ref: RadioRef, info: IndexedRadio,
                     rs: RadioState, rx: int, rule: AlternateRule,
                     allowed: frozenset[RadioRef] | None) -> Wanted:
    """Source 2 (6.10.2): an ``Alternate`` rule of ``ref`` that matches its receive
    antenna ``rx`` and frequency asks for its antenna (None when unusable or not available)
    for every unrelated radio transmitting in the rule's range on one of its other
    antennas (only the ``AltActive`` radios when ``allowed`` names them)."""
    if rule.this_antennas and ix.canon[rx] not in {
            ix.canon.get(a, a) for a in rule.this_antennas}:
        return []
    if rs.khz is None or not rule.range.contains(rs.khz):
        return []
    want = rule.antenna
    if want is not None and (want not in ix.antennas or unusable(
            ix, st, info, want, rs.khz, "rx") is not None):
        want = None
    want = available(ix, st, ref, want)
    return [(t, want) for t in ix.mains if _rule_triggers(ix, st, ref, rule, allowed, t)]


def _rule_triggers(ix: ConfigIndex, st: State, ref: RadioRef, rule: AlternateRule,
                   allowed: frozenset[RadioRef] | None, t: RadioRef) -> bool:
    """Whether radio ``t`` transmitting sets off ``ref``'s ``Alternate`` rule: it is
    unrelated, allowed, transmits in the rule's range and on one of its other antennas."""
    if related(ix, ref, t) or (allowed is not None and t not in allowed):
        return False
    ts = st.radios[t]
    if ts.tx is None or ts.tx_freq is None or not rule.range.contains(ts.tx_freq):
        return False
    return not (rule.other_antennas and ix.canon[ts.tx] not in {
        ix.canon.get(a, a) for a in rule.other_antennas})


def _first_source_wins(safety: Wanted, others: Wanted
                       ) -> tuple[int | None, frozenset[RadioRef]]:
    """One alternate per station: the shared-transmit source decides when it speaks
    (disagreeing triggers give none), else the first rule's; the triggers are every
    shared-transmit trigger and the others that want the same antenna."""
    if safety:
        wants = {want for _, want in safety}
        alt = wants.pop() if len(wants) == 1 else None
    else:
        alt = others[0][1]
    triggers = {t for t, _want in safety}
    triggers |= {t for t, want in others if want == alt and t not in triggers}
    return alt, frozenset(triggers)


__all__ = ["alternates", "available", "inhibit_reason", "partner_alternate"]
