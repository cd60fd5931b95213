"""Selection by frequency: appendix F, step by step.

1. Same-band protection: with ``ProtectSameBand``, a radio arriving on a band
   another radio is operating on gets no antenna (and is inhibited), unless the
   two are configured to work one band together (an Always, SameBand or
   inhibit-buss relation between them).
2. The current antenna stays while the new frequency is in the same segment
   (contiguous ranges) as the old one.
3. History: the antennas this radio used last on this band (TX and RX; if the
   pair is not free, either one alone when it can do both jobs).
4. The lowest-ID free antenna covering the frequency, skipping TX-only, RX-only
   and ``NoSelect`` antennas.
5. The lowest-ID free TX-only antenna with the lowest-ID free RX-only antenna
   that is fast with it.
6. Nothing free covers the frequency: the antenna whose range is nearest,
   starting with the current one (so 14000 -> 13999 changes nothing); the
   radio is inhibited because its antenna does not cover the frequency.
7. Nothing at all: no antenna, inhibited.

Sub and alternate receivers only receive: steps 2-7 for the receive antenna,
RX-only antennas allowed after the others in step 4.  After every operation,
:func:`recheck` re-runs steps 1 and 3-5 for every radio left without a suitable
antenna, and changes it only when something suitable was found.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from moas_gui.config.model import RadioRef

from .index import IndexedRadio, RadioKind
from .ranges import describe_khz, distance, in_segment
from .rules import (
    join_shared,
    plan,
    related,
    seen_together,
    shared_member,
    shared_users,
    unusable,
)
from .why import (
    HANDOVER,
    SAME_BAND,
    SHARED,
    STEP_HISTORY,
    STEP_KEPT,
    STEP_LOWEST,
    STEP_NEAREST,
    STEP_NONE,
    STEP_PAIR,
    STEP_SAME_BAND_TAKEN,
    Why,
)
from .work import Work

SAME_BAND_NOTE = "already on this band"


def _choices(w: Work, info: IndexedRadio, antenna: int, role: str) -> list[int]:
    """The paths of ``antenna`` this radio can use for ``role`` now, preferred first."""
    out = []
    st = w.st
    rs = st.radios[info.ref]
    for a in w.ix.group[antenna]:
        target = join_shared(w.ix, st, info.ref, a)
        if target in out:
            continue
        if unusable(w.ix, st, info, target, rs.khz, role) is None:
            out.append(target)
    return out


Reason = Why | Callable[[], Why] | None
"""A reason, or a function making it: selection tries many antennas and words only the
reason of the one it gives."""


def _took(w: Work, ref: RadioRef, losers: list[RadioRef], reason: Reason) -> Why | None:
    """The reason for antennas taken from radios they did not suit (a hand-over)."""
    why = reason() if callable(reason) else reason
    if not losers:
        return why
    names = ", ".join(str(o) for o in losers)
    base = why.text if why is not None else "selected"
    return Why(HANDOVER, f"{base}; handed over from {names}, which it does not suit",
               why.passed_over if why is not None else ())


def place(w: Work, ref: RadioRef, tx: int | None, rx: int | None, note: str = "",
          takeover: bool | None = None, why: Reason = None) -> bool:
    """Give ``ref`` the antennas ``tx``/``rx`` (any free path of them) for the reason ``why``;
    False if impossible (``w.refusal`` then says why).

    Paths that disturb nobody are preferred; only then is another radio moved to
    another path of its antenna to make room.
    """
    ix = w.ix
    info = ix.radios[ref]
    if takeover is None:
        takeover = w.takeover
    if info.kind is not RadioKind.MAIN:
        tx = None
    if tx is not None and rx is not None and ix.canon[tx] == ix.canon[rx]:
        return _place_one(w, ref, info, tx, note, takeover, why)
    return _place_two(w, ref, info, tx, rx, note, takeover, why)


def _place_one(w: Work, ref: RadioRef, info: IndexedRadio, antenna: int, note: str,
               takeover: bool, why: Reason) -> bool:
    """One antenna for both transmit and receive: the first of its paths that can be
    planned, those that move nobody first."""
    ix = w.ix
    choices = _choices(w, info, antenna, "both")
    if not choices:
        w.refusal = unusable(ix, w.st, info, antenna, w.st.radios[ref].khz, "both") or ""
    for repath in (False, True):
        for a in choices:
            p, reason = plan(ix, w.st, ref, a, takeover=takeover, repath=repath)
            if p is not None:
                w.apply_plan(p)
                w.set_pair(ref, a, a, note, _took(w, ref, p.takeovers, why))
                return True
            w.refusal = reason
    return False


def _place_two(w: Work, ref: RadioRef, info: IndexedRadio, tx: int | None, rx: int | None,
               note: str, takeover: bool, why: Reason) -> bool:
    """A transmit and a receive antenna (either may be none): the first pair of their
    paths that are fast with each other and can be planned together, those that move
    nobody first."""
    ix = w.ix
    tx_choices = _choices(w, info, tx, "tx") if tx is not None else [None]
    rx_choices = _choices(w, info, rx, "rx") if rx is not None else [None]
    for repath in (False, True):
        for t in tx_choices:
            for r in rx_choices:
                if t is not None and r is not None and not ix.is_fast(t, r):
                    continue
                first = t if t is not None else r
                if first is None:
                    continue
                also = (r,) if t is not None and r is not None else ()
                p, reason = plan(ix, w.st, ref, first, also=also, takeover=takeover,
                                 repath=repath)
                if p is not None:
                    w.apply_plan(p)
                    w.set_pair(ref, t, r, note, _took(w, ref, p.takeovers, why))
                    return True
                w.refusal = reason
    w.refusal = w.refusal or "no free path"
    return False


def band_neighbour(w: Work, ref: RadioRef) -> RadioRef | None:
    """Step 1: another radio operating on this radio's band that it may not share."""
    ix, st = w.ix, w.st
    info = ix.radios[ref]
    rs = st.radios[ref]
    if rs.khz is None:
        return None
    band = info.band(rs.khz)
    mine = info.radio
    for other in ix.mains:
        if related(ix, ref, other):
            continue
        ors = st.radios[other]
        if ors.tx is None and ors.rx is None:
            continue
        # 1.1.16: "a frequency within the range of another radio" -- its band as that radio
        # sees it, or this radio's band holding the other's frequency.
        if not (in_segment(band, ors.khz)
                or in_segment(ix.radios[other].band(ors.khz), rs.khz)):
            continue
        theirs = ix.radios[other].radio
        if seen_together(ix, ref, other) and (
                other in mine.always or ref in theirs.always or other in mine.same_band
                or ref in theirs.same_band
                or st.busses.get(ref, frozenset()) & st.busses.get(other, frozenset())):
            continue
        return other
    return None


