"""The server window's bar of holds: each radio whose antennas someone holds against
its frequency (an Antenna Genius program's ``auto=0``), who holds it and since when,
and a Release button (docs/antenna-genius.md, "Hold").  Hidden while nothing is held.

A hold outlives the program that set it; this is where the station's owner sees a
radio pinned by a program that went away, and frees it."""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime
from typing import Protocol

from .qt import QHBoxLayout, QLabel, QPushButton, Qt, QVBoxLayout, QWidget, Signal


class HeldRadio(Protocol):
    """What the bar reads of a held radio (the server's radio views are such)."""

    @property
    def station(self) -> int: ...

    @property
    def radio(self) -> int: ...

    @property
    def held_by(self) -> str | None: ...

    @property
    def held_since(self) -> float | None: ...


def since_text(seconds: float | None) -> str:
    """``since 09:14`` (this computer's clock; with the date when not today), or ""."""
    if seconds is None:
        return ""
    moment = datetime.fromtimestamp(seconds).astimezone()
    today = datetime.now().astimezone().date()
    return " since " + moment.strftime("%H:%M" if moment.date() == today else "%Y-%m-%d %H:%M")


def hold_text(view: HeldRadio) -> str:
    return (f"Station {view.station} radio {view.radio}: held by {view.held_by}"
            f"{since_text(view.held_since)}; its antennas do not follow its frequency")


class HoldsBar(QWidget):
    """One line and a Release button per held radio (see the module notes)."""

    release_requested = Signal(int, int)
    """``(station, radio)``: the user pressed that hold's Release."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("holdsBar")
        self.setStyleSheet("#holdsBar { background: #3a2a10; }"
                           "#holdsBar QLabel { color: #ffcc80; font-weight: bold; }")
        self.setAttribute(Qt.WidgetAttribute.WA_StyledBackground, True)
        self._rows = QVBoxLayout(self)
        self._rows.setContentsMargins(8, 4, 8, 4)
        self._rows.setSpacing(2)
        self.lines: list[QLabel] = []
        self.buttons: list[QPushButton] = []
        self.hide()

    def show_holds(self, holds: Sequence[HeldRadio]) -> None:
        while self._rows.count():
            item = self._rows.takeAt(0)
            row = item.widget() if item is not None else None
            if row is not None:
                row.deleteLater()
        self.lines, self.buttons = [], []
        for view in holds:
            row = QWidget(self)
            layout = QHBoxLayout(row)
            layout.setContentsMargins(0, 0, 0, 0)
            line = QLabel("\u26a0 " + hold_text(view), row)
            line.setWordWrap(True)
            button = QPushButton("Release", row)
            button.setToolTip(f"Release the hold of station {view.station} radio "
                              f"{view.radio}: its antennas follow its frequency again")
            station, radio = view.station, view.radio
            button.clicked.connect(lambda _=False, s=station, r=radio:
                                   self.release_requested.emit(s, r))
            layout.addWidget(line, 1)
            layout.addWidget(button)
            self._rows.addWidget(row)
            self.lines.append(line)
            self.buttons.append(button)
        self.setVisible(bool(holds))


__all__ = ["HeldRadio", "HoldsBar", "hold_text", "since_text"]
