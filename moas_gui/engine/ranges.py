"""Frequency ranges as the selection rules use them.

A *path* is what connects one radio to one antenna in one frequency range: the
relays of that range for that radio.  An antenna's ranges that touch or overlap
(a gap of at most :data:`CONTIGUOUS_GAP_KHZ`) form one *segment*: moving within
a segment keeps the antenna (appendix F step 2).  A radio's *band* at a
frequency is the narrowest segment, among all antennas it can use, that holds
the frequency; history (step 3) and same-band rules are keyed by it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

INF = float("inf")
CONTIGUOUS_GAP_KHZ = 1.0
"""Ranges closer than this (in kHz) are contiguous: 1800-1850 and 1850.5-2000 are one."""

Segment = tuple[float, float]
"""A closed interval in kHz; unbounded sides are -inf / inf."""

ALL_SPECTRUM: Segment = (-INF, INF)


@dataclass(frozen=True, slots=True)
class RangeRelays:
    """The relays that connect one radio to one antenna within one range (global numbers)."""

    lower: float
    upper: float
    relays: frozenset[int]
    rx_relays: frozenset[int]
    persistent: frozenset[int]
    radio_rx_antenna: bool = False
    """The antenna reaches the radio through its separate RX-antenna input (6.4)."""

    @property
    def unbounded(self) -> bool:
        return self.lower == -INF and self.upper == INF

    def contains(self, khz: float) -> bool:
        return self.lower <= khz <= self.upper

    def distance(self, khz: float) -> float:
        if khz < self.lower:
            return self.lower - khz
        if khz > self.upper:
            return khz - self.upper
        return 0.0


def range_relays_at(paths: Sequence[RangeRelays], khz: float | None) -> RangeRelays | None:
    """The range relays whose range holds ``khz``; with no frequency, an unbounded one."""
    if khz is None:
        for p in paths:
            if p.unbounded:
                return p
        return None
    for p in paths:
        if p.lower <= khz <= p.upper:
            return p
    return None


def nearest_range_relays(paths: Sequence[RangeRelays], khz: float | None) -> RangeRelays | None:
    """The range relays holding ``khz``, else those whose range is closest to it."""
    found = range_relays_at(paths, khz)
    if found is not None or not paths:
        return found
    if khz is None:
        return paths[0]
    return min(paths, key=lambda p: p.distance(khz))


def distance(paths: Sequence[RangeRelays], khz: float) -> float:
    return min((p.distance(khz) for p in paths), default=INF)


def merge_segments(ranges: Iterable[Segment]) -> tuple[Segment, ...]:
    """Join ranges that overlap or are at most :data:`CONTIGUOUS_GAP_KHZ` apart."""
    out: list[list[float]] = []
    for lo, hi in sorted(ranges):
        if out and lo <= out[-1][1] + CONTIGUOUS_GAP_KHZ:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return tuple((lo, hi) for lo, hi in out)


def segment_at(segments: Sequence[Segment], khz: float | None) -> Segment | None:
    if khz is None:
        return ALL_SPECTRUM if ALL_SPECTRUM in segments else None
    for seg in segments:
        if seg[0] <= khz <= seg[1]:
            return seg
    return None


def in_segment(seg: Segment | None, khz: float | None) -> bool:
    return seg is not None and khz is not None and seg[0] <= khz <= seg[1]


def bound(value: float | None, default: float) -> float:
    return default if value is None else float(value)


def describe_khz(khz: float | None) -> str:
    if khz is None:
        return "an unknown frequency"
    return f"{khz:g} kHz"


__all__ = ["ALL_SPECTRUM", "CONTIGUOUS_GAP_KHZ", "INF", "RangeRelays", "Segment", "bound",
           "describe_khz", "distance", "in_segment", "merge_segments", "nearest_range_relays",
           "range_relays_at", "segment_at"]