def _keep_current(w: Work, ref: RadioRef, old_khz: float | None) -> bool:
    """Step 2.  True when the current antennas stay (perhaps with a new RX)."""
    ix = w.ix
    info = ix.radios[ref]
    rs = w.st.radios[ref]
    khz = rs.khz
    cur = rs.tx if info.kind is RadioKind.MAIN else rs.rx
    if cur is None or not in_segment(info.used_segment(cur, old_khz), khz):
        return False
    why = Why(STEP_KEPT, f"kept: it covers {describe_khz(khz)} in the range it was used in")
    if info.kind is not RadioKind.MAIN:
        w.set_pair(ref, None, cur, why=why)
        return True
    rx = rs.rx
    if rx is not None and rx != cur and info.covers(rx, khz):
        w.set_pair(ref, cur, rx, why=why)
        return True
    if ix.can_receive(cur):
        w.set_pair(ref, cur, cur, why=why)
        return True
    for r in _rx_only(w, info, khz):
        if ix.is_fast(cur, r) and place(w, ref, cur, r, why=why):
            return True
    w.set_pair(ref, cur, None, why=why)
    return True


def _rx_only(w: Work, info: IndexedRadio, khz: float | None) -> Iterable[int]:
    for a in info.covering(khz):
        ant = w.ix.antennas[a]
        if ant.rx_only and not ant.no_select and ant.enabled:
            yield a


