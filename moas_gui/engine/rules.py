"""Who may use what: conflicts, sharing, interlocks, and re-pathing.

Rules, in words:

* Two radios may not hold conflicting antennas (5.5), counting each radio's
  transmit and receive antennas.  Alternate receive antennas never block anyone
  (the switch gives an alternate no relays while it conflicts).
* A radio and its own sub or alternate receiver never block each other.
* Exceptions the manual grants: radios using the same shared member of a
  system in shared mode (5.10); interlocked radios (each inhibits the other)
  when one of the two antennas is ``SharedTX`` (5.12).
* An antenna held by a radio it does not suit (it does not cover that radio's
  frequency) may be taken over by a radio it suits; the loser is selected
  again (appendix F).
* A blocking radio may be moved to another path of the same antenna (5.8,
  7.4) when that path is free: the swap of the main and sub feeds.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

from moas_gui.config.model import RadioRef

from .index import ConfigIndex, IndexedRadio, RadioKind
from .ranges import describe_khz, in_segment
from .state import RadioState, State
from .systems import Link


def related(ix: ConfigIndex, a: RadioRef, b: RadioRef) -> bool:
    """A radio, its sub receiver and its alternate receiver are one family."""
    if a == b:
        return True
    ia, ib = ix.radios.get(a), ix.radios.get(b)
    if ia is None or ib is None:
        return False
    return (ia.main or a) == (ib.main or b)


def users(ix: ConfigIndex, st: State, ref: RadioRef) -> Iterator[tuple[RadioRef, str, int]]:
    """(radio, "tx"/"rx", antenna) held by radios outside ``ref``'s family that can block."""
    for other, rs in st.radios.items():
        if rs.tx is None and rs.rx is None:
            continue
        info = ix.radios[other]
        if info.kind is RadioKind.ALT or related(ix, ref, other):
            continue
        if rs.tx is not None:
            yield other, "tx", rs.tx
        if rs.rx is not None and rs.rx != rs.tx:
            yield other, "rx", rs.rx


# -- inhibit relations ------------------------------------------------------------------------

def same_band(ix: ConfigIndex, st: State, transmitter: RadioRef, receiver: RadioRef) -> bool:
    """Whether ``transmitter`` transmits within the range of ``receiver``'s receive antenna."""
    t = st.radios.get(transmitter)
    r = st.radios.get(receiver)
    if t is None or r is None or t.tx_freq is None or r.khz is None:
        return False
    info = ix.radios[receiver]
    seg = info.segment(r.rx, r.khz) if r.rx is not None else None
    if seg is None:
        seg = info.band(r.khz)
    return in_segment(seg, t.tx_freq)


def seen_together(ix: ConfigIndex, a: RadioRef, b: RadioRef) -> bool:
    """Whether some switch has ports of both radios: only such a switch can inhibit one
    while the other transmits (it reads one's T/R line and drives the other's inhibit)."""
    return bool(ix.radio_switches.get(a, frozenset()) & ix.radio_switches.get(b, frozenset()))


def inhibits(ix: ConfigIndex, st: State, transmitter: RadioRef, receiver: RadioRef) -> bool:
    """Whether ``receiver`` is inhibited while ``transmitter`` transmits (5.11)."""
    if transmitter == receiver:
        return False
    info = ix.radios.get(receiver)
    if info is None or info.kind is not RadioKind.MAIN:
        return False
    cfg = info.radio
    related = (transmitter in cfg.always
               or bool(st.busses.get(receiver, frozenset()) & st.busses.get(transmitter,
                                                                            frozenset()))
               or transmitter in cfg.same_band and same_band(ix, st, transmitter, receiver))
    return related and seen_together(ix, transmitter, receiver)


def interlocked(ix: ConfigIndex, st: State, a: RadioRef, b: RadioRef) -> bool:
    """Only one of ``a`` and ``b`` can transmit at a time."""
    return inhibits(ix, st, a, b) and inhibits(ix, st, b, a)


