"""The ten functions of 5.20 and 6.6, dispatched through the table of function kinds
(``function_kinds.KINDS``), and the relays the functions hold.

Each function has a status (available now or not, with the reason in words, so a button
can show it) and an action.  Functions that toggle something (Share, Relay, Inhibit,
Extra, Partner, AltActive) also report whether they are on, which a button shows as
"selected".

Decisions where the manual is silent are in ``docs/engine.md``; in short:
Swap exchanges TX and RX antennas and needs each radio's antennas to cover the
other radio's frequency; Store keeps one memory per radio; Share, turning a
system shared, gives the first user the shared member closest in size to what
it had and lets the others join it, and turning it unshared keeps the first user
on its member and gives the others the preferred antennas first, then selects by
frequency; a Relay with a radio and antennas is switched off when the condition
stops holding and, with "S", back on when it holds again; an Extra with "Transfer"
is active only while the two radios could swap and are interlocked; AltActive toggles
the listed radios in and out of the set that switches the radio to its alternate.
"""

from __future__ import annotations

from moas_gui.config.model import Function, RadioRef

from .errors import NotFound, Unavailable
from .function_kinds import KINDS, OK, Status, relay_condition, swap_status
from .index import ConfigIndex
from .state import State
from .why import FUNCTION, Why
from .work import Work


def function(ix: ConfigIndex, function_id: int) -> Function:
    f = ix.functions.get(function_id)
    if f is None:
        raise NotFound(f"There is no function {function_id}")
    return f


def status(ix: ConfigIndex, st: State, ref: RadioRef, f: Function) -> Status:
    """Whether ``f`` can run now for the radio ``ref`` that asks."""
    kind = KINDS.get(f.name)
    if kind is None:
        return Status(False, f"function {f.id} ({f.label}) has a name the server does not "
                             f"know: {f.name!r}")
    return kind.check(ix, f) or kind.status(ix, st, ref, f)


def is_on(ix: ConfigIndex, st: State, f: Function) -> bool:
    """Whether a toggling function is on now (a button shows it selected)."""
    kind = KINDS.get(f.name)
    if kind is None or kind.is_on is None or kind.check(ix, f) is not None:
        return False
    return kind.is_on(ix, st, f)


def run(w: Work, ref: RadioRef, f: Function) -> None:
    """Run ``f`` for ``ref`` (refused with the reason when its status is not available)."""
    verdict = status(w.ix, w.st, ref, f)
    if not verdict.available:
        raise Unavailable(f"{f.label} is not available: {verdict.reason}")
    w.default_why = Why(FUNCTION, f"the {f.label} function ({f.name}) run by {ref}")
    try:
        KINDS[f.name].run(w, ref, f)
    finally:
        w.default_why = None


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


__all__ = ["OK", "Status", "extra_relays", "function", "is_on", "refresh_relays",
           "relay_condition", "relay_contributions", "run", "status", "swap_status"]
