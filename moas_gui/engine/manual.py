"""What the operator asks for directly: a button press, a direction (5.15, 5.16).

``select`` targets: "both" sets the transmit and receive antennas (a
receive-only antenna sets only the receive antenna, a transmit-only one only
the transmit antenna: "It is not necessary to press the RX button before
selecting" a Beverage); "tx" and "rx" set one.  A receive antenna different
from the transmit antenna must be fast with it, else the switch would receive
on the transmit antenna anyway, so the press is refused with the reason.

Shared systems (5.10): a radio joining a shared system that others use gets
their member, whatever it pressed; a radio already on it changes the member
for every user.
"""

from __future__ import annotations

from moas_gui.config.model import RadioRef

from .errors import BadRequest, NotFound, Unavailable
from .index import RadioKind
from .rules import plan, shared_member, shared_users, unusable
from .selection import place
from .systems import press
from .why import DIRECTION, PRESS, SHARED, Why
from .work import Work, radio_name

TARGETS = ("both", "tx", "rx")


def _why_not(w: Work, ref: RadioRef, tx: int | None, rx: int | None) -> str:
    ix, st = w.ix, w.st
    info = ix.radios[ref]
    khz = st.radios[ref].khz
    for role, a in (("tx", tx), ("rx", rx)):
        if a is not None:
            reasons = [unusable(ix, st, info, p, khz, role) for p in ix.group[a]]
            if all(reasons):
                return reasons[0] or ""
    if tx is not None and rx is not None and tx != rx and not ix.is_fast(tx, rx):
        return (f"{radio_name(ref)} cannot receive on {ix.describe(rx)} while transmitting on "
                f"{ix.describe(tx)}: the switch cannot change between them fast enough")
    first = tx if tx is not None else rx
    assert first is not None
    for p in ix.group[first]:
        result, reason = plan(ix, st, ref, p, also=(rx,) if tx is not None and rx is not None
                              and rx != tx else (), takeover=False)
        if result is None and reason:
            return reason
    return f"{ix.describe(first)} cannot be used by {ref} now"


def select_antenna(w: Work, ref: RadioRef, antenna: int, target: str, exclusive: bool) -> None:
    ix, st = w.ix, w.st
    ant = ix.antennas.get(antenna)
    if ant is None:
        raise NotFound(f"There is no antenna {antenna}")
    if target not in TARGETS:
        raise BadRequest(f"target must be one of both, tx, rx (not {target!r})")
    rs = st.radios[ref]
    role = _press_role(w, ref, antenna, target)
    base = rs.rx if role == "rx" else (rs.tx if rs.tx is not None else rs.rx)
    current = ix.comps[base] if base is not None else frozenset()
    wanted = press(ix.systems, ix.comps, current, ix.canon[antenna], exclusive)
    if not wanted:
        w.log.append(f"{radio_name(ref)}: press on {ix.name(antenna)} ignored: it would leave "
                     "no antenna selected")
        return
    candidates = _combining(w, ref, antenna, wanted)
    if base is not None and ix.comps[base] == wanted and (role != "both" or rs.tx == rs.rx) \
            and base in candidates:
        return
    reason = ""
    why = Why(PRESS, f"{ix.name(antenna)} pressed by the operator"
              + (" (alone)" if exclusive else ""))
    for c in candidates:
        tx, rx = _roles(w, ref, role, c)
        if _shared_press(w, ref, c, role):
            return
        if place(w, ref, tx, rx, rs.note if rs.khz is None else "", why=why):
            return
        reason = reason or _why_not(w, ref, tx, rx)
    raise Unavailable(reason[0].upper() + reason[1:] if reason else
                      f"{ix.describe(antenna)} cannot be used now")


def _press_role(w: Work, ref: RadioRef, antenna: int, target: str) -> str:
    """What a press with ``target`` sets: a receiver only receives; "both" on a
    receive-only antenna sets the receive antenna, on a transmit-only one the transmit
    antenna.  A role the antenna cannot play is refused."""
    ix = w.ix
    ant = ix.antennas[antenna]
    if ix.radios[ref].kind is not RadioKind.MAIN:
        if target == "tx":
            raise BadRequest(f"{radio_name(ref)} only receives; it has no transmit antenna")
        target = "rx"
    if target == "both":
        role = "rx" if ant.rx_only else "tx" if ant.tx_only else "both"
    else:
        role = target
    if role == "tx" and ant.rx_only:
        raise Unavailable(f"{ix.describe(antenna)} is receive only")
    if role == "rx" and ant.tx_only:
        raise Unavailable(f"{ix.describe(antenna)} is transmit only")
    return role


def _combining(w: Work, ref: RadioRef, antenna: int, wanted: frozenset[int]) -> list[int]:
    """The antennas that combine exactly the components ``wanted``, the pressed one first
    when it is one of them; none is refused."""
    ix = w.ix
    candidates = list(ix.combos.get(wanted, ()))
    if ix.comps[antenna] == wanted and antenna in candidates:
        candidates.remove(antenna)
        candidates.insert(0, antenna)
    if not candidates:
        names = ", ".join(ix.name(c) for c in sorted(wanted))
        raise Unavailable(f"No antenna combines {names} for {ref}")
    return candidates


