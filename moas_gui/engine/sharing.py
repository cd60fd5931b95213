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


__all__ = ["toggle_share"]