# -- sharing ----------------------------------------------------------------------------------

def shared_member(ix: ConfigIndex, st: State, antenna: int) -> int | None:
    """The system when ``antenna`` is a shared member of a system in shared mode."""
    if antenna not in ix.shared_members:
        return None
    m = ix.systems.parent(ix.canon[antenna])
    if m is None or m.link is not Link.SHARED or not st.shared.get(m.system, False):
        return None
    return m.system


def permitted(ix: ConfigIndex, st: State, a: RadioRef, b: RadioRef, x: int, y: int) -> bool:
    """Whether radio ``a`` on ``x`` and radio ``b`` on ``y`` may coexist although they conflict."""
    if x == y and shared_member(ix, st, x) is not None:
        return True
    if ix.antennas[x].shared_tx or ix.antennas[y].shared_tx:
        return interlocked(ix, st, a, b)
    return False


def shared_users(ix: ConfigIndex, st: State, system: int, ref: RadioRef
                 ) -> list[tuple[RadioRef, int]]:
    """Other radios using a shared member of ``system``, ``ref``'s own sub receiver included
    (it is "an additional radio", 1.1.12, on the same coax)."""
    out = []
    for other, rs in st.radios.items():
        if other == ref or ix.radios[other].kind is RadioKind.ALT:
            continue
        for a in (rs.tx, rs.rx):
            if a is not None and shared_member(ix, st, a) == system:
                out.append((other, a))
                break
    return out


def join_shared(ix: ConfigIndex, st: State, ref: RadioRef, antenna: int) -> int:
    """5.10: joining a shared system in use gives the member its users have now."""
    system = shared_member(ix, st, antenna)
    if system is None:
        return antenna
    for _other, member in shared_users(ix, st, system, ref):
        return member
    return antenna


def unpermitted(ix: ConfigIndex, st: State) -> list[tuple[RadioRef, RadioRef, int, int]]:
    """Radios holding conflicting antennas the rules do not permit now (after an inhibit
    relation changed under two radios sharing a ``SharedTX`` antenna)."""
    held = [(ref, a) for ref in ix.order if ix.radios[ref].kind is not RadioKind.ALT
            for a in {st.radios[ref].tx, st.radios[ref].rx} if a is not None]
    out = []
    for i, (ra, x) in enumerate(held):
        for rb, y in held[i + 1:]:
            if ra != rb and ix.conflict(x, y) and not related(ix, ra, rb) \
                    and not permitted(ix, st, ra, rb, x, y):
                out.append((ra, rb, x, y))
    return out


# -- usability --------------------------------------------------------------------------------

def unusable(ix: ConfigIndex, st: State, info: IndexedRadio, antenna: int, khz: float | None,
             role: str, nearest: bool = False) -> str | None:
    """Why ``info``'s radio cannot use ``antenna`` for ``role`` at ``khz`` (None when it can).

    ``role`` is "tx", "rx" or "both".  With ``nearest``, coverage is not required.
    """
    ant = ix.antennas.get(antenna)
    if ant is None:
        return f"there is no antenna {antenna}"
    if not ant.enabled:
        return f"{ix.describe(antenna)} is not enabled"
    if role != "rx" and ant.rx_only:
        return f"{ix.describe(antenna)} is receive only"
    if role != "tx" and ant.tx_only:
        return f"{ix.describe(antenna)} is transmit only"
    if antenna not in info.paths:
        return f"{ix.describe(antenna)} has no relays for {info.ref}"
    if not nearest and not info.covers(antenna, khz):
        return f"{ix.describe(antenna)} does not cover {describe_khz(khz)} for {info.ref}"
    if not ix.systems.usable(ix.canon[antenna], st.shared):
        m = ix.systems.parent(ix.canon[antenna])
        mode = "shared" if m is not None and st.shared.get(m.system, False) else "not shared"
        return f"{ix.describe(antenna)} cannot be used while its system is {mode}"
    return None