def _roles(w: Work, ref: RadioRef, role: str, c: int) -> tuple[int | None, int | None]:
    ix = w.ix
    rs = w.st.radios[ref]
    if role == "both":
        return c, c
    if role == "tx":
        rx = rs.rx if rs.rx is not None else (c if ix.can_receive(c) else None)
        return c, rx
    return rs.tx, c


def _shared_press(w: Work, ref: RadioRef, c: int, role: str) -> bool:
    """5.10 for a press on a shared member; True when it was handled here."""
    ix, st = w.ix, w.st
    system = shared_member(ix, st, c)
    if system is None:
        return False
    others = shared_users(ix, st, system, ref)
    if not others:
        return False
    rs = st.radios[ref]
    mine = [a for a in (rs.tx, rs.rx) if a is not None and shared_member(ix, st, a) == system]
    if not mine:
        _join_shared(w, ref, role, others)
        return True
    for other, _member in others:
        _move_shared_user(w, ref, other, c, system)
    tx, rx = _roles(w, ref, role, c)
    if not place(w, ref, tx, rx, why=Why(PRESS, f"{ix.name(c)} pressed by the operator "
                                                "(for every user of the shared system)")):
        raise Unavailable(_why_not(w, ref, tx, rx))
    return True


def _join_shared(w: Work, ref: RadioRef, role: str, others: list[tuple[RadioRef, int]]
                 ) -> None:
    """A radio not yet on a shared system that others use gets their member, whatever
    it pressed (5.10)."""
    member = others[0][1]
    tx, rx = _roles(w, ref, role, member)
    users = ", ".join(str(o) for o, _m in others)
    if not place(w, ref, tx, rx, why=Why(SHARED, f"the member of a shared system that "
                                                 f"{users} already use")):
        raise Unavailable(_why_not(w, ref, tx, rx))
    w.log.append(f"{radio_name(ref)} joined the shared system on {w.ix.name(member)}, "
                 "which its other users have selected")


def _move_shared_user(w: Work, ref: RadioRef, other: RadioRef, c: int, system: int) -> None:
    """A radio on a shared system pressing member ``c`` moves every other user of the
    system to ``c`` on the same roles (5.10); refused, with the reason, when ``c``
    cannot serve that user or is slow with the antenna it keeps."""
    ix, st = w.ix, w.st
    ors = st.radios[other]
    on_tx = ors.tx is not None and shared_member(ix, st, ors.tx) == system
    on_rx = ors.rx is not None and shared_member(ix, st, ors.rx) == system
    why = unusable(ix, st, ix.radios[other], c, ors.khz, "both" if on_tx and on_rx else
                   "tx" if on_tx else "rx")
    if why is None and on_tx != on_rx:
        keep = ors.rx if on_tx else ors.tx
        if keep is not None and not ix.is_fast(c, keep):
            why = f"the change between {ix.describe(c)} and {ix.describe(keep)} is slow"
    if why:
        raise Unavailable(f"{ix.describe(c)} cannot be used by {other}, which shares "
                          f"this system: {why}")
    w.set_pair(other,
               c if ors.tx is not None and shared_member(ix, st, ors.tx) == system else ors.tx,
               c if ors.rx is not None and shared_member(ix, st, ors.rx) == system else ors.rx,
               ors.note, Why(SHARED, f"{ref} changed the member of the shared system "
                                     "this radio uses"))


def select_direction(w: Work, rotator: int, heading: float) -> None:
    ix, st = w.ix, w.st
    members = [a for a in ix.ids if ix.antennas[a].rotator == rotator]
    if not members:
        raise Unavailable(f"No antenna is turned by rotator {rotator}")

    def gap(a: int) -> float:
        d = abs((ix.antennas[a].offset - heading) % 360)
        return min(d, 360 - d)

    ranked = sorted(members, key=lambda a: (gap(a), a))
    users = [ref for ref in ix.order
             if any(a in members for a in (st.radios[ref].tx, st.radios[ref].rx))]
    if not users:
        raise Unavailable(f"No radio is using an antenna of rotator {rotator}")
    why = Why(DIRECTION, f"rotator {rotator} turned to {heading:g} degrees")
    done = False
    for ref in users:
        rs = st.radios[ref]
        if done and any(shared_member(ix, st, a) is not None
                        for a in (rs.tx, rs.rx) if a is not None):
            continue
        if not _turn_radio(w, ref, members, ranked, why):
            raise Unavailable(f"No antenna of rotator {rotator} near {heading:g} degrees can be "
                              f"used by {ref} now")
        done = True
    w.log.append(f"Rotator {rotator}: {ix.name(ranked[0])} is closest to {heading:g} degrees")


def _turn_radio(w: Work, ref: RadioRef, members: list[int], ranked: list[int], why: Why
                ) -> bool:
    """A radio using antennas of the rotator gets the closest one it can have, on the
    roles it uses them for (staying where it is counts); False when none can be had."""
    rs = w.st.radios[ref]
    role = ("both" if rs.tx in members and rs.rx in members else
            "tx" if rs.tx in members else "rx")
    for target in ranked:
        tx, rx = _roles(w, ref, role, target)
        if (tx, rx) == (rs.tx, rs.rx) or _shared_press(w, ref, target, role) or place(
                w, ref, tx, rx, why=why):
            return True
    return False


__all__ = ["TARGETS", "select_antenna", "select_direction"]
