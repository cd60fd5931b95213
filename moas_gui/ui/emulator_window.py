"""The MOAS II emulator's window: what the emulated box holds, at a glance.

It shows the 64 relays in eight groups of eight (as the box's connectors
are), each station's antennas, transmit/receive and inhibit state, a TX box
per station to key it as its radio would, and a log of the bytes received
and sent.  It holds no state of its own: it redraws from the box's
:meth:`~moas_gui.hw.moas2.emulator.box.EmulatedBox.view` whenever the box
says something changed.  The server opens the same widget for a switch whose
port is ``"emulator"``.
"""

from __future__ import annotations

import time

from PySide6.QtCore import QTimer, Signal
from PySide6.QtGui import QCloseEvent, QFontDatabase
from PySide6.QtWidgets import (
    QCheckBox,
    QFrame,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPlainTextEdit,
    QScrollArea,
    QStyle,
    QVBoxLayout,
    QWidget,
)

from ..hw.moas2.emulator.box import EmulatedBox, Traffic
from ..hw.moas2.emulator.view import BoxView, StationView
from .screen_fit import fit_to_screen

_ON = "background:#2e9e44; color:white; border:1px solid #1d6b2c; border-radius:3px;"
_OFF = "background:#d8d8d8; color:#555; border:1px solid #aaa; border-radius:3px;"
_INHIBIT = "color:#b00020; font-weight:bold;"
_PLAIN = ""

_COLUMNS = ("Station", "Key", "State", "TX", "RX", "Alt", "Extra", "Inhibit", "Mode", "Waiting")


def _antenna(slot_antenna: int, relays: frozenset[int]) -> str:
    name = "none" if slot_antenna == 63 else str(slot_antenna)
    return f"{name} [{', '.join(map(str, sorted(relays)))}]" if relays else name


def _state(st: StationView) -> str:
    if st.transmitting:
        word = "TX"
    elif st.on_alternate:
        word = "RX alt"
    else:
        word = "RX"
    return word if st.phase.value in ("receive", "transmit") else f"{word} ({st.phase.value})"


def _inhibit(st: StationView) -> str:
    if not st.inhibited:
        return "no"
    reasons = []
    if st.inhibited_by_command:
        reasons.append("command")
    if st.inhibited_by:
        reasons.append("by " + ",".join(map(str, sorted(st.inhibited_by))))
    if st.phase.value in ("slow", "interrupt"):
        reasons.append(st.phase.value)
    return "yes: " + ", ".join(reasons)


PING = b"';"
"""The once-a-second ping of the server, as the box receives it."""


