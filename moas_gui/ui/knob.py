"""The knob in the desktop client: mouse wheel, keys and USB encoders (manual 5.18).

A turn moves a cursor (a ring drawn on the button) and a press selects what it
is on, as the manual's knob client does; the list it steps through and the
wrapping are :mod:`moas_gui.client.knob`'s.

==========================================  =============================================
mouse wheel over the buttons, or arrow keys  cursor to the next / previous antenna of the
(with a button focused)                      layout that can be selected now
Enter or Return, middle click, Space         select the antenna under the cursor (Shift+Enter:
                                             that antenna alone, as a double-click)
Page Down / Page Up                          cursor to the next / previous entry of the
                                             radio's relative list; Ctrl+Enter selects it
Alt+1 ... Alt+9                              this window serves radio 1 ... 9 of its station
Volume Up / Volume Down / Mute               as the wheel and a press: what most USB knobs
                                             (HID consumer-control encoders) send
a Phidget encoder (``moas-gui[knob]``)       turn: the cursor; press: that antenna alone;
                                             turn while pressed: add it on release
                                             (:mod:`moas_gui.client.phidget`)
==========================================  =============================================

The Phidget encoder attaching and detaching is shown in the status line; without
the extra or without an encoder the log says so once, and the rest works as before.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from moas_gui.client.knob import knob_antennas, knob_step
from moas_gui.client.model import ButtonState, ButtonType
from moas_gui.client.phidget import PhidgetKnob, PhidgetLibrary
from moas_gui.client.screen import Tone

from .qt import QKeySequence, QObject, QShortcut, Qt, QTimer, QWidget, Signal, Slot

ABSENT_AFTER_MS = 3000
"""How long after the window opens a missing Phidget encoder is said (once)."""


class _Hop(QObject):
    """Runs what the Phidget library's thread posts on the window's thread (a queued
    signal to a slot of an object of that thread)."""

    posted = Signal(object)

    def __init__(self) -> None:
        super().__init__()
        self.posted.connect(self.run)

    @Slot(object)
    def run(self, work: Callable[[], None]) -> None:
        work()

__all__ = ["KnobControl"]


class KnobControl:
    """Adds the knob to a client window (see the module notes).  A plain object, not
    a QObject: it is told of the wheel by the grid's signals and of keys by shortcuts,
    so nothing of it runs while Qt takes the window apart."""

    def __init__(self, window: Any, *, phidget: bool = True,
                 library: PhidgetLibrary | None = None) -> None:
        self.window = window
        self.cursor: int | None = None
        """The antenna ID under the layout cursor."""
        self._last = "layout"
        grid: QWidget = window.grid
        window.grid.wheel_turned.connect(self._wheel_turned)
        window.grid.middle_pressed.connect(self.press)
        in_grid = Qt.ShortcutContext.WidgetWithChildrenShortcut
        in_window = Qt.ShortcutContext.WindowShortcut
        keys: list[tuple[Any, Any, Any]] = [
            (Qt.Key.Key_Left, lambda: self.step(-1), in_grid),
            (Qt.Key.Key_Up, lambda: self.step(-1), in_grid),
            (Qt.Key.Key_Right, lambda: self.step(1), in_grid),
            (Qt.Key.Key_Down, lambda: self.step(1), in_grid),
            (Qt.Key.Key_Return, lambda: self.press(), in_grid),
            (Qt.Key.Key_Enter, lambda: self.press(), in_grid),
            ("Shift+Return", lambda: self.press(exclusive=True), in_grid),
            (Qt.Key.Key_PageDown, lambda: self.step_relative(1), in_window),
            (Qt.Key.Key_PageUp, lambda: self.step_relative(-1), in_window),
            ("Ctrl+Return", self.press_relative, in_window),
            (Qt.Key.Key_VolumeUp, lambda: self.step(1), in_window),
            (Qt.Key.Key_VolumeDown, lambda: self.step(-1), in_window),
            (Qt.Key.Key_VolumeMute, self.press_last, in_window),
        ]
        for number in range(1, 10):
            keys.append((f"Alt+{number}", lambda n=number: self.choose_radio(n), in_window))
        self.shortcuts: list[QShortcut] = []
        for key, action, context in keys:
            parent = grid if context is in_grid else window
            shortcut = QShortcut(QKeySequence(key), parent)
            shortcut.setContext(context)
            shortcut.activated.connect(action)
            self.shortcuts.append(shortcut)
        self._hop = _Hop()
        self.phidget = PhidgetKnob(self, self._hop.posted.emit, library=library)
        if phidget:
            self.start_phidget(library)

    # -- the Phidget encoder ------------------------------------------------------------------
    def start_phidget(self, library: PhidgetLibrary | None = None) -> bool:
        """Opens the Phidget encoder (``library``: phidget22's classes, or a stand-in with
        their shape); False when there is no library.  A knob already open is closed."""
        self.phidget.close()
        self.phidget = PhidgetKnob(self, self._hop.posted.emit, library=library)
        if not self.phidget.start():
            return False
        QTimer.singleShot(ABSENT_AFTER_MS, self.phidget.say_if_absent)
        return True

    def knob_attached(self, name: str) -> None:
        self.window._say(f"Knob: {name} attached", Tone.INFO)

    def knob_detached(self, name: str) -> None:
        self.window._say(f"Knob: {name} detached; the wheel and keys still step", Tone.WARNING)

    def close(self) -> None:
        self.phidget.close()

    # -- the layout cursor -------------------------------------------------------------------
    def items(self) -> tuple[int, ...]:
        return knob_antennas(self.window.layout_view)

    def step(self, steps: int) -> int | None:
        """Moves the cursor ``steps`` antennas on (back when negative); returns where it is."""
        self._last = "layout"
        items = self.items()
        current = self.cursor
        if current not in items:  # from the focused button, else the antenna in use
            focused = self.window.grid.focusWidget()
            view = getattr(focused, "view", None)
            radio = self.window.radio_view
            if view is not None and view.type is ButtonType.ANTENNA and view.id in items:
                current = view.id
            else:
                current = radio.tx if radio is not None else None
        self._show(knob_step(items, current, steps))
        return self.cursor

    def press(self, exclusive: bool = False) -> bool:
        """Selects the antenna under the cursor; False when there is none to select."""
        grid = self.window.grid
        button = grid.button_for(ButtonType.ANTENNA, self.cursor) if self.cursor is not None \
            else None
        if button is None or (button.view.state is ButtonState.UNAVAILABLE
                              and not button.greyed):
            return False
        if exclusive:
            grid.double_pressed.emit(button.view)
        else:
            button.click()
        return True

    def _show(self, antenna: int | None) -> None:
        self.cursor = antenna
        for button in self.window.grid.buttons:
            here = button.view.type is ButtonType.ANTENNA and button.view.id == antenna
            button.set_cursor(here)
            if here:
                button.setFocus(Qt.FocusReason.OtherFocusReason)

    # -- the relative list ---------------------------------------------------------------------
    def step_relative(self, steps: int) -> int:
        """Moves the relative list's cursor; returns its position."""
        self._last = "relative"
        box = self.window.relative_box
        count = box.count()
        if count:
            box.setCurrentIndex((max(box.currentIndex(), 0) + steps) % count)
        return int(box.currentIndex())

    def press_relative(self) -> None:
        self._last = "relative"
        if self.window.relative_go.isEnabled():
            self.window.relative_go.click()

    def press_last(self) -> None:
        if self._last == "relative":
            self.press_relative()
        else:
            self.press()

    # -- radios ----------------------------------------------------------------------------------
    def choose_radio(self, radio: int) -> bool:
        """This window serves radio ``radio`` of its station; False when there is none."""
        box = self.window.radio_box
        index = box.findText(str(radio))
        if index < 0:
            return False
        box.setCurrentIndex(index)
        self.cursor = None
        return True

    # -- the wheel ---------------------------------------------------------------------------------
    def _wheel_turned(self, notches: int) -> None:
        self.step(-notches)  # the wheel turned towards the user: the next antenna
