"""The ten functions of 5.20 and 6.6.

Each has a status (available now or not, with the reason in words, so a button
can show it) and an action.  Functions that toggle something (Share, Relay,
Inhibit, Extra, Partner, AltActive) also report whether they are on, which a
button shows as "selected".

Decisions where the manual is silent are in ``docs/engine.md``; in short:
Swap exchanges TX and RX antennas and needs each radio's antennas to cover the
other radio's frequency; Store keeps one memory per radio; Share, turning a
system shared, gives the first user the shared member closest in size to what
it had and lets the others join it, and turning it unshared gives the users
the preferred antennas first, then selects by frequency; a Relay with a radio
and antennas is switched off when the condition stops holding and, with "S",
back on when it holds again; an Extra with "Transfer" is active only while
the two radios could swap and are interlocked; AltActive toggles the listed
radios in and out of the set that switches the radio to its alternate.
"""

from __future__ import annotations

from dataclasses import dataclass

from .config.model import Function, RadioRef
from .errors import NotFound, Unavailable
from .index import ConfigIndex, Kind
from .rules import interlocked, join_shared, unusable
from .selection import place, select_by_frequency
from .state import State
from .work import Work, radio_name


@dataclass(frozen=True, slots=True)
class Status:
    available: bool
    reason: str = ""


OK = Status(True)


def _ref(ix: ConfigIndex, params: tuple[int, ...], at: int) -> RadioRef | None:
    if len(params) < at + 2:
        return None
    ref = RadioRef(params[at], params[at + 1])
    return ref if ref in ix.radios else None


def _missing(f: Function, what: str) -> Status:
    return Status(False, f"function {f.id} ({f.label}) {what}")


def _main(ix: ConfigIndex, f: Function, ref: RadioRef | None, what: str) -> Status | None:
    if ref is None:
        return _missing(f, f"names {what} that does not exist")
    if ix.radios[ref].kind is not Kind.MAIN:
        return _missing(f, f"names {ref}, which is a receiver only")
    return None


def function(ix: ConfigIndex, function_id: int) -> Function:
    f = ix.functions.get(function_id)
    if f is None:
        raise NotFound(f"There is no function {function_id}")
    return f


# -- availability -----------------------------------------------------------------------------

def swap_status(ix: ConfigIndex, st: State, a: RadioRef, b: RadioRef) -> Status:
    ra, rb = st.radios[a], st.radios[b]
    if ra.tx is None or rb.tx is None:
        who = a if ra.tx is None else b
        return Status(False, f"{who} has no antenna to swap")
    for src, dst in ((ra, b), (rb, a)):
        info = ix.radios[dst]
        dst_khz = st.radios[dst].khz
        for role, antenna in (("tx", src.tx), ("rx", src.rx)):
            if antenna is None:
                continue
            if not any(unusable(ix, st, info, p, dst_khz, role) is None
                       for p in ix.group[antenna]):
                return Status(False, f"{ix.name(antenna)} does not cover the frequency of {dst}")
    return OK


def relay_condition(ix: ConfigIndex, st: State, f: Function) -> bool:
    """Whether a Relay function's radio has one of its antennas selected (6.6.6)."""
    p = f.int_params
    if len(p) < 3:
        return True
    ref = RadioRef(p[1], p[2])
    rs = st.radios.get(ref)
    if rs is None:
        return False
    wanted = {ix.canon.get(a, a) for a in p[3:]}
    if not wanted:
        return True
    flags = {s.upper() for s in f.string_params}
    use_tx = "T" in flags or not flags & {"T", "R"}
    use_rx = "R" in flags or not flags & {"T", "R"}
    return ((use_tx and rs.tx is not None and ix.canon[rs.tx] in wanted)
            or (use_rx and rs.rx is not None and ix.canon[rs.rx] in wanted))


