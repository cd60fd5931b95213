"""The ten function kinds of 5.20 and 6.6 as one table: per kind, how its parameters are
checked against the configuration, whether it can run now, whether it is on, and what it
does.  :data:`KINDS` is the table; ``functions.py`` dispatches through it.

A kind's ``check`` answers "does this function make sense in this configuration" (radios
that exist and transmit, enough parameters); ``status`` answers "can it run now" and is
only asked after ``check`` passed; ``is_on`` is None for kinds that do not toggle.
Decisions where the manual is silent are in ``docs/engine.md``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from moas_gui.config.model import FUNCTION_NAMES, Function, RadioRef

from .errors import Unavailable
from .index import ConfigIndex, RadioKind
from .rules import interlocked, unusable
from .selection import place
from .sharing import toggle_share
from .state import State
from .work import Work, radio_name


@dataclass(frozen=True, slots=True)
class Status:
    """Whether a function can be used now, and why not when it cannot."""

    available: bool
    reason: str = ""


OK = Status(True)

Check = Callable[[ConfigIndex, Function], "Status | None"]
StatusOf = Callable[[ConfigIndex, State, RadioRef, Function], Status]
IsOn = Callable[[ConfigIndex, State, Function], bool]
Run = Callable[[Work, RadioRef, Function], None]


@dataclass(frozen=True, slots=True)
class FunctionKind:
    """One row of the table."""

    name: str
    check: Check
    """None when the parameters make sense for the configuration, else why not."""
    status: StatusOf
    """Whether it can run now for the radio asking (after ``check`` passed)."""
    is_on: IsOn | None
    """Whether a toggling function is on now (a button shows it selected)."""
    run: Run


# -- parameter helpers ------------------------------------------------------------------------

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
    if ix.radios[ref].kind is not RadioKind.MAIN:
        return _missing(f, f"names {ref}, which is a receiver only")
    return None


def _two_mains(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    return (_main(ix, f, _ref(ix, p, 0), "a first radio")
            or _main(ix, f, _ref(ix, p, 2), "a second radio"))


def _no_check(ix: ConfigIndex, f: Function) -> Status | None:
    return None


def _always(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    return OK


def _pair(p: tuple[int, ...]) -> tuple[RadioRef, RadioRef]:
    return RadioRef(p[0], p[1]), RadioRef(p[2], p[3])


def _listed(p: tuple[int, ...]) -> frozenset[RadioRef]:
    return frozenset(RadioRef(p[i], p[i + 1]) for i in range(2, len(p) - 1, 2))


# -- AntennaSwap (6.6.1) ----------------------------------------------------------------------

def swap_status(ix: ConfigIndex, st: State, a: RadioRef, b: RadioRef) -> Status:
    """Both radios have antennas and each one's antennas (some path) cover the other's
    frequency."""
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


def _swap_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    return swap_status(ix, st, *_pair(f.int_params))


def _swap_run(w: Work, ref: RadioRef, f: Function) -> None:
    a, b = _pair(f.int_params)
    st = w.st
    ra, rb = st.radios[a], st.radios[b]
    w.set_pair(a, None, None, ra.note)
    w.set_pair(b, None, None, rb.note)
    if not (place(w, a, rb.tx, rb.rx, takeover=False)
            and place(w, b, ra.tx, ra.rx, takeover=False)):
        raise Unavailable(f"the antennas of {a} and {b} cannot be swapped now")


# -- RXTX (6.6.2) -----------------------------------------------------------------------------

def _rxtx_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    rs = st.radios[ref]
    if ix.radios[ref].kind is not RadioKind.MAIN or rs.tx is None:
        return Status(False, f"{ref} has no transmit antenna")
    if rs.rx == rs.tx:
        return Status(False, f"{ref} already receives on its transmit antenna")
    why = unusable(ix, st, ix.radios[ref], rs.tx, rs.khz, "rx")
    return Status(False, why) if why else OK


def _rxtx_run(w: Work, ref: RadioRef, f: Function) -> None:
    rs = w.st.radios[ref]
    if not place(w, ref, rs.tx, rs.tx, rs.note, takeover=False):
        raise Unavailable(f"{ref} cannot receive on {w.ix.name(rs.tx)} now")


# -- Store and Recall (6.6.3, 6.6.4) ----------------------------------------------------------

def _store_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    rs = st.radios[ref]
    if rs.tx is None and rs.rx is None:
        return Status(False, f"{ref} has no antenna to store")
    return OK


def _store_run(w: Work, ref: RadioRef, f: Function) -> None:
    rs = w.st.radios[ref]
    w.st.stored[ref] = (rs.tx, rs.rx)
    w.log.append(f"{radio_name(ref)}: stored TX {w.ix.name(rs.tx)}, RX {w.ix.name(rs.rx)}")


def _recall_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    stored = st.stored.get(ref)
    if stored is None:
        return Status(False, f"nothing is stored for {ref}")
    trial = Work(ix, st.clone())
    if not place(trial, ref, stored[0], stored[1], takeover=False):
        return Status(False, f"the stored antennas ({ix.name(stored[0])}, "
                             f"{ix.name(stored[1])}) cannot be used now")
    return OK


def _recall_run(w: Work, ref: RadioRef, f: Function) -> None:
    tx, rx = w.st.stored[ref]
    place(w, ref, tx, rx, takeover=False)


# -- Share (6.6.5) ----------------------------------------------------------------------------

def _share_check(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    if not p or p[0] not in ix.systems.shared_capable:
        return _missing(f, "does not name a system with shared antennas")
    return None


def _share_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    return st.shared.get(f.int_params[0], False)


def _share_run(w: Work, ref: RadioRef, f: Function) -> None:
    toggle_share(w, f.int_params[0], f.int_params[1:])


# -- Relay (6.6.6) ----------------------------------------------------------------------------

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


def _relay_check(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    if not p:
        return _missing(f, "does not name a relay")
    if len(p) >= 3 and _ref(ix, p, 1) is None:
        return _missing(f, "names a radio that does not exist")
    return None


def _relay_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    p = f.int_params
    if f.id in st.relay_on or relay_condition(ix, st, f):
        return OK
    return Status(False, f"{RadioRef(p[1], p[2])} is not using an antenna this relay goes with")


def _relay_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    return f.id in st.relay_on


def _relay_run(w: Work, ref: RadioRef, f: Function) -> None:
    st = w.st
    on = f.id not in st.relay_on
    st.relay_on = st.relay_on | {f.id} if on else st.relay_on - {f.id}
    st.relay_auto_off = st.relay_auto_off - {f.id}
    w.log.append(f"Relay {f.int_params[0]} ({f.label}) switched {'on' if on else 'off'}")


# -- Inhibit (6.6.7) --------------------------------------------------------------------------

def _inhibit_check(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    return _main(ix, f, _ref(ix, p, 0), "a radio") or (
        None if len(p) >= 3 else _missing(f, "does not name an inhibit buss"))


def _inhibit_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    p = f.int_params
    return p[2] in st.busses.get(RadioRef(p[0], p[1]), frozenset())


def _inhibit_run(w: Work, ref: RadioRef, f: Function) -> None:
    p = f.int_params
    st = w.st
    who = RadioRef(p[0], p[1])
    busses = st.busses.get(who, frozenset())
    joined = p[2] not in busses
    st.busses[who] = busses | {p[2]} if joined else busses - {p[2]}
    w.log.append(f"{radio_name(who)} {'joined' if joined else 'left'} inhibit buss {p[2]}")


# -- Extra (6.6.8) ----------------------------------------------------------------------------

def _transfer(f: Function) -> bool:
    return any(s.lower() == "transfer" for s in f.string_params)


def _extra_check(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    bad = _main(ix, f, _ref(ix, p, 0), "a radio")
    if bad:
        return bad
    if len(p) < (5 if _transfer(f) else 3):
        return _missing(f, "does not name its relay")
    if _transfer(f):
        return _main(ix, f, _ref(ix, p, 2), "a second radio")
    return None


def _extra_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    if not _transfer(f):
        return OK
    a, b = _pair(f.int_params)
    swap = swap_status(ix, st, a, b)
    if not swap.available:
        return swap
    if not interlocked(ix, st, a, b):
        return Status(False, f"{a} and {b} are not interlocked")
    return OK


def _extra_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    return f.id in st.extra_on


def _extra_run(w: Work, ref: RadioRef, f: Function) -> None:
    st = w.st
    p = f.int_params
    on = f.id not in st.extra_on
    st.extra_on = st.extra_on | {f.id} if on else st.extra_on - {f.id}
    w.log.append(f"Extra relay {p[-1]} ({f.label}) {'on' if on else 'off'} "
                 f"for {RadioRef(p[0], p[1])}")


# -- Partner (6.6.9) --------------------------------------------------------------------------

def _partner_check(ix: ConfigIndex, f: Function) -> Status | None:
    bad = _two_mains(ix, f)
    if bad:
        return bad
    a, b = _pair(f.int_params)
    return _missing(f, "names the same radio twice") if a == b else None


def _partner_status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    a, b = _pair(f.int_params)
    if st.partners.get(a) == b:
        return OK
    for x in (a, b):
        if x in st.partners:
            return Status(False, f"{x} already has partner {st.partners[x]}")
    return OK


def _partner_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    a, b = _pair(f.int_params)
    return st.partners.get(a) == b


def _partner_run(w: Work, ref: RadioRef, f: Function) -> None:
    st = w.st
    a, b = _pair(f.int_params)
    if st.partners.get(a) == b:
        del st.partners[a]
        st.partners.pop(b, None)
        w.log.append(f"{radio_name(a)} and {b} are no longer partners")
    else:
        st.partners[a] = b
        st.partners[b] = a
        w.log.append(f"{radio_name(a)} and {b} are partners")


# -- AltActive (6.6.10) -----------------------------------------------------------------------

def _alt_active_check(ix: ConfigIndex, f: Function) -> Status | None:
    p = f.int_params
    return _main(ix, f, _ref(ix, p, 0), "a radio") or (
        None if len(p) >= 4 else _missing(f, "names no radio to switch it"))


def _alt_active_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    p = f.int_params
    current = st.alt_active.get(RadioRef(p[0], p[1]))
    listed = _listed(p)
    return current is not None and bool(listed) and listed <= current


def _alt_active_run(w: Work, ref: RadioRef, f: Function) -> None:
    st = w.st
    p = f.int_params
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


# -- the table --------------------------------------------------------------------------------

KINDS: Mapping[str, FunctionKind] = MappingProxyType({k.name: k for k in (
    FunctionKind("AntennaSwap", _two_mains, _swap_status, None, _swap_run),
    FunctionKind("RXTX", _no_check, _rxtx_status, None, _rxtx_run),
    FunctionKind("Store", _no_check, _store_status, None, _store_run),
    FunctionKind("Recall", _no_check, _recall_status, None, _recall_run),
    FunctionKind("Share", _share_check, _always, _share_on, _share_run),
    FunctionKind("Relay", _relay_check, _relay_status, _relay_on, _relay_run),
    FunctionKind("Inhibit", _inhibit_check, _always, _inhibit_on, _inhibit_run),
    FunctionKind("Extra", _extra_check, _extra_status, _extra_on, _extra_run),
    FunctionKind("Partner", _partner_check, _partner_status, _partner_on, _partner_run),
    FunctionKind("AltActive", _alt_active_check, _always, _alt_active_on, _alt_active_run),
)})
"""Every function kind of the manual, by its ``Name`` in the configuration."""

assert set(KINDS) == set(FUNCTION_NAMES), "one table entry per function kind of the manual"


__all__ = ["KINDS", "OK", "FunctionKind", "Status", "relay_condition", "swap_status"]
