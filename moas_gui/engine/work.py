"""One operation in progress: the cloned state, and what it changed so far."""

from __future__ import annotations

from moas_gui.config.model import RadioRef

from .index import ConfigIndex, RadioKind
from .rules import UsePlan
from .state import State
from .why import HANDOVER, MOVED, RESTART, Why

_RESTARTED = frozenset({"f3_history", "f4_lowest", "f5_tx_rx_pair"})


def radio_name(ref: RadioRef) -> str:
    return f"Station {ref.station} radio {ref.radio}"


class Work:
    """The state an operation edits, plus its log lines and the radios it touched."""

    def __init__(self, ix: ConfigIndex, st: State) -> None:
        self.ix = ix
        self.st = st
        self.log: list[str] = []
        self.details: list[str] = []
        """Debug-level sentences: what each decision passed over."""
        self.touched: set[RadioRef] = set()
        """Radios whose antennas changed in this operation."""
        self.pending: list[RadioRef] = []
        """Radios that lost an antenna to a takeover and must be selected again."""
        self.reported: RadioRef | None = None
        """The radio whose frequency report this operation is."""
        self.takeover = False
        """Whether selection may take an antenna from a radio it does not suit: only for the
        radio whose frequency changed (appendix F: "if another radio changes frequency and
        the antenna is the best choice for it"), never for presses or the restart rule."""
        self.default_why: Why | None = None
        """The reason recorded for antennas given without one of their own (a function)."""
        self.restarting = False
        """Selection runs for appendix F's restart rule (the reason says so)."""
        self.failed: dict[int, str] = {}
        """Antennas selection by frequency tried and could not have, with the reason."""
        self.refusal = ""
        """Why the last :func:`~.selection.place` that failed could not give the antennas."""

    def set_pair(self, ref: RadioRef, tx: int | None, rx: int | None, note: str = "",
                 why: Why | None = None) -> bool:
        """Give ``ref`` these antennas for the reason ``why``; True when anything changed."""
        rs = self.st.radios[ref]
        info = self.ix.radios[ref]
        if info.kind is not RadioKind.MAIN:
            tx = None
        if why is None:
            why = self.default_why
        elif self.restarting and why.rule in _RESTARTED:
            why = Why(RESTART, f"{why.text}, once another radio's change freed it",
                      why.passed_over)
        if why is not None:
            self.st.why[ref] = why
        if rs.tx == tx and rs.rx == rx and rs.note == note:
            if self.reported is not None:
                self.remember(ref)
            return False
        moved = rs.tx != tx or rs.rx != rx
        self.st.radios[ref] = rs.with_(tx=tx, rx=rx, note=note)
        if moved:
            self.touched.add(ref)
            self.log.append(self.describe(ref))
            if why is not None and why.passed_over:
                self.details.append(f"{radio_name(ref)} passed over: " + "; ".join(
                    f"{self.ix.name(a)} {r}" for a, r in why.passed_over))
        self.remember(ref)
        return True

    def remember(self, ref: RadioRef) -> None:
        """Appendix F step 3: note what this radio uses on this band."""
        rs = self.st.radios[ref]
        info = self.ix.radios[ref]
        band = info.band(rs.khz)
        if band is None:
            return
        if info.kind is RadioKind.MAIN:
            if rs.tx is None or not info.covers(rs.tx, rs.khz):
                return
            if rs.rx is not None and not info.covers(rs.rx, rs.khz):
                return
        elif rs.rx is None or not info.covers(rs.rx, rs.khz):
            return
        self.st.remember(ref, band, (rs.tx, rs.rx))

    def describe(self, ref: RadioRef) -> str:
        """One line for the log: the radio, its antennas, and why."""
        rs = self.st.radios[ref]
        ix = self.ix
        if self.ix.radios[ref].kind is not RadioKind.MAIN:
            text = f"{radio_name(ref)}: RX {ix.name(rs.rx)}"
        elif rs.tx == rs.rx:
            text = f"{radio_name(ref)}: {ix.name(rs.tx) if rs.tx is not None else 'no antenna'}"
        else:
            text = f"{radio_name(ref)}: TX {ix.name(rs.tx)}, RX {ix.name(rs.rx)}"
        why = self.st.why.get(ref)
        if why is not None:
            text += f" \u2014 {why.short(ix.name)}"
        elif rs.note:
            text += f" ({rs.note})"
        return text

    def apply_plan(self, p: UsePlan) -> None:
        """Move blocking radios to other paths, and take antennas from radios they do not suit."""
        for (other, role), antenna in p.moves.items():
            rs = self.st.radios[other]
            why = Why(MOVED, f"moved to another path of {self.ix.name(antenna)} to make "
                             "room for another radio")
            if rs.tx == rs.rx:
                self.set_pair(other, antenna, antenna, rs.note, why)
            elif role == "tx":
                self.set_pair(other, antenna, rs.rx, rs.note, why)
            else:
                self.set_pair(other, rs.tx, antenna, rs.note, why)
            self.log.append(f"{radio_name(other)} moved to another path of the same antenna "
                            f"({self.ix.name(antenna)}) to make room")
        for other in p.takeovers:
            rs = self.st.radios[other]
            if self.set_pair(other, None, None, "its antenna was taken by a radio it suits",
                             Why(HANDOVER, "its antenna went to a radio changing frequency, "
                                           "which it suits better")):
                self.pending.append(other)


__all__ = ["Work", "radio_name"]
