"""A guard against a reference-counting fault of the Qt binding.

Measured on this project's machines: PySide6-Essentials 6.12.0 under Python
3.11 loses one reference to ``None`` on every call of a Qt method that returns
nothing (``QWidget.setEnabled``, ``QPainter.drawLine``, ``QLabel.setText``...)
and on ``QComboBox.currentData()`` when it returns ``None``.  A fresh
application holds about 9,000 references to ``None`` and one repaint of the
compass makes about 100 such calls, so after a minute of a turning rotator
Python aborts with "Fatal Python error: none_dealloc".  PySide6 6.11.3 does
not have the fault, and from Python 3.12 on ``None`` is immortal, so the
count no longer matters.

:func:`guard_none_refcount` measures the loss with a throwaway object and,
only when there is one and Python cannot protect itself, gives ``None`` a
reserve of references so large that no run can use it up (the same effect
Python 3.12 gets by making ``None`` immortal).  It logs a warning saying why.
The proper cure is a binding version without the fault.
"""

from __future__ import annotations

import ctypes
import logging
import sys

from .qt import QObject

__all__ = ["guard_none_refcount", "none_references_lost_per_call"]

log = logging.getLogger("moas_gui.ui")

RESERVE = 1 << 40
"""References added to None: at one lost per call, more than any run can make."""

_guarded = False


def none_references_lost_per_call(calls: int = 200) -> float:
    """How many references to ``None`` one call of a Qt method returning nothing loses."""
    probe = QObject()
    before = sys.getrefcount(None)
    for _ in range(calls):
        probe.setObjectName("probe")
    lost = before - sys.getrefcount(None)
    probe.deleteLater()
    return max(0.0, lost / calls)


def guard_none_refcount() -> bool:
    """Protects ``None`` from the binding fault when it is present; True when it was."""
    global _guarded
    if _guarded:
        return True
    if sys.version_info >= (3, 12) or sys.implementation.name != "cpython":
        return False
    lost = none_references_lost_per_call()
    if lost < 0.5:
        return False
    refcount = ctypes.c_ssize_t.from_address(id(None))
    refcount.value += RESERVE
    _guarded = True
    try:
        from PySide6 import __version__ as binding_version
    except ImportError:  # pragma: no cover - the binding is there, or qt.py failed first
        binding_version = "?"
    log.warning(
        "PySide6 %s loses a reference to None on each Qt call that returns nothing "
        "(%.1f per call); moas-gui keeps None alive so the window does not abort. "
        "Use a PySide6-Essentials version without this fault (6.11.3 is fine).",
        binding_version, lost)
    return True
