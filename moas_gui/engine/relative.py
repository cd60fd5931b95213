"""Relative antennas (5.19, 6.8, appendix G): next, previous, or by position.

The list for a radio is the ``RelativeAntennas`` group naming that station and
radio (a group naming the radio beats one naming only the station, which beats
one for everybody), and in it the entry whose range holds the radio's
frequency.  The receive antenna is the transmit antenna unless the entry has
``RXIDs``.  Next/previous treat the list as circular: find the radio's
transmit antenna in the list, scanning from the last relative position in the
direction asked; then take the following available entry.  With no current
position (first use, or the radio changed to another list) start at the
beginning.  A transmit antenna not in the list leaves the position alone.
"""

from __future__ import annotations

from moas_gui.config.model import RadioRef, RelativeRange

from .errors import BadRequest, NotFound, Unavailable
from .index import ConfigIndex
from .ranges import describe_khz
from .selection import place
from .why import RELATIVE, Why
from .work import Work, radio_name


def relative_list(ix: ConfigIndex, ref: RadioRef, khz: float | None
                  ) -> tuple[tuple[int, int], RelativeRange] | None:
    best: tuple[int, int] | None = None
    for gi, group in enumerate(ix.config.relative_antennas):
        if group.station is not None and group.station != ref.station:
            continue
        if group.radio is not None and group.radio != ref.radio:
            continue
        score = (group.radio is not None) * 2 + (group.station is not None)
        if best is None or score > best[0]:
            best = (score, gi)
    if best is None:
        return None
    gi = best[1]
    for ri, entry in enumerate(ix.config.relative_antennas[gi].antennas):
        if (khz is None and entry.range.unbounded) or (khz is not None
                                                       and entry.range.contains(khz)):
            return (gi, ri), entry
    return None


def _pair(entry: RelativeRange, i: int) -> tuple[int, int]:
    tx = entry.ids[i]
    rx = entry.rx_ids[i] if entry.rx_ids is not None and i < len(entry.rx_ids) else tx
    return tx, rx


def relative(w: Work, ref: RadioRef, step: int | None, index: int | None) -> None:
    ix, st = w.ix, w.st
    if (step is None) == (index is None):
        raise BadRequest("give either step (+1 or -1) or index, not both or neither")
    if step is not None and step not in (1, -1):
        raise BadRequest(f"step must be +1 or -1 (not {step})")
    rs = st.radios[ref]
    found = relative_list(ix, ref, rs.khz)
    if found is None:
        raise Unavailable(f"There are no relative antennas for {ref} at {describe_khz(rs.khz)}")
    key, entry = found
    n = len(entry.ids)
    if n == 0:
        raise Unavailable(f"The relative antenna list for {ref} is empty")
    if index is not None:
        _by_position(w, ref, key, entry, index)
        return
    assert step is not None
    pos = _position(w, ref, key, entry, step)
    order = [0] + [(k * step) % n for k in range(1, n)] if pos is None else [
        (pos + k * step) % n for k in range(1, n + 1)]
    for j in order:
        tx, rx = _pair(entry, j)
        if tx in ix.antennas and (rx in ix.antennas) and place(w, ref, tx, rx,
                                                               why=_why(entry, j, rs.khz)):
            _mark(w, ref, key, j)
            return
    raise Unavailable(f"No other relative antenna can be used by {ref} now")


def _by_position(w: Work, ref: RadioRef, key: tuple[int, int], entry: RelativeRange,
                 index: int) -> None:
    """The entry at ``index`` of the list, or a refusal saying why not."""
    ix = w.ix
    n = len(entry.ids)
    if not 0 <= index < n:
        raise NotFound(f"There is no relative antenna {index} for {ref}: the list has {n}")
    tx, rx = _pair(entry, index)
    if tx not in ix.antennas or not place(w, ref, tx, rx,
                                          why=_why(entry, index, w.st.radios[ref].khz)):
        raise Unavailable(f"Relative antenna {index} ({ix.name(tx)}) cannot be used by "
                          f"{ref} now")
    _mark(w, ref, key, index)


def _position(w: Work, ref: RadioRef, key: tuple[int, int], entry: RelativeRange,
              step: int) -> int | None:
    """Where the radio is in the list: its transmit antenna's entry, scanning from the
    last relative position in the direction asked; the last position when the transmit
    antenna is not in the list; None with no position in this list."""
    ix = w.ix
    rs = w.st.radios[ref]
    n = len(entry.ids)
    pos = rs.rel_pos if rs.rel_key == key else None
    if rs.tx is not None:
        start = pos if pos is not None else 0
        for k in range(n):
            j = (start + k * step) % n
            if entry.ids[j] in ix.antennas and ix.canon[entry.ids[j]] == ix.canon[rs.tx]:
                return j
    return pos


def _why(entry: RelativeRange, i: int, khz: float | None) -> Why:
    return Why(RELATIVE, f"relative antenna {i + 1} of {len(entry.ids)} for "
                         f"{describe_khz(khz)}")


def _mark(w: Work, ref: RadioRef, key: tuple[int, int], pos: int) -> None:
    rs = w.st.radios[ref]
    w.st.radios[ref] = rs.with_(rel_pos=pos, rel_key=key)
    if not w.log or not w.log[-1].startswith(radio_name(ref)):
        w.log.append(w.describe(ref))


__all__ = ["relative", "relative_list"]
