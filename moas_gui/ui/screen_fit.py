"""Windows open within the screen they are on.

A window asks for the size its content likes; :func:`fit_to_screen` gives it
that or the screen's available area (less room for the window manager's frame
and title bar), whichever is smaller.  Sizes are Qt's device-independent
pixels, so a 1920x1080 screen at scale 2 counts as 960x540.  What does not fit
then scrolls inside the window (each window's content sits in a scroll area).
"""

from __future__ import annotations

from .qt import QApplication, QRect, QWidget

__all__ = ["FRAME_ROOM", "available_area", "fit_to_screen"]

FRAME_ROOM = (16, 48)
"""Width and height left for a window manager's frame and title bar."""


def available_area(window: QWidget) -> QRect | None:
    """The available geometry of the screen ``window`` is on (or the primary one)."""
    screen = window.screen() or QApplication.primaryScreen()
    return None if screen is None else screen.availableGeometry()


def fit_to_screen(window: QWidget, width: int, height: int) -> None:
    """Resizes ``window`` to ``width`` x ``height``, or less to fit its screen, and moves
    it back onto the screen when part of it would lie outside."""
    area = available_area(window)
    if area is None:
        window.resize(width, height)
        return
    room_w, room_h = FRAME_ROOM
    fitted_w = max(1, min(width, area.width() - room_w))
    fitted_h = max(1, min(height, area.height() - room_h))
    window.resize(fitted_w, fitted_h)
    x = min(max(window.x(), area.left()), area.right() - fitted_w - room_w)
    y = min(max(window.y(), area.top()), area.bottom() - fitted_h - room_h)
    if (x, y) != (window.x(), window.y()):
        window.move(max(x, area.left()), max(y, area.top()))