def passed_over(w: Work, info: IndexedRadio, khz: float | None, below: int | None,
                failed: dict[int, str]) -> tuple[tuple[int, str], ...]:
    """Why each antenna of this radio numbered below ``below`` was not chosen (``failed``
    holds the reasons found while trying them).  With ``below`` None (nothing free covers
    the frequency: steps 6 and 7) only the antennas covering the frequency are listed."""
    ix = w.ix
    covering = info.covering(khz)
    out = []
    outside = ""
    for a in info.antennas if below is not None else covering:
        if below is not None and a >= below:
            break
        reason = failed.get(a)
        if reason is not None:
            reason = _short(w, a, reason)
        else:
            ant = ix.antennas[a]
            if a not in covering:
                outside = outside or f"does not cover {describe_khz(khz)}"
                reason = outside
            elif not ant.enabled:
                reason = "is not enabled"
            elif ant.no_select:
                reason = "is never selected automatically (NoSelect)"
            elif ant.tx_only:
                reason = "is transmit only"
            elif ant.rx_only:
                reason = "is receive only"
            else:
                continue
        out.append((a, reason))
    return tuple(out)


def _short(w: Work, a: int, reason: str) -> str:
    """A refusal about antenna ``a`` without its own name in front."""
    prefix = w.ix.describe(a) + " "
    return reason.removeprefix(prefix)


def _reason(w: Work, info: IndexedRadio, khz: float | None, chosen: int,
            failed: dict[int, str], rule: str, text: str) -> Callable[[], Why]:
    """The reason for giving ``chosen`` by ``rule``, worded only when it is given
    (``{khz}`` in ``text`` becomes the frequency)."""
    def make() -> Why:
        return Why(rule, text.replace("{khz}", describe_khz(khz)),
                   passed_over(w, info, khz, chosen, failed))
    return make


def _suitable_steps(w: Work, ref: RadioRef) -> bool:
    """Steps 3, 4 and 5."""
    info = w.ix.radios[ref]
    khz = w.st.radios[ref].khz
    main = info.kind is RadioKind.MAIN
    if _history_step(w, ref, info, khz, main):
        return True
    failed: dict[int, str] = {}
    w.failed = failed
    if _lowest_step(w, ref, info, khz, main, failed):
        return True
    if not main:
        return _receive_only_step(w, ref, info, khz, failed)
    return _pair_step(w, ref, info, khz, failed)


def _history_step(w: Work, ref: RadioRef, info: IndexedRadio, khz: float | None,
                  main: bool) -> bool:
    """Step 3: the antennas this radio used last on this band, as a pair; if the pair is
    not free, either one alone when it can do both jobs (a receiver: receive)."""
    ix = w.ix
    band = info.band(khz)
    remembered = w.st.history.get(ref, {}).get(band) if band is not None else None
    if remembered is None:
        return False
    htx, hrx = remembered
    def why() -> Why:
        return Why(STEP_HISTORY, f"used last by this radio on this band "
                                 f"({describe_khz(khz)})")

    if main and htx is not None and hrx is not None and place(w, ref, htx, hrx, why=why):
        return True
    for a in (htx, hrx):
        if a is None:
            continue
        if main and ix.can_transmit(a) and ix.can_receive(a) and place(w, ref, a, a,
                                                                         why=why):
            return True
        if not main and ix.can_receive(a) and place(w, ref, None, a, why=why):
            return True
    return False


