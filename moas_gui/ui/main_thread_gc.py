"""Python's garbage collection, run on the Qt thread only.

Python's cyclic garbage collector runs on whichever thread happens to allocate
when a generation's count passes its threshold.  The window programs have
other threads (the saved state's writer, serial readers, the emulator's pump),
and a Qt object freed on one of them cannot stop its timers: Qt refuses to kill
a timer from another thread, leaves it registered, and the timer later fires
on freed memory, which ends the program with a segmentation fault.

So a window program turns automatic collection off and collects here instead,
on the Qt thread, as often as Python would have: :func:`collect_due` looks at
the same counts and thresholds and collects the generation they call for.
"""

from __future__ import annotations

import gc

from moas_gui.ui.qt import QObject, QTimer

CHECK_INTERVAL_MS = 250
"""How often the counts are looked at: a few times a second costs next to nothing."""


def collect_due() -> int | None:
    """Collects the oldest generation whose count has passed its threshold, as Python's
    automatic collection would; returns that generation, or ``None`` when none is due."""
    thresholds, counts = gc.get_threshold(), gc.get_count()
    due = None
    for generation in range(3):
        if thresholds[generation] and counts[generation] > thresholds[generation]:
            due = generation
    if due is not None:
        gc.collect(due)
    return due


class MainThreadCollector(QObject):
    """While it runs, garbage is collected on the thread that made this object (the
    Qt thread) and never on any other; :meth:`stop` gives collection back to Python."""

    def __init__(self, parent: QObject | None = None,
                 interval_ms: int = CHECK_INTERVAL_MS) -> None:
        super().__init__(parent)
        self._was_enabled = gc.isenabled()
        gc.disable()
        self._timer = QTimer(self)
        self._timer.setInterval(interval_ms)
        self._timer.timeout.connect(collect_due)
        self._timer.start()

    def stop(self) -> None:
        self._timer.stop()
        if self._was_enabled:
            gc.enable()


__all__ = ["CHECK_INTERVAL_MS", "MainThreadCollector", "collect_due"]
