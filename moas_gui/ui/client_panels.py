"""The two small panels under the client window's button grid.

:class:`RelativeStrip` is the built-in relative client (manual 5.19):
previous, next, or one antenna of the radio's relative list.
:class:`FrequencyBox` sends a frequency (optionally split) for testing a
configuration without a logging program.  Both only emit what the user asked
for; the window turns it into a protocol request.
"""

from __future__ import annotations

from moas_gui.client.model import RadioView, Snapshot

from .qt import (
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QGroupBox,
    QHBoxLayout,
    QPushButton,
    QWidget,
    Signal,
)

__all__ = ["FrequencyBox", "RelativeStrip", "frequency_text"]

CHECK = "\u2714"
UNKNOWN_LIST_POSITIONS = 8
"""Positions offered when the server does not send the radio's relative list."""


class RelativeStrip(QGroupBox):
    """Previous / the list / Use / Next."""

    step_requested = Signal(int)
    """-1 for the previous antenna, +1 for the next."""
    index_requested = Signal(int)
    """A 0-based position in the relative list."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__("Relative", parent)
        row = QHBoxLayout(self)
        self._shown_tx: int | None = None
        self.previous_button = QPushButton("\u25c0 Previous", self)
        self.next_button = QPushButton("Next \u25b6", self)
        self.list_box = QComboBox(self)
        self.list_box.setMinimumWidth(180)
        # long antenna names must not widen the window: the list shows about
        # 20 characters and opens wide enough for all of them
        self.list_box.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.list_box.setMinimumContentsLength(20)
        self.list_box.setToolTip("The relative antenna list for this frequency")
        self.use_button = QPushButton("Use", self)
        row.addWidget(self.previous_button)
        row.addWidget(self.list_box, 1)
        row.addWidget(self.use_button)
        row.addWidget(self.next_button)
        self.previous_button.clicked.connect(lambda: self.step_requested.emit(-1))
        self.next_button.clicked.connect(lambda: self.step_requested.emit(+1))
        self.use_button.clicked.connect(
            lambda: self.index_requested.emit(max(0, self.list_box.currentIndex())))

    def show_list(self, radio: RadioView, snapshot: Snapshot, *, mark: bool = True) -> None:
        """The radio's relative list by name when the server sends it, else positions.
        The antenna in use is marked and shown as the current entry (``mark`` False:
        none is in use, the switches are stopped)."""
        before = self.list_box.currentIndex()
        self.list_box.blockSignals(True)
        self.list_box.clear()
        if radio.relative is not None:
            for index, antenna_id in enumerate(radio.relative):
                antenna = snapshot.antenna(antenna_id)
                in_use = mark and antenna_id == radio.tx
                name = antenna.name if antenna else f"Antenna {antenna_id}"
                self.list_box.addItem(f"{CHECK + ' ' if in_use else ''}{index + 1}. {name}")
            if mark and radio.tx in radio.relative and radio.tx != self._shown_tx:
                before = radio.relative.index(radio.tx)  # the list follows a new selection
        else:
            for index in range(UNKNOWN_LIST_POSITIONS):
                self.list_box.addItem(f"Position {index + 1}")
        self._shown_tx = radio.tx if mark else None
        self.list_box.setCurrentIndex(max(0, min(before, self.list_box.count() - 1)))
        self.list_box.blockSignals(False)


class FrequencyBox(QGroupBox):
    """kHz, an optional split transmit frequency, and Set."""

    frequency_requested = Signal(float, object)
    """(receive kHz, transmit kHz or None)"""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__("Frequency (testing without a logger)", parent)
        row = QHBoxLayout(self)
        self.khz_box = _khz_box(self)
        self.split_box = QCheckBox("Split TX", self)
        self.tx_khz_box = _khz_box(self)
        self.tx_khz_box.setEnabled(False)
        self.set_button = QPushButton("Set", self)
        row.addWidget(self.khz_box, 1)
        row.addWidget(self.split_box)
        row.addWidget(self.tx_khz_box, 1)
        row.addWidget(self.set_button)
        self.split_box.toggled.connect(self.tx_khz_box.setEnabled)
        self.set_button.clicked.connect(self._send)
        self.khz_box.editingFinished.connect(self._entered)

    def show_radio(self, radio: RadioView | None) -> None:
        """Starts the boxes from the radio's frequencies."""
        if radio is None or radio.khz is None:
            return
        self.khz_box.setValue(radio.khz)
        self.tx_khz_box.setValue(radio.tx_khz if radio.tx_khz is not None else radio.khz)
        self.split_box.setChecked(radio.tx_khz is not None and radio.tx_khz != radio.khz)

    def _entered(self) -> None:
        if self.khz_box.hasFocus():
            self._send()

    def _send(self) -> None:
        tx = self.tx_khz_box.value() if self.split_box.isChecked() else None
        self.frequency_requested.emit(self.khz_box.value(), tx)


def _khz_box(parent: QWidget) -> QDoubleSpinBox:
    box = QDoubleSpinBox(parent)
    box.setRange(0.0, 10_000_000.0)
    box.setDecimals(1)
    box.setSingleStep(1.0)
    box.setSuffix(" kHz")
    box.setKeyboardTracking(False)
    box.setMinimumWidth(130)
    return box


def frequency_text(radio: RadioView) -> str:
    """``14025.0 kHz``, or ``RX 14100.0  TX 14150.5 kHz`` when split."""
    if radio.khz is None:
        return "no frequency"
    if radio.tx_khz is not None and radio.tx_khz != radio.khz:
        return f"RX {radio.khz:.1f}  TX {radio.tx_khz:.1f} kHz"
    return f"{radio.khz:.1f} kHz"
