"""Long names in the client window are cut with "…" and shown whole in a tooltip,
instead of widening the window past a laptop screen."""

from __future__ import annotations

from typing import Any

from moas_gui.ui.elided_label import MIN_WIDTH, ElidedLabel

LONG = "14025.0 kHz     TX  20 m 4/4/4 stack top + middle + bottom     RX  20 m 4/4/4 stack"


def test_a_long_text_is_cut_with_an_ellipsis_and_shown_whole_in_the_tooltip(qapp: Any) -> None:
    label = ElidedLabel(LONG)
    assert label.minimumSizeHint().width() <= MIN_WIDTH
    label.resize(200, 30)
    label.show()
    qapp.processEvents()
    assert label.text() == LONG
    assert label.shown_text().endswith("\u2026") and len(label.shown_text()) < len(LONG)
    assert label.toolTip() == LONG
    label.resize(label.sizeHint().width() + 10, 30)
    qapp.processEvents()
    assert label.shown_text() == LONG and label.toolTip() == ""
    label.setText("short")
    assert label.shown_text() == "short" and label.toolTip() == ""
    label.close()
