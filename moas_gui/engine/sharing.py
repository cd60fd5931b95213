"""The Share function's work (6.6.5, 5.10): turning a shared-capable system shared or not,
and putting every radio on it back on a member it may have in the new mode."""

from __future__ import annotations

from moas_gui.config.model import RadioRef

from .rules import join_shared
from .selection import place, select_by_frequency
from .work import Work


def toggle_share(w: Work, system: int, preferred: tuple[int, ...]) -> None:
    """6.6.5.  Turning a system unshared re-places every radio on it, first come first
    served: radios that were sharing one member must not keep it together."""
    ix, st = w.ix, w.st
    on = not st.shared.get(system, False)
    st.shared[system] = on
    w.log.append(f"System {system}: {'shared' if on else 'not shared'}")
    affected = [r for r in ix.order if any(_in_system(w, system, a)
                                           for a in (st.radios[r].tx, st.radios[r].rx))]
    held = {}
    for r in affected:
        rs = st.radios[r]
        held[r] = (rs.tx, rs.rx)
        w.set_pair(r, None if _in_system(w, system, rs.tx) else rs.tx,
                   None if _in_system(w, system, rs.rx) else rs.rx, rs.note)
    for r, (tx, rx) in held.items():
        cur = next(a for a in (tx, rx) if _in_system(w, system, a))
        assert cur is not None
        if on:
            back = _back_on_shared(w, system, r, tx, rx, cur)
        else:
            back = _back_on_unshared(w, system, r, tx, rx, cur, preferred)
        if not back:
            select_by_frequency(w, r, None)


def _in_system(w: Work, system: int, a: int | None) -> bool:
    """Whether antenna ``a`` is a member of the shared-capable ``system``."""
    found = None if a is None else w.ix.systems.shared_system(w.ix.canon[a])
    return found is not None and found[0] == system


def _put(w: Work, system: int, r: RadioRef, tx: int | None, rx: int | None, a: int) -> bool:
    """``r`` back with ``a`` in place of what it had in the system."""
    return place(w, r, a if _in_system(w, system, tx) else tx,
                 a if _in_system(w, system, rx) else rx, takeover=False)


def _back_on_shared(w: Work, system: int, r: RadioRef, tx: int | None, rx: int | None,
                    cur: int) -> bool:
    """Turned shared: the member the other users already hold (that one only), else the
    member it had, then the others closest to it in size (5.10)."""
    ix = w.ix
    members = [a for a in ix.ids if ix.systems.shared_system(ix.canon[a]) == (system, True)]
    size = len(ix.comps[cur])
    members.sort(key=lambda a: (a != cur, abs(len(ix.comps[a]) - size), a))
    joined = join_shared(ix, w.st, r, cur)
    if joined != cur:
        members = [joined]
    return any(_put(w, system, r, tx, rx, m) for m in members)


def _back_on_unshared(w: Work, system: int, r: RadioRef, tx: int | None, rx: int | None,
                      cur: int, preferred: tuple[int, ...]) -> bool:
    """Turned unshared: the member it had when that may be used unshared, else the first
    free antenna of ``preferred``."""
    ix = w.ix
    if ix.systems.usable(ix.canon[cur], w.st.shared) and _put(w, system, r, tx, rx, cur):
        return True
    return any(place(w, r, a, a, takeover=False) for a in preferred if a in ix.antennas)


__all__ = ["toggle_share"]