def _lowest_step(w: Work, ref: RadioRef, info: IndexedRadio, khz: float | None,
                 main: bool, failed: dict[int, str]) -> bool:
    """Step 4: the lowest-numbered free antenna covering the frequency, skipping
    transmit-only, receive-only, ``NoSelect`` and disabled ones (``failed`` collects why
    each tried one was refused)."""
    for a in info.covering(khz):
        ant = w.ix.antennas[a]
        if ant.no_select or ant.tx_only or ant.rx_only or not ant.enabled:
            continue
        if place(w, ref, a if main else None, a, why=_reason(
                w, info, khz, a, failed, STEP_LOWEST,
                "lowest-numbered antenna covering {khz}")):
            return True
        failed[a] = w.refusal
    return False


def _receive_only_step(w: Work, ref: RadioRef, info: IndexedRadio, khz: float | None,
                       failed: dict[int, str]) -> bool:
    """Step 4 for a sub or alternate receiver, after the others: the lowest-numbered
    free receive-only antenna covering the frequency."""
    for a in _rx_only(w, info, khz):
        if place(w, ref, None, a, why=_reason(
                w, info, khz, a, failed, STEP_LOWEST,
                "lowest-numbered receive antenna covering {khz}")):
            return True
        failed[a] = w.refusal
    return False


def _pair_step(w: Work, ref: RadioRef, info: IndexedRadio, khz: float | None,
               failed: dict[int, str]) -> bool:
    """Step 5: the lowest-numbered free transmit-only antenna covering the frequency with
    the lowest-numbered free receive-only antenna that is fast with it."""
    ix = w.ix
    for t in info.covering(khz):
        ant = ix.antennas[t]
        if not ant.tx_only or ant.no_select or not ant.enabled:
            continue
        for r in _rx_only(w, info, khz):
            if ix.is_fast(t, r) and place(w, ref, t, r, why=_reason(
                    w, info, khz, t, failed, STEP_PAIR,
                    "lowest-numbered transmit-only antenna covering {khz}, with the "
                    "receive-only " + ix.name(r))):
                return True
        failed[t] = w.refusal or "has no free receive-only partner"
    return False


def _nearest(w: Work, ref: RadioRef) -> bool:
    """Step 6."""
    ix, st = w.ix, w.st
    info = ix.radios[ref]
    khz = st.radios[ref].khz
    if khz is None:
        return False
    found = _nearest_free(w, ref, info, khz)
    if found is None:
        return False
    best, best_d, best_joined = found
    covered = best_d == 0
    note = "" if covered else f"no free antenna covers {describe_khz(khz)}; nearest used"
    tx = best if info.kind is RadioKind.MAIN and ix.can_transmit(best) else None
    text = (f"free antenna covering {describe_khz(khz)} (found by nearest range)" if covered
            else f"no free antenna covers {describe_khz(khz)}; the nearest range")
    if best_joined:
        users = ", ".join(str(o) for o, _m in shared_users(ix, st, shared_member(ix, st, best)
                                                            or 0, ref))
        why = Why(SHARED, f"{text}: the member of a shared system that {users} already use",
                  passed_over(w, info, khz, None, w.failed))
    else:
        why = Why(STEP_NEAREST, text, passed_over(w, info, khz, None, w.failed))
    w.set_pair(ref, tx, best, note, why)
    return True


