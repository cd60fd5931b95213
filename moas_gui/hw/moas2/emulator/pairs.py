"""The switch's two triangular 64x64 tables (conflicts, fast transitions).

A pair of antennas is one bit, the same whichever way round it is asked, so
each table is 64 row bitmasks kept symmetric.
"""

from __future__ import annotations

from collections.abc import Iterable

_ALL = (1 << 64) - 1


class PairTable:
    """One symmetric 64x64 table of booleans, all False to start."""

    __slots__ = ("_rows",)

    def __init__(self) -> None:
        self._rows = [0] * 64

    def fill(self, value: bool) -> None:
        """Set every pair (including each antenna with itself) to ``value``."""
        self._rows = [_ALL if value else 0] * 64

    def set(self, a: int, b: int, value: bool) -> None:
        """Set the pair ``a``-``b`` (and ``b``-``a``)."""
        if value:
            self._rows[a] |= 1 << b
            self._rows[b] |= 1 << a
        else:
            self._rows[a] &= ~(1 << b)
            self._rows[b] &= ~(1 << a)

    def set_many(self, pairs: Iterable[tuple[int, int]], value: bool) -> None:
        for a, b in pairs:
            self.set(a, b, value)

    def get(self, a: int, b: int) -> bool:
        return bool(self._rows[a] >> b & 1)

    def row(self, a: int) -> int:
        """Bitmask of the antennas paired with ``a``."""
        return self._rows[a]

    def pairs(self) -> frozenset[tuple[int, int]]:
        """Every set pair as ``(low, high)``."""
        return frozenset(
            (a, b) for a in range(64) for b in range(a, 64) if self._rows[a] >> b & 1
        )


__all__ = ["PairTable"]