def suits(ix: ConfigIndex, rs: RadioState, info: IndexedRadio, antenna: int | None) -> bool:
    return antenna is not None and info.covers(antenna, rs.khz)


# -- planning a use ---------------------------------------------------------------------------

@dataclass(slots=True)
class UsePlan:
    """How ``antenna`` can be given to a radio: other radios moved or taken from."""

    antenna: int
    moves: dict[tuple[RadioRef, str], int] = field(default_factory=dict)
    takeovers: list[RadioRef] = field(default_factory=list)


def _blocks(ix: ConfigIndex, st: State, ref: RadioRef, x: int, other: RadioRef, y: int) -> bool:
    return ix.conflict(x, y) and not permitted(ix, st, ref, other, x, y)


def plan(ix: ConfigIndex, st: State, ref: RadioRef, antenna: int, *,
         also: Sequence[int] = (), takeover: bool = True,
         repath: bool = True) -> tuple[UsePlan | None, str]:
    """Whether ``ref`` can hold ``antenna`` (plus ``also``, its other role) without conflict.

    Returns the plan, or None and a sentence naming the radio in the way.  With
    ``repath`` False no other radio is moved to another path.
    """
    result = UsePlan(antenna)
    mine = (antenna, *also)
    held = list(users(ix, st, ref))
    blocked: dict[RadioRef, list[tuple[str, int]]] = {}
    for other, role, y in held:
        if any(_blocks(ix, st, ref, x, other, y) for x in mine):
            blocked.setdefault(other, []).append((role, y))
    if not blocked:
        return result, ""
    for other, roles in blocked.items():
        ors = st.radios[other]
        oinfo = ix.radios[other]
        unsuited = [(r, y) for r, y in roles if not suits(ix, ors, oinfo, y)]
        if takeover and unsuited and len(unsuited) == len(roles):
            result.takeovers.append(other)
            continue
        for role, y in roles:
            moved = _repath(ix, st, ref, mine, other, role, y, result) if repath else None
            if moved is None:
                return None, (f"{ix.describe(y)} is in use by {other}"
                              if y in mine or ix.canon[y] in {ix.canon[m] for m in mine}
                              else f"{ix.describe(antenna)} conflicts with {ix.describe(y)} "
                                   f"used by {other}")
            result.moves[(other, role)] = moved
    return result, ""


def _repath(ix: ConfigIndex, st: State, ref: RadioRef, mine: Sequence[int], other: RadioRef,
            role: str, y: int, result: UsePlan) -> int | None:
    ors = st.radios[other]
    oinfo = ix.radios[other]
    both = ors.tx == ors.rx
    for y2 in ix.group[y]:
        if y2 == y or unusable(ix, st, oinfo, y2, ors.khz, "both" if both else role):
            continue
        if any(_blocks(ix, st, ref, x, other, y2) for x in mine):
            continue
        clash = False
        # every other holder counts, the requesting radio's own family too (its sub receiver
        # may hold an antenna on the new path's feed); the requesting radio's own antennas
        # are the ones being replaced (``mine``, checked above)
        for third, _r, z in users(ix, st, other):
            if third == ref:
                continue
            z = result.moves.get((third, _r), z)
            if _blocks(ix, st, other, y2, third, z):
                clash = True
                break
        if clash:
            continue
        if not both:
            partner = ors.rx if role == "tx" else ors.tx
            if partner is not None and partner != y2 and not ix.is_fast(y2, partner):
                continue
        return y2
    return None


__all__ = [
    "UsePlan",
    "inhibits",
    "interlocked",
    "join_shared",
    "permitted",
    "plan",
    "related",
    "same_band",
    "seen_together",
    "shared_member",
    "shared_users",
    "suits",
    "unpermitted",
    "unusable",
    "users",
]