def status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    """Whether ``f`` can run now for the radio ``ref`` that asks."""
    p = f.int_params
    name = f.name
    rs = st.radios[ref]
    if name == "AntennaSwap":
        a, b = _ref(ix, p, 0), _ref(ix, p, 2)
        bad = _main(ix, f, a, "a first radio") or _main(ix, f, b, "a second radio")
        if bad:
            return bad
        assert a is not None and b is not None
        return swap_status(ix, st, a, b)
    if name == "RXTX":
        if ix.radios[ref].kind is not Kind.MAIN or rs.tx is None:
            return Status(False, f"{ref} has no transmit antenna")
        if rs.rx == rs.tx:
            return Status(False, f"{ref} already receives on its transmit antenna")
        why = unusable(ix, st, ix.radios[ref], rs.tx, rs.khz, "rx")
        return Status(False, why) if why else OK
    if name == "Store":
        if rs.tx is None and rs.rx is None:
            return Status(False, f"{ref} has no antenna to store")
        return OK
    if name == "Recall":
        stored = st.stored.get(ref)
        if stored is None:
            return Status(False, f"nothing is stored for {ref}")
        trial = Work(ix, st.clone())
        if not place(trial, ref, stored[0], stored[1], takeover=False):
            return Status(False, f"the stored antennas ({ix.name(stored[0])}, "
                                 f"{ix.name(stored[1])}) cannot be used now")
        return OK
    if name == "Share":
        if not p or p[0] not in ix.systems.shared_capable:
            return _missing(f, "does not name a system with shared antennas")
        return OK
    if name == "Relay":
        if not p:
            return _missing(f, "does not name a relay")
        if len(p) >= 3 and _ref(ix, p, 1) is None:
            return _missing(f, "names a radio that does not exist")
        if f.id in st.relay_on or relay_condition(ix, st, f):
            return OK
        return Status(False, f"{RadioRef(p[1], p[2])} is not using an antenna this relay "
                             "goes with")
    if name == "Inhibit":
        return _main(ix, f, _ref(ix, p, 0), "a radio") or (
            OK if len(p) >= 3 else _missing(f, "does not name an inhibit buss"))
    if name == "Extra":
        transfer = any(s.lower() == "transfer" for s in f.string_params)
        bad = _main(ix, f, _ref(ix, p, 0), "a radio")
        if bad:
            return bad
        if len(p) < (5 if transfer else 3):
            return _missing(f, "does not name its relay")
        if transfer:
            a, b = RadioRef(p[0], p[1]), _ref(ix, p, 2)
            bad = _main(ix, f, b, "a second radio")
            if bad:
                return bad
            assert b is not None
            swap = swap_status(ix, st, a, b)
            if not swap.available:
                return swap
            if not interlocked(ix, st, a, b):
                return Status(False, f"{a} and {b} are not interlocked")
        return OK
    if name == "Partner":
        a, b = _ref(ix, p, 0), _ref(ix, p, 2)
        bad = _main(ix, f, a, "a first radio") or _main(ix, f, b, "a second radio")
        if bad:
            return bad
        assert a is not None and b is not None
        if a == b:
            return _missing(f, "names the same radio twice")
        if st.partners.get(a) == b:
            return OK
        for x in (a, b):
            if x in st.partners:
                return Status(False, f"{x} already has partner {st.partners[x]}")
        return OK
    if name == "AltActive":
        return _main(ix, f, _ref(ix, p, 0), "a radio") or (
            OK if len(p) >= 4 else _missing(f, "names no radio to switch it"))
    return _missing(f, f"has a name the server does not know: {name!r}")


def is_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    """Whether a toggling function is on now (a button shows it selected)."""
    p = f.int_params
    if f.name == "Share":
        return bool(p) and st.shared.get(p[0], False)
    if f.name == "Relay":
        return f.id in st.relay_on
    if f.name == "Inhibit":
        return len(p) >= 3 and p[2] in st.busses.get(RadioRef(p[0], p[1]), frozenset())
    if f.name == "Extra":
        return f.id in st.extra_on
    if f.name == "Partner":
        return len(p) >= 4 and st.partners.get(RadioRef(p[0], p[1])) == RadioRef(p[2], p[3])
    if f.name == "AltActive":
        current = st.alt_active.get(RadioRef(p[0], p[1])) if len(p) >= 2 else None
        listed = _listed(p)
        return current is not None and bool(listed) and listed <= current
    return False