def _nearest_free(w: Work, ref: RadioRef, info: IndexedRadio, khz: float
                  ) -> tuple[int, float, bool] | None:
    """The usable antenna whose range is nearest ``khz``, the current one first (so a
    tie keeps it), as joined to a shared system the others use; with its distance and
    whether it was so joined.  None when no antenna can be had."""
    ix, st = w.ix, w.st
    rs = st.radios[ref]
    best: int | None = None
    best_joined = False
    best_d = float("inf")
    current = rs.tx if rs.tx is not None else rs.rx
    order = ([current] if current is not None else []) + [a for a in info.antennas
                                                          if a != current]
    for a in order:
        ant = ix.antennas[a]
        if not ant.enabled or ant.tx_only or (ant.no_select and a != current):
            continue
        joined = join_shared(ix, st, ref, a)
        if joined not in info.paths:
            continue
        d = distance(info.paths[joined], khz)
        if d >= best_d:
            continue
        if unusable(ix, st, info, joined, khz, "rx", nearest=True) is not None:
            continue
        if plan(ix, st, ref, joined, takeover=False, repath=False)[0] is None:
            continue
        best, best_d, best_joined = joined, d, joined != a
    if best is None:
        return None
    return best, best_d, best_joined


def select_by_frequency(w: Work, ref: RadioRef, old_khz: float | None,
                        suitable_only: bool = False) -> bool:
    """Run appendix F for ``ref`` at its current frequency; True if its antennas changed."""
    ix, st = w.ix, w.st
    info = ix.radios[ref]
    before = st.radios[ref]
    if before.khz is None:
        return False
    if info.kind is RadioKind.MAIN and ix.config.protect_same_band:
        other = band_neighbour(w, ref)
        if other is not None:
            if suitable_only:
                return False
            return w.set_pair(ref, None, None, f"{other} is {SAME_BAND_NOTE}",
                              Why(STEP_SAME_BAND_TAKEN, f"{other} is already on this band "
                                  "(ProtectSameBand)"))
    w.failed = {}
    w.restarting = suitable_only
    try:
        kept = not suitable_only and _keep_current(w, ref, old_khz) or _suitable_steps(w, ref)
    finally:
        w.restarting = False
    if kept:
        pass
    elif suitable_only:
        if before.note.endswith(SAME_BAND_NOTE):
            w.set_pair(ref, before.tx, before.rx, "no free antenna covers "
                       f"{describe_khz(before.khz)}", Why(
                           SAME_BAND, "no longer kept off the band by same-band protection, "
                           f"but no free antenna covers {describe_khz(before.khz)}",
                           passed_over(w, info, before.khz, None, w.failed)))
            return _changed(w, ref, before)
        return False
    elif not _nearest(w, ref):
        w.set_pair(ref, None, None, f"no antenna can be connected at {describe_khz(before.khz)}",
                   Why(STEP_NONE, f"no antenna can be connected at {describe_khz(before.khz)}",
                       passed_over(w, info, before.khz, None, w.failed)))
    return _changed(w, ref, before)


def _changed(w: Work, ref: RadioRef, before: object) -> bool:
    return w.st.radios[ref] != before


def unsuitable(w: Work, ref: RadioRef) -> bool:
    """Whether ``ref`` has no antenna, or one that does not cover its frequency."""
    info = w.ix.radios[ref]
    rs = w.st.radios[ref]
    if rs.khz is None:
        return False
    if info.kind is RadioKind.MAIN:
        return (rs.tx is None or not info.covers(rs.tx, rs.khz)
                or (rs.rx is not None and not info.covers(rs.rx, rs.khz)) or rs.rx is None)
    return rs.rx is None or not info.covers(rs.rx, rs.khz)


def recheck(w: Work) -> None:
    """Give radios without a suitable antenna another chance (appendix F, last paragraphs)."""
    ix = w.ix
    w.takeover = False
    for ref in list(w.pending):
        w.pending.remove(ref)
        select_by_frequency(w, ref, None)
    for _ in range(len(ix.order) + 1):
        progressed = False
        for ref in ix.order:
            if unsuitable(w, ref) and select_by_frequency(w, ref, None, suitable_only=True):
                progressed = True
            while w.pending:
                select_by_frequency(w, w.pending.pop(0), None)
                progressed = True
        if not progressed:
            break


__all__ = ["band_neighbour", "place", "recheck", "select_by_frequency", "unsuitable"]
