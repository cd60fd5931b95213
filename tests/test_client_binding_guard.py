"""The guard against the Qt binding losing references to None (see its module)."""

from __future__ import annotations

import sys

from moas_gui.ui.binding_guard import RESERVE, guard_none_refcount, none_references_lost_per_call
from moas_gui.ui.qt import QApplication, QWidget


def test_none_survives_more_qt_calls_than_it_had_references(qapp: QApplication) -> None:
    unguarded = min(sys.getrefcount(None), 1_000_000)
    lost = none_references_lost_per_call()
    applied = guard_none_refcount()
    assert applied == (lost >= 0.5 and sys.version_info < (3, 12))
    widget = QWidget()
    for _ in range(unguarded + 1000):  # would use up every reference None had unguarded
        widget.setEnabled(True)
    assert sys.getrefcount(None) > 1000
    if applied:
        assert sys.getrefcount(None) > RESERVE // 2
    assert guard_none_refcount() is applied
