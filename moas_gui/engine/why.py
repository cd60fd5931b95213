"""Why a radio has the antennas it has: the rule that chose them, in words.

Every place in the engine that gives a radio antennas records a :class:`Why` for it
at that moment (selection by frequency, a press, the restart rule, a shared system,
a relative step, a function, the switch's own antennas after a restart).  Selection
by frequency also records, for each lower-numbered antenna it passed over, the
reason it could not have it (in use, conflicting, not covering the frequency,
transmit or receive only, ...).  The reason is kept with the radio's state and
shown in the log, in the client protocol's radio entries and in the station plan.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

STEP_SAME_BAND_TAKEN = "f1_same_band"
"""Appendix F step 1: another radio is on this band and ``ProtectSameBand`` is set."""
STEP_KEPT = "f2_kept"
"""Step 2: the current antenna covers the new frequency, contiguous with the old one."""
STEP_HISTORY = "f3_history"
"""Step 3: what this radio used last on this band."""
STEP_LOWEST = "f4_lowest"
"""Step 4: the lowest-numbered free antenna covering the frequency."""
STEP_PAIR = "f5_tx_rx_pair"
"""Step 5: a transmit-only antenna with a receive-only antenna."""
STEP_NEAREST = "f6_nearest"
"""Step 6: nothing free covers the frequency; the antenna whose range is nearest."""
STEP_NONE = "f7_none"
"""Step 7: no antenna at all."""
SAME_BAND = "same_band"
"""Same-band protection took the antennas of a radio that had some (a press, a guard)."""
PRESS = "press"
"""An operator pressed an antenna button."""
RESTART = "restart"
"""Appendix F's restart rule: a radio without a suitable antenna got one after another
radio changed antennas."""
SHARED = "shared"
"""A shared system's member that its other users have (5.10)."""
HANDOVER = "handover"
"""The antenna was taken from a radio it did not suit, for a radio changing frequency."""
MOVED = "moved"
"""Moved to another path of the same antenna to make room for another radio (5.8)."""
RELATIVE = "relative"
"""A relative step (appendix G)."""
FUNCTION = "function"
"""A function (Swap, Recall, Share, ...)."""
DIRECTION = "direction"
"""An electrical rotator's direction chose the antenna (5.15)."""
SWITCH = "switch"
"""After a restart the switch itself held these antennas (KeepSwitchAntennas)."""

RULES: tuple[str, ...] = (
    STEP_SAME_BAND_TAKEN, STEP_KEPT, STEP_HISTORY, STEP_LOWEST, STEP_PAIR, STEP_NEAREST,
    STEP_NONE, SAME_BAND, PRESS, RESTART, SHARED, HANDOVER, MOVED, RELATIVE, FUNCTION,
    DIRECTION, SWITCH,
)
"""Every ``rule`` a :class:`Why` can carry (the client protocol's ``why.rule`` values)."""

APPENDIX_F_STEPS: dict[str, int] = {
    STEP_SAME_BAND_TAKEN: 1, STEP_KEPT: 2, STEP_HISTORY: 3, STEP_LOWEST: 4, STEP_PAIR: 5,
    STEP_NEAREST: 6, STEP_NONE: 7,
}


@dataclass(frozen=True, slots=True)
class Why:
    """The reason for a radio's antennas: ``rule`` (one of :data:`RULES`), ``text`` (a short
    clause for people) and ``passed_over``: (antenna ID, reason) for each lower-numbered
    antenna selection passed over, lowest first."""

    rule: str
    text: str
    passed_over: tuple[tuple[int, str], ...] = ()

    def to_dict(self, *, full: bool = True) -> dict[str, Any]:
        """``full=False`` (what clients are told) leaves out the antennas passed over only
        because they do not cover the frequency: they decide nothing a person asks about,
        and stay in the Debug log's "passed over" line."""
        passed = self.passed_over if full else self.deciding()
        return {"rule": self.rule, "text": self.text,
                "passed_over": [{"antenna": a, "reason": r} for a, r in passed]}

    def deciding(self) -> tuple[tuple[int, str], ...]:
        """The antennas passed over for a reason other than not covering the frequency."""
        return tuple(p for p in self.passed_over if not p[1].startswith("does not cover"))

    def short(self, name: Any, limit: int = 2) -> str:
        """``text`` with a few of the antennas passed over for a deciding reason in
        brackets (``name`` maps an ID to its name); those that merely do not cover the
        frequency are left out (the Debug log's "passed over" line lists them)."""
        deciding = self.deciding()
        if not deciding:
            return self.text
        parts = [f"{name(a)} {r}" for a, r in deciding[:limit]]
        more = len(deciding) - limit
        if more > 0:
            parts.append(f"{more} more")
        return f"{self.text} ({'; '.join(parts)})"


__all__ = ["APPENDIX_F_STEPS", "RULES", "Why"]
