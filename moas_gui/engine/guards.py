"""Checks after an operation that may refuse it (or, for a frequency report, re-select the
reporting radio): rules that hold between radios rather than for one selection."""

from __future__ import annotations

from .errors import Unavailable
from .index import RadioKind
from .rules import unpermitted
from .selection import band_neighbour, select_by_frequency
from .work import Work, radio_name


def same_band_guard(w: Work) -> None:
    """1.1.16: with ``ProtectSameBand`` a radio on another radio's band "will not be connected
    to an antenna", so a press (or function, relative step, direction) connecting one there is
    refused like any other unavailable antenna."""
    ix = w.ix
    if not ix.config.protect_same_band:
        return
    for ref in sorted(w.touched):
        rs = w.st.radios[ref]
        if ix.radios[ref].kind is not RadioKind.MAIN or (rs.tx is None and rs.rx is None):
            continue
        other = band_neighbour(w, ref)
        if other is not None:
            raise Unavailable(f"{other} is already on this band ({radio_name(ref)} may not "
                              "join it: ProtectSameBand)")


def interlock_guard(w: Work, refuse: bool) -> None:
    """5.12: conflicting transmit antennas are shared only by radios that inhibit each other.
    An operator's request that ends an interlock while two radios share such antennas is
    refused; a frequency report that does so (a ``SameBand`` interlock left behind) gives the
    reporting radio other antennas."""
    ix, st = w.ix, w.st
    for _ in range(len(ix.order) + 1):
        bad = unpermitted(ix, st)
        if not bad:
            return
        a, b, x, y = bad[0]
        if refuse:
            raise Unavailable(f"{a} on {ix.describe(x)} and {b} on {ix.describe(y)} share "
                              "conflicting antennas only while each inhibits the other")
        victim = a if a == w.reported or ix.radios[a].main == w.reported else b
        rs = st.radios[victim]
        w.set_pair(victim, None, None, rs.note)
        select_by_frequency(w, victim, None)
    raise Unavailable("conflicting antennas could not be resolved")


__all__ = ["interlock_guard", "same_band_guard"]
