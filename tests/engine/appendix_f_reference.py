"""A small reference implementation of appendix F of the MOAS II manual ("Antenna Selection
Algorithm"), written from the manual's text alone, for a differential test of the engine.

It knows only what the appendix needs: radios that transmit and receive, antennas with
frequency ranges per radio, conflicts (an antenna conflicts with itself and with what it
lists), transmit-only and receive-only antennas, and ``ProtectSameBand``.  Ranges of the
stations it is given are whole amateur bands, so "the band" and "the range that was being
used" are simply the range holding a frequency.  The manual's sentences are quoted where
each rule is applied.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

Range = tuple[float, float]


@dataclass(frozen=True)
class RefAntenna:
    id: int
    ranges: dict[tuple[int, int], tuple[Range, ...]]
    """(station, radio) -> the ranges in which that radio can use the antenna."""
    conflicts: frozenset[int]
    tx_only: bool = False
    rx_only: bool = False


@dataclass
class RefRadio:
    ref: tuple[int, int]
    khz: float | None = None
    tx: int | None = None
    rx: int | None = None
    history: dict[Range, tuple[int | None, int | None]] = field(default_factory=dict)
    blocked: bool = False
    """Stopped by step 1 (same band)."""
    rule: str = ""
    """Which rule gave the radio its antennas last (the engine's ``why.rule`` names)."""
    took: bool = False
    """The last antennas were taken from a radio they did not suit."""


class AppendixF:
    def __init__(self, antennas: Sequence[RefAntenna], radios: Sequence[tuple[int, int]],
                 protect_same_band: bool) -> None:
        self.ants = {a.id: a for a in sorted(antennas, key=lambda a: a.id)}
        self.radios = {r: RefRadio(r) for r in sorted(radios)}
        self.protect = protect_same_band

    # -- facts -------------------------------------------------------------------------------
    def ranges(self, r: tuple[int, int], a: int) -> tuple[Range, ...]:
        return self.ants[a].ranges.get(r, ())

    def range_at(self, r: tuple[int, int], a: int, khz: float | None) -> Range | None:
        if khz is None:
            return None
        for lo, hi in self.ranges(r, a):
            if lo <= khz <= hi:
                return (lo, hi)
        return None

    def covers(self, r: tuple[int, int], a: int | None, khz: float | None) -> bool:
        return a is not None and self.range_at(r, a, khz) is not None

    def distance(self, r: tuple[int, int], a: int, khz: float) -> float:
        return min((max(lo - khz, khz - hi, 0.0) for lo, hi in self.ranges(r, a)),
                   default=float("inf"))

    def band(self, r: tuple[int, int], khz: float) -> Range | None:
        for a in self.ants:
            found = self.range_at(r, a, khz)
            if found is not None:
                return found
        return None

    def conflict(self, a: int, b: int) -> bool:
        return b in self.ants[a].conflicts or a in self.ants[b].conflicts

    def available(self, r: tuple[int, int], antennas: Sequence[int], takeover: bool
                  ) -> tuple[bool, list[tuple[int, int]]]:
        """Whether ``r`` may use ``antennas``; with ``takeover``, radios holding a conflicting
        antenna that does not cover their own frequency lose it ("the antenna will be selected
        by the other radio")."""
        losers = []
        for o, rs in self.radios.items():
            if o == r:
                continue
            held = [x for x in (rs.tx, rs.rx) if x is not None]
            if any(self.conflict(a, b) for a in antennas for b in held):
                if takeover and all(not self.covers(o, b, rs.khz) for b in held):
                    losers.append(o)
                    continue
                return False, []
        return True, losers

    # -- the steps ---------------------------------------------------------------------------
    def _use(self, r: tuple[int, int], tx: int | None, rx: int | None, takeover: bool) -> bool:
        wanted = [a for a in (tx, rx) if a is not None]
        ok, losers = self.available(r, wanted, takeover)
        if not ok:
            return False
        rs = self.radios[r]
        rs.tx, rs.rx = tx, rx
        rs.took = bool(losers)
        # "a different antenna will be chosen for the radio that originally had the
        # antenna": every radio taken from has lost its antenna at once.
        for o in losers:
            self.radios[o].tx = self.radios[o].rx = None
        for o in losers:
            self._select(o, None, takeover=False)
        return True

    def _same_band(self, r: tuple[int, int]) -> bool:
        """Step 1: "If there is another station on the band and the same band operation is
        not allowed use no antennas and inhibit transmit."""
        rs = self.radios[r]
        if not self.protect or rs.khz is None:
            return False
        band = self.band(r, rs.khz)
        for o, other in self.radios.items():
            if o == r or (other.tx is None and other.rx is None) or other.khz is None:
                continue
            # 1.1.16: "if a radio switches to a frequency within the range of another radio"
            theirs = self.band(o, other.khz)
            if band is not None and band[0] <= other.khz <= band[1] or \
                    theirs is not None and theirs[0] <= rs.khz <= theirs[1]:
                return True
        return False

    def _suitable(self, r: tuple[int, int], takeover: bool) -> bool:
        """Steps 3, 4 and 5."""
        rs = self.radios[r]
        khz = rs.khz
        assert khz is not None
        # Step 3: "Check the history to see if an antenna was previously used for this
        # frequency range. If an antenna is found and available use it."  And: "If ... the
        # history shows that different transmit and receive antennas were used it will try to
        # use them again. If one or the other is not available it will try to use the
        # remaining antenna if it is suitable."
        band = self.band(r, khz)
        found = rs.history.get(band) if band is not None else None
        if found is not None:
            htx, hrx = found
            if htx is not None and hrx is not None and self._use(r, htx, hrx, takeover):
                return self._rule(r, "f3_history")
            for a in (htx, hrx):
                if a is not None and not self.ants[a].tx_only and not self.ants[a].rx_only \
                        and self.covers(r, a, khz) and self._use(r, a, a, takeover):
                    return self._rule(r, "f3_history")
        # Step 4: "Starting with the lowest numbered antenna in the configuration check each
        # to see if it covers the frequency and is available. If so, use it. This check
        # ignores antennas which are transmit-only or receive-only."
        for a, ant in self.ants.items():
            if ant.tx_only or ant.rx_only or not self.covers(r, a, khz):
                continue
            if self._use(r, a, a, takeover):
                return self._rule(r, "f4_lowest")
        # Step 5: "check each to see if it is transmit-only. If so and it covers the frequency
        # and is available check each receive-only antenna starting with the lowest numbered
        # to see if it covers the frequency and is available. If so use them."
        for t, ant in self.ants.items():
            if not ant.tx_only or not self.covers(r, t, khz):
                continue
            for x, other in self.ants.items():
                if other.rx_only and self.covers(r, x, khz) and self._use(r, t, x, takeover):
                    return self._rule(r, "f5_tx_rx_pair")
        return False

    def _rule(self, r: tuple[int, int], rule: str) -> bool:
        """Record the rule that gave ``r`` its antennas (a hand-over when it took them)."""
        rs = self.radios[r]
        rs.rule = "handover" if rs.took else rule
        rs.took = False
        return True

    def _select(self, r: tuple[int, int], old_khz: float | None, takeover: bool) -> None:
        rs = self.radios[r]
        khz = rs.khz
        assert khz is not None
        rs.blocked = False
        if self._same_band(r):
            rs.tx = rs.rx = None
            rs.blocked = True
            rs.rule = "f1_same_band"
            return
        # Step 2: "If the current antenna covers a frequency range which includes the current
        # frequency and is contiguous to the range that was being used, continue to use the
        # current antenna." -- "the case where an operator has tuned beyond the band edge and
        # then tunes back into the band": the range being used is the one nearest the old
        # frequency when the old frequency was beyond it.
        cur = rs.tx
        if cur is not None and old_khz is not None:
            used = min(self.ranges(r, cur), key=lambda rg: max(rg[0] - old_khz, old_khz - rg[1],
                                                                0.0), default=None)
            if used is not None and used[0] <= khz <= used[1]:
                rs.rule = "f2_kept"
                if rs.rx is not None and rs.rx != cur and self.covers(r, rs.rx, khz):
                    return self._remember(r)
                if not self.ants[cur].tx_only:
                    rs.rx = cur
                    return self._remember(r)
                for x, ant in self.ants.items():
                    if ant.rx_only and self.covers(r, x, khz) and self._use(r, cur, x, False):
                        return self._remember(r)
                rs.rx = None
                return None
        if self._suitable(r, takeover):
            return self._remember(r)
        # Step 6: "No antenna which covers the frequency range is available. Find the antenna
        # which has a range closest to the radio's frequency. Start this check using the
        # current antenna."
        current = rs.tx if rs.tx is not None else rs.rx
        order = ([current] if current is not None else []) + \
            [a for a in self.ants if a != current]
        best, best_d = None, float("inf")
        for a in order:
            if self.ants[a].tx_only or not self.ranges(r, a):
                continue
            d = self.distance(r, a, khz)
            if d < best_d and self.available(r, [a], False)[0]:
                best, best_d = a, d
        if best is not None:
            rs.tx = None if self.ants[best].rx_only else best
            rs.rx = best
            rs.rule = "f6_nearest"
            return self._remember(r)
        # Step 7: "If no antenna at all can be found don't connect the radio to any antenna."
        rs.tx = rs.rx = None
        rs.rule = "f7_none"
        return None

    def _remember(self, r: tuple[int, int]) -> None:
        rs = self.radios[r]
        band = self.band(r, rs.khz) if rs.khz is not None else None
        if band is not None and self.covers(r, rs.tx, rs.khz) and (
                rs.rx is None or self.covers(r, rs.rx, rs.khz)):
            rs.history[band] = (rs.tx, rs.rx)

    def _unsuitable(self, r: tuple[int, int]) -> bool:
        rs = self.radios[r]
        return rs.khz is not None and not (self.covers(r, rs.tx, rs.khz)
                                           and self.covers(r, rs.rx, rs.khz))

    def _restart(self) -> None:
        """ "Whenever a radio changes antennas a check is made for radios that have antennas
        that do not cover their frequency or that have no antenna. If one is found the antenna
        selection is restarted for that radio in case a suitable antenna is now available. If
        no suitable antenna is available the antenna will not be changed." """
        for _ in range(len(self.radios) + 1):
            changed = False
            for r, rs in self.radios.items():
                if not self._unsuitable(r) or self._same_band(r):
                    continue
                before = (rs.tx, rs.rx)
                if self._suitable(r, takeover=False):
                    rs.blocked = False
                    rs.rule = "restart"
                    self._remember(r)
                    changed = changed or (rs.tx, rs.rx) != before
                else:
                    rs.tx, rs.rx = before
                    if rs.blocked:
                        # the band is free of the other radio, but nothing suitable is
                        rs.rule = "same_band"
                        rs.blocked = False
            if not changed:
                return

    # -- the event ---------------------------------------------------------------------------
    def set_frequency(self, r: tuple[int, int], khz: float) -> None:
        rs = self.radios[r]
        old = rs.khz
        rs.khz = khz
        self._select(r, old, takeover=True)
        self._restart()

    def pairs(self) -> dict[tuple[int, int], tuple[int | None, int | None]]:
        return {r: (rs.tx, rs.rx) for r, rs in self.radios.items()}

    def rules(self) -> dict[tuple[int, int], str]:
        """The rule that decided each radio's antennas last ("" before its first report)."""
        return {r: rs.rule for r, rs in self.radios.items()}

    def inhibited(self, r: tuple[int, int]) -> bool:
        """Steps 1, 6 and 7: "inhibit transmit"."""
        rs = self.radios[r]
        return rs.khz is not None and not self.covers(r, rs.tx, rs.khz)


__all__ = ["AppendixF", "RefAntenna"]