def _listed(p: tuple[int, ...]) -> frozenset[RadioRef]:
    return frozenset(RadioRef(p[i], p[i + 1]) for i in range(2, len(p) - 1, 2))


# -- actions ----------------------------------------------------------------------------------

def run(w: Work, ref: RadioRef, f: Function) -> None:
    """Run ``f`` for ``ref`` (its status must be available)."""
    ix, st = w.ix, w.st
    verdict = status(ix, st, ref, f)
    if not verdict.available:
        raise Unavailable(f"{f.label} is not available: {verdict.reason}")
    p = f.int_params
    name = f.name
    if name == "AntennaSwap":
        _swap(w, RadioRef(p[0], p[1]), RadioRef(p[2], p[3]))
    elif name == "RXTX":
        rs = st.radios[ref]
        if not place(w, ref, rs.tx, rs.tx, rs.note, takeover=False):
            raise Unavailable(f"{ref} cannot receive on {ix.name(rs.tx)} now")
    elif name == "Store":
        rs = st.radios[ref]
        st.stored[ref] = (rs.tx, rs.rx)
        w.log.append(f"{radio_name(ref)}: stored TX {ix.name(rs.tx)}, RX {ix.name(rs.rx)}")
    elif name == "Recall":
        tx, rx = st.stored[ref]
        place(w, ref, tx, rx, takeover=False)
    elif name == "Share":
        _share(w, p[0], p[1:])
    elif name == "Relay":
        on = f.id not in st.relay_on
        st.relay_on = st.relay_on | {f.id} if on else st.relay_on - {f.id}
        st.relay_auto_off = st.relay_auto_off - {f.id}
        w.log.append(f"Relay {p[0]} ({f.label}) switched {'on' if on else 'off'}")
    elif name == "Inhibit":
        who = RadioRef(p[0], p[1])
        busses = st.busses.get(who, frozenset())
        joined = p[2] not in busses
        st.busses[who] = busses | {p[2]} if joined else busses - {p[2]}
        w.log.append(f"{radio_name(who)} {'joined' if joined else 'left'} inhibit buss {p[2]}")
    elif name == "Extra":
        on = f.id not in st.extra_on
        st.extra_on = st.extra_on | {f.id} if on else st.extra_on - {f.id}
        w.log.append(f"Extra relay {p[-1]} ({f.label}) {'on' if on else 'off'} "
                     f"for {RadioRef(p[0], p[1])}")
    elif name == "Partner":
        a, b = RadioRef(p[0], p[1]), RadioRef(p[2], p[3])
        if st.partners.get(a) == b:
            del st.partners[a]
            st.partners.pop(b, None)
            w.log.append(f"{radio_name(a)} and {b} are no longer partners")
        else:
            st.partners[a] = b
            st.partners[b] = a
            w.log.append(f"{radio_name(a)} and {b} are partners")
    elif name == "AltActive":
        who = RadioRef(p[0], p[1])
        listed = _listed(p)
        current = st.alt_active.get(who)
        if current is not None and listed <= current:
            st.alt_active[who] = current - listed
            w.log.append(f"{radio_name(who)}: no longer switched to its alternate by "
                         + ", ".join(str(x) for x in sorted(listed)))
        else:
            st.alt_active[who] = (current or frozenset()) | listed
            w.log.append(f"{radio_name(who)}: switched to its alternate when "
                         + ", ".join(str(x) for x in sorted(listed)) + " transmit")


def _swap(w: Work, a: RadioRef, b: RadioRef) -> None:
    st = w.st
    ra, rb = st.radios[a], st.radios[b]
    w.set_pair(a, None, None, ra.note)
    w.set_pair(b, None, None, rb.note)
    if not (place(w, a, rb.tx, rb.rx, takeover=False)
            and place(w, b, ra.tx, ra.rx, takeover=False)):
        raise Unavailable(f"the antennas of {a} and {b} cannot be swapped now")


