"""Button layouts (5.16, 6.7): the closest configured layout and each button's state.

The closest layout for a client of R rows and C columns, among the layouts for
its station and radio (a layout naming neither serves everybody): the one with
the smallest ``|rows - R| + |columns - C|``; on a tie the more specific one
(naming the radio, then the station), then one that fits inside R x C, then
the first in the file.  Its buttons are those of the matrix entries whose range
holds the radio's frequency, plus those of entries with no range; a button
outside the layout's rows and columns, or a second button on the same place,
is left out.  A button is "selected" when it shows the radio's antenna (or a
toggling function that is on), "available" when pressing it would work now,
otherwise "unavailable", with the refusal a press would get as its ``reason``.
"""

from __future__ import annotations

from collections.abc import Callable

from moas_gui.config.model import ButtonType, Layout, RadioRef

from .index import ConfigIndex
from .views import AVAILABLE, SELECTED, UNAVAILABLE, ButtonView, LayoutView


def closest_layout(ix: ConfigIndex, ref: RadioRef, rows: int, columns: int) -> Layout | None:
    best: tuple[tuple[int, int, int, int], Layout] | None = None
    for i, layout in enumerate(ix.config.layouts):
        if layout.station is not None and layout.station != ref.station:
            continue
        if layout.radio is not None and layout.radio != ref.radio:
            continue
        specific = (layout.radio is not None) * 2 + (layout.station is not None)
        fits = layout.rows <= rows and layout.columns <= columns
        score = (abs(layout.rows - rows) + abs(layout.columns - columns), -specific,
                 0 if fits else 1, i)
        if best is None or score < best[0]:
            best = (score, layout)
    return best[1] if best else None


def layout_view(ix: ConfigIndex, ref: RadioRef, khz: float | None, rows: int, columns: int,
                antenna_state: Callable[[int], tuple[str, str]],
                function_state: Callable[[int], tuple[str, str]]) -> LayoutView:
    """The layout closest to ``rows`` x ``columns`` with its buttons; each ``*_state``
    gives a button's state and, when unavailable, why."""
    layout = closest_layout(ix, ref, rows, columns)
    if layout is None:
        return LayoutView(ref.station, ref.radio, rows, columns, ())
    taken: set[tuple[int, int]] = set()
    buttons: list[ButtonView] = []
    for entry in layout.matrix:
        if entry.range.unbounded:
            pass
        elif khz is None or not entry.range.contains(khz):
            continue
        for b in entry.buttons:
            place = (b.row, b.column)
            if place in taken or not (0 <= b.row < layout.rows and 0 <= b.column < layout.columns):
                continue
            if b.type is ButtonType.ANTENNA:
                ant = ix.antennas.get(b.id)
                if ant is None:
                    continue
                label, (state, reason) = ant.label, antenna_state(b.id)
            else:
                f = ix.functions.get(b.id)
                if f is None:
                    continue
                label, (state, reason) = f.label, function_state(b.id)
            taken.add(place)
            buttons.append(ButtonView(b.row, b.column, b.type.value, b.id, label, state,
                                      reason))
    buttons.sort(key=lambda b: (b.row, b.column))
    return LayoutView(ref.station, ref.radio, layout.rows, layout.columns, tuple(buttons))


__all__ = ["AVAILABLE", "SELECTED", "UNAVAILABLE", "closest_layout", "layout_view"]
