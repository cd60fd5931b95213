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
why that radio gets it.  The partner's sub receiver on that antenna (or one
conflicting with it) decides by how it is wired (6.10):

* with a port of its own, or with ``PersistSubReceiver``, it keeps listening
  while the partner transmits: the antenna is in use by another station
  (1.1.4, 1.1.12) and the alternate is "none";
* riding on the partner's port without ``PersistSubReceiver``, its relays are
  among that port's receive relays only, open exactly while the partner
  transmits, which is when the alternate is switched in: it is then where the
  partner is, and the partner's receive antenna stays the alternate.

When a radio that needs an alternate gets "none", :func:`alternates` says why
(the radio view's ``alt_why``).
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
    caller then asks :func:`available`, which judges the partner's own sub receiver)."""
    return _partner_alternate(ix, st, ref, other)[0]


def _partner_alternate(ix: ConfigIndex, st: State, ref: RadioRef, other: RadioRef
                       ) -> tuple[int | None, str]:
    """:func:`partner_alternate`, and when it is None which of 5.13's conditions fails."""
    if st.partners.get(ref) != other:
        return None, f"{other} is not its partner (5.13)"
    me, them = st.radios[ref], st.radios[other]
    shared = them.tx
    if shared is None or them.rx is None or them.rx == shared:
        return None, (f"its partner {other} receives on the antenna it transmits on, so it "
                      "has no antenna which can be used (5.13)")
    if them.transmitting and ix.conflict(them.rx, shared):
        # "The other partner has an antenna which can be used": one that conflicts with the
        # antenna the partner transmits on cannot be used while it transmits.  Until the
        # partner is seen transmitting it stays the prepared alternate: the switch's table
        # (its slot conflicts with the partner's transmit slot) then refuses it by itself.
        return None, (f"its partner's receive antenna {ix.name(them.rx)} conflicts with "
                      f"{ix.name(shared)}, on which {other} transmits (5.13)")
    canon = ix.canon[shared]
    count = 0
    for r in ix.mains:
        rs = st.radios[r]
        if any(a is not None and ix.canon[a] == canon for a in (rs.tx, rs.rx)):
            count += 1
    if count != 2:
        return None, (f"{count} radios use {ix.name(shared)}, and 5.13 is not available if "
                      "more than two radios are using the antenna")
    why = unusable(ix, st, ix.radios[ref], them.rx, me.khz, "rx")
    if why is not None:
        return None, f"its partner's receive antenna: {why} (5.13)"
    if me.tx is not None and me.tx != them.rx and not ix.is_fast(me.tx, them.rx):
        return None, (f"its partner's receive antenna {ix.name(them.rx)} is not fast with "
                      f"{ix.name(me.tx)}, and 5.13 says it must be fast")
    return them.rx, ""


def available(ix: ConfigIndex, st: State, ref: RadioRef, want: int | None,
              partner: RadioRef | None = None) -> int | None:
    """``want`` when no radio outside ``ref``'s family transmits on it or on anything
    conflicting with it, and none receives on it (or on a conflicting antenna) without the
    manual's permission, else None (:func:`blocked` says why).

    A transmit antenna of another radio is never available, shared or not: 5.12's
    permission is for radios taking turns to transmit ("only one can transmit at a time"),
    and an alternate is exactly what ``ref`` listens on while another radio transmits (5.9:
    "if a station transmits on an antenna while another station is listening").  The
    receive antenna of ``partner`` is exempt: 5.13 gives it to ``ref`` while the partner
    transmits (:func:`partner_alternate` has judged it against the partner's transmit
    antenna, and the switch's table forbids the pair).  So is what the partner's sub
    receiver listens on when it rides on the partner's port without ``PersistSubReceiver``
    (its relays open exactly while the partner transmits); with a port of its own or with
    ``PersistSubReceiver`` it keeps listening then, and uses the antenna (1.1.4)."""
    if want is None or blocked(ix, st, ref, want, partner):
        return None
    return want


def blocked(ix: ConfigIndex, st: State, ref: RadioRef, want: int,
            partner: RadioRef | None = None) -> str:
    """Why ``want`` is not available as ``ref``'s alternate ("" when it is): see
    :func:`available`."""
    for other, role, y in users(ix, st, ref):
        if other == partner and role == "rx":
            continue
        if not ix.conflict(want, y):
            continue
        if partner is not None and role == "rx" and _silent_with(ix, other, partner):
            continue
        if role == "tx" and other != partner:
            return f"{ix.name(y)} is {other}'s transmit antenna (5.9)"
        if not permitted(ix, st, ref, other, want, y):
            return _in_use(ix, other, y, partner)
    return ""


def sub_keeps_listening(ix: ConfigIndex, sub: RadioRef) -> str:
    """Why sub receiver ``sub`` listens on while its main radio transmits: "its own port"
    or "PersistSubReceiver" ("" when it rides on the main radio's port without
    ``PersistSubReceiver``, so that its relays open while the main radio transmits)."""
    info = ix.radios.get(sub)
    if info is None or info.kind is not RadioKind.SUB:
        return ""
    if info.ports:
        return "its own port"
    if ix.sub_flag(sub, "persist_sub_receiver"):
        return "PersistSubReceiver"
    return ""


def _silent_with(ix: ConfigIndex, other: RadioRef, partner: RadioRef) -> bool:
    """Whether ``other`` is ``partner``'s sub receiver riding on its port without
    ``PersistSubReceiver`` (6.10): disconnected exactly while the partner transmits."""
    info = ix.radios.get(other)
    return (info is not None and info.kind is RadioKind.SUB and info.main == partner
            and not sub_keeps_listening(ix, other))


def _in_use(ix: ConfigIndex, other: RadioRef, y: int, partner: RadioRef | None) -> str:
    info = ix.radios.get(other)
    if partner is not None and info is not None and info.kind is RadioKind.SUB \
            and info.main == partner:
        return (f"{ix.name(y)} is in use by {other}, the sub receiver of its partner "
                f"{partner}, which keeps listening while {partner} transmits "
                f"({sub_keeps_listening(ix, other)}; 1.1.4, 6.10)")
    return f"{ix.name(y)} is in use by {other} (5.9)"


Wanted = list[tuple[RadioRef, int | None, str]]
"""Trigger radios, each with the alternate it asks for (None: no antenna) and, when None,
why."""

Alternates = dict[RadioRef, tuple[int | None, frozenset[RadioRef]]]
"""Per main radio: its alternate receive antenna and the radios that switch it there."""


def alternates(ix: ConfigIndex, st: State, reasons: dict[RadioRef, str] | None = None
               ) -> Alternates:
    """Per main radio: its alternate receive antenna and the radios that switch it there.
    ``reasons`` gets, for each radio some radio switches to "none", why it has no
    alternate."""
    out: Alternates = {}
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
                why = "" if free is not None else (
                    f"its alternate receiver's antenna {ix.name(manual)}: "
                    + (blocked(ix, st, ref, manual) or "not available"))
                others.extend((t, free, why) for t in sorted(allowed) if t in ix.radios
                              and not related(ix, ref, t))
        if not safety and not others:
            out[ref] = (available(ix, st, ref, manual), frozenset())
        else:
            alt, triggers, why = _first_source_wins(safety, others)
            out[ref] = (alt, triggers)
            if reasons is not None and alt is None and triggers:
                reasons[ref] = why
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
                got = available(ix, st, ref, want, partner=t)
                why = "" if got is not None else (
                    f"its partner's receive antenna {ix.name(want)} is no alternate: "
                    + (blocked(ix, st, ref, want, partner=t) or "not available"))
            else:
                got = available(ix, st, ref, manual)
                why = "" if got is not None else (
                    f"{_partner_alternate(ix, st, ref, t)[1]}, and its alternate receiver's "
                    + ("antenna: none (1.1.14)" if manual is None else
                       f"antenna {ix.name(manual)}: "
                       + (blocked(ix, st, ref, manual) or "not available")))
            want = got
            if why:
                why = f"while {t} transmits on {ix.name(ts.tx)}: {why}"
            safety.append((t, want, why))
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
    why = "its Alternate rule names no antenna" if want is None else ""
    if want is not None and (want not in ix.antennas or unusable(
            ix, st, info, want, rs.khz, "rx") is not None):
        why = f"its Alternate rule's antenna {ix.name(want)}: " + (
            unusable(ix, st, info, want, rs.khz, "rx") or "" if want in ix.antennas
            else f"there is no antenna {want}")
        want = None
    got = available(ix, st, ref, want)
    if want is not None and got is None:
        why = f"its Alternate rule's antenna {ix.name(want)}: " + (
            blocked(ix, st, ref, want) or "not available")
    want = got
    return [(t, want, why) for t in ix.mains if _rule_triggers(ix, st, ref, rule, allowed, t)]


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
                       ) -> tuple[int | None, frozenset[RadioRef], str]:
    """One alternate per station: the shared-transmit source decides when it speaks
    (disagreeing triggers give none), else the first rule's; the triggers are every
    shared-transmit trigger and the others that want the same antenna.  The text says why
    the alternate is none (when it is)."""
    if safety:
        wants = {want for _, want, _why in safety}
        alt = wants.pop() if len(wants) == 1 else None
        if alt is None and wants:
            why = ("the radios holding transmit antennas its receive antenna conflicts with "
                   "would switch it to different antennas, and the switch has one alternate "
                   "per station")
        else:
            why = next((w for _, _want, w in safety if w), "")
    else:
        alt, why = others[0][1], others[0][2]
        if why:
            why = f"while {others[0][0]} transmits: {why}"
    triggers = {t for t, _want, _why in safety}
    triggers |= {t for t, want, _why in others if want == alt and t not in triggers}
    return alt, frozenset(triggers), why


__all__ = ["Alternates", "alternates", "available", "blocked", "inhibit_reason",
           "partner_alternate", "sub_keeps_listening"]