class EmulatorWindow(QWidget):
    """A window on one :class:`EmulatedBox`."""

    closed = Signal()

    def __init__(self, box: EmulatedBox, *, port: str = "", parent: QWidget | None = None):
        super().__init__(parent)
        self.box = box
        self.setWindowTitle(f"MOAS II emulator — {port}" if port else "MOAS II emulator")
        self._refresh_queued = False
        self.relay_labels: list[QLabel] = []
        self.key_boxes: dict[int, QCheckBox] = {}
        self.station_cells: dict[int, dict[str, QLabel]] = {}

        layout = QVBoxLayout(self)
        self.header = QLabel()
        self.header.setWordWrap(True)
        layout.addWidget(self.header)
        # relays and stations scroll on a small screen instead of widening the window
        panels = QWidget()
        inner = QVBoxLayout(panels)
        inner.setContentsMargins(0, 0, 0, 0)
        inner.addWidget(self._build_relays())
        inner.addWidget(self._build_stations())
        self.scroll_area = QScrollArea()
        self.scroll_area.setWidgetResizable(True)
        self.scroll_area.setFrameShape(QFrame.Shape.NoFrame)
        self.scroll_area.setWidget(panels)
        self.scroll_area.setMinimumSize(420, 240)
        layout.addWidget(self.scroll_area, 2)
        self.log = QPlainTextEdit()
        self.log.setReadOnly(True)
        self.log.setMaximumBlockCount(2000)
        self.log.setFont(QFontDatabase.systemFont(QFontDatabase.SystemFont.FixedFont))
        above_log = QHBoxLayout()
        above_log.addWidget(QLabel("Bytes received (in) and sent (out):"), 1)
        self.show_pings = QCheckBox("Show pings")
        self.show_pings.setToolTip("The server pings once a second; its pings and their "
                                   "answers are left out of the log unless this is ticked")
        above_log.addWidget(self.show_pings)
        layout.addLayout(above_log)
        self._answering_ping = False
        layout.addWidget(self.log, 1)

        self._stop_listening = box.add_listener(self._on_box)
        self.refresh()
        # wide enough for all 64 relays where the screen allows; else they scroll
        margins = layout.contentsMargins()
        bar = self.style().pixelMetric(QStyle.PixelMetric.PM_ScrollBarExtent)
        wanted = panels.sizeHint().width() + margins.left() + margins.right() + bar
        fit_to_screen(self, max(wanted, self.sizeHint().width()),
                      max(620, self.sizeHint().height()))

    # ------------------------------------------------------------------ building

    def _build_relays(self) -> QWidget:
        outer = QGroupBox("Relays")
        row = QHBoxLayout(outer)
        for group in range(8):
            box = QGroupBox(f"{group * 8}-{group * 8 + 7}")
            grid = QGridLayout(box)
            grid.setSpacing(2)
            for i in range(8):
                relay = group * 8 + i
                label = QLabel(str(relay))
                label.setMinimumWidth(22)
                label.setStyleSheet(_OFF)
                label.setToolTip(f"relay {relay}")
                grid.addWidget(label, i // 4, i % 4)
                self.relay_labels.append(label)
            row.addWidget(box)
        return outer

    def _build_stations(self) -> QWidget:
        outer = QGroupBox("Stations")
        grid = QGridLayout(outer)
        for column, title in enumerate(_COLUMNS):
            grid.addWidget(QLabel(f"<b>{title}</b>"), 0, column)
        for number in range(1, 7):
            grid.addWidget(QLabel(str(number)), number, 0)
            key = QCheckBox("TX")
            key.setToolTip(f"Key station {number} (its amplifier key line)")
            key.toggled.connect(lambda on, n=number: self.box.set_tr(n, on))
            self.key_boxes[number] = key
            grid.addWidget(key, number, 1)
            cells = {}
            for column, title in enumerate(_COLUMNS[2:], start=2):
                cell = QLabel()
                cells[title] = cell
                grid.addWidget(cell, number, column)
            self.station_cells[number] = cells
        return outer

    # ------------------------------------------------------------------ updates

    def _on_box(self, kind: Traffic, data: bytes) -> None:
        if kind is Traffic.RECEIVED:
            self._answering_ping = data == PING
            if not self._answering_ping or self.show_pings.isChecked():
                self._log("in ", data)
        elif kind is Traffic.SENT:
            was_ping, self._answering_ping = self._answering_ping, False
            if not was_ping or self.show_pings.isChecked():
                self._log("out", data)
        if not self._refresh_queued:
            self._refresh_queued = True
            QTimer.singleShot(0, self.refresh)

    def _log(self, direction: str, data: bytes) -> None:
        stamp = time.strftime("%H:%M:%S")
        text = data.decode("ascii", errors="backslashreplace")
        text = "".join(c if " " <= c <= "~" else f"\\x{ord(c):02x}" for c in text)
        self.log.appendPlainText(f"{stamp} {direction} {text}")

    def refresh(self) -> None:
        """Redraw everything from the box."""
        self._refresh_queued = False
        view = self.box.view()
        self._show_header(view)
        for relay, label in enumerate(self.relay_labels):
            closed = relay in view.relays
            if label.property("closed") != closed:
                label.setProperty("closed", closed)
                label.setStyleSheet(_ON if closed else _OFF)
        for st in view.stations:
            self._show_station(st)

    def _show_header(self, view: BoxView) -> None:
        state = "active" if view.active else "inactive: all relays off"
        resolver = "on" if view.resolver_on else "off"
        self.header.setText(
            f"<b>{state}</b> &nbsp; resolver {resolver} &nbsp; unit {view.unit_id}, "
            f"firmware {view.version} &nbsp; inhibit {view.inhibit_ms} ms, "
            f"interrupt delay {view.interrupt_ms} ms"
        )

    def _show_station(self, st: StationView) -> None:
        key = self.key_boxes[st.number]
        if key.isChecked() != st.key:
            key.blockSignals(True)
            key.setChecked(st.key)
            key.blockSignals(False)
        cells = self.station_cells[st.number]
        cells["State"].setText(_state(st))
        cells["TX"].setText(_antenna(st.tx.antenna, st.tx.relays))
        cells["RX"].setText(_antenna(st.rx.antenna, st.rx.relays))
        cells["Alt"].setText(_antenna(st.alt.antenna, st.alt.relays))
        cells["Extra"].setText(", ".join(map(str, sorted(st.extra))) or "-")
        line = "low" if st.inhibit_line_low else "high"
        cells["Inhibit"].setText(f"{_inhibit(st)} (line {line})")
        cells["Inhibit"].setStyleSheet(_INHIBIT if st.inhibited else _PLAIN)
        cells["Mode"].setText(f"{st.mode.name.lower()}, rx delay {st.receive_delay_ms} ms")
        cells["Waiting"].setText(" ".join(f"{k}{a}" for k, a in st.pending) or "-")

    def relay_shown_closed(self, relay: int) -> bool:
        """Whether the window shows ``relay`` as closed."""
        return bool(self.relay_labels[relay].property("closed"))

    def closeEvent(self, event: QCloseEvent) -> None:
        self._stop_listening()
        self.closed.emit()
        super().closeEvent(event)


__all__ = ["EmulatorWindow"]