def _share(w: Work, system: int, preferred: tuple[int, ...]) -> None:
    """6.6.5.  Turning a system unshared re-places every radio on it, first come first
    served: radios that were sharing one member must not keep it together."""
    ix, st = w.ix, w.st
    on = not st.shared.get(system, False)
    st.shared[system] = on
    w.log.append(f"System {system}: {'shared' if on else 'not shared'}")

    def in_system(a: int | None) -> bool:
        found = None if a is None else ix.systems.shared_system(ix.canon[a])
        return found is not None and found[0] == system

    affected = [r for r in ix.order if any(in_system(a) for a in (st.radios[r].tx,
                                                                    st.radios[r].rx))]
    held = {}
    for r in affected:
        rs = st.radios[r]
        held[r] = (rs.tx, rs.rx)
        w.set_pair(r, None if in_system(rs.tx) else rs.tx,
                   None if in_system(rs.rx) else rs.rx, rs.note)

    def put(r: RadioRef, tx: int | None, rx: int | None, a: int) -> bool:
        """``r`` back with ``a`` in place of what it had in the system."""
        return place(w, r, a if in_system(tx) else tx, a if in_system(rx) else rx,
                     takeover=False)

    for r, (tx, rx) in held.items():
        cur = next(a for a in (tx, rx) if in_system(a))
        assert cur is not None
        if on:
            members = [a for a in ix.ids if ix.systems.shared_system(ix.canon[a]) == (system, True)]
            size = len(ix.comps[cur])
            members.sort(key=lambda a: (a != cur, abs(len(ix.comps[a]) - size), a))
            joined = join_shared(ix, st, r, cur)
            if joined != cur:
                members = [joined]
            if any(put(r, tx, rx, m) for m in members):
                continue
        else:
            if ix.systems.usable(ix.canon[cur], st.shared) and put(r, tx, rx, cur):
                continue
            if any(place(w, r, a, a, takeover=False) for a in preferred if a in ix.antennas):
                continue
        select_by_frequency(w, r, None)


def refresh_relays(ix: ConfigIndex, st: State, w: Work | None = None) -> None:
    """Relay functions follow their antenna condition (6.6.6 "S")."""
    for f in ix.functions.values():
        if f.name != "Relay" or len(f.int_params) < 3:
            continue
        holds = relay_condition(ix, st, f)
        if f.id in st.relay_on and not holds:
            st.relay_on = st.relay_on - {f.id}
            if any(s.upper() == "S" for s in f.string_params):
                st.relay_auto_off = st.relay_auto_off | {f.id}
            if w is not None:
                w.log.append(f"Relay {f.int_params[0]} ({f.label}) switched off: its antenna "
                             "is no longer selected")
        elif f.id in st.relay_auto_off and holds:
            st.relay_on = st.relay_on | {f.id}
            st.relay_auto_off = st.relay_auto_off - {f.id}
            if w is not None:
                w.log.append(f"Relay {f.int_params[0]} ({f.label}) switched back on")


def relay_contributions(ix: ConfigIndex, st: State) -> list[tuple[int, RadioRef | None]]:
    """Relays that Relay functions hold on, with the radio each goes with."""
    out = []
    for fid in sorted(st.relay_on):
        f = ix.functions[fid]
        p = f.int_params
        owner = RadioRef(p[1], p[2]) if len(p) >= 3 else None
        out.append((p[0], owner))
    return out


def extra_relays(ix: ConfigIndex, st: State) -> dict[RadioRef, frozenset[int]]:
    """Relays closed while each radio transmits: 6.10.4 Extra and Extra functions."""
    out: dict[RadioRef, set[int]] = {}
    for ref in ix.mains:
        rs = st.radios[ref]
        freq = rs.tx_freq
        if freq is None:
            continue
        for tr in ix.radios[ref].radio.relays:
            if tr.extra and tr.range.contains(freq):
                out.setdefault(ref, set()).update(tr.extra)
    for fid in sorted(st.extra_on):
        f = ix.functions[fid]
        p = f.int_params
        ref = RadioRef(p[0], p[1])
        if ref in st.radios and status(ix, st, ref, f).available:
            out.setdefault(ref, set()).add(p[-1])
    return {k: frozenset(v) for k, v in out.items()}


__all__ = ["Status", "extra_relays", "function", "is_on", "refresh_relays",
           "relay_condition", "relay_contributions", "run", "status", "swap_status"]
