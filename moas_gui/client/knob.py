"""The knob's arithmetic, with no Qt: what a turn steps through (manual 5.18, 6.7).

A knob (a mouse wheel, arrow keys, a USB encoder) steps a *cursor* through a
list, wrapping past either end, and a press selects what the cursor is on.
The list is either the layout's antennas that can be selected now (available
or already selected, in reading order: row by row, left to right; a knob
layout is one row of up to 50), or the radio's relative list.
"""

from __future__ import annotations

from moas_gui.client.model import ButtonState, ButtonType, LayoutView

__all__ = ["knob_antennas", "knob_step"]


def knob_antennas(layout: LayoutView | None) -> tuple[int, ...]:
    """The antenna IDs a knob steps through on ``layout``, each once."""
    if layout is None:
        return ()
    usable = sorted(
        (b.row, b.column, b.id) for b in layout.buttons
        if b.type is ButtonType.ANTENNA and b.state is not ButtonState.UNAVAILABLE)
    return tuple(dict.fromkeys(ident for _row, _column, ident in usable))


def knob_step(items: tuple[int, ...], current: int | None, steps: int) -> int | None:
    """The item ``steps`` away from ``current`` (wrapping); from nowhere, a step
    forward lands on the first item and a step back on the last."""
    if not items:
        return None
    if current not in items:
        if steps == 0:
            return None
        position = -1 if steps > 0 else len(items)
        return items[(position + steps) % len(items)]
    return items[(items.index(current) + steps) % len(items)]
