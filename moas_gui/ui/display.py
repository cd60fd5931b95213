"""Whether a window can be shown here, asked before Qt is: Qt aborts the whole
process (SIGABRT, with advice about plugins) when it cannot open the display.

:func:`display_problem` returns None when a window can open, else one sentence
saying why not.  On X11 it opens a connection with libxcb itself, the library
Qt's own display plugin uses, so an unset, wrong or refused ``DISPLAY`` is
found out without Qt.  ``python -m moas_gui.ui.display`` prints the sentence
and exits 1 (``scripts/run-example.sh`` falls back to headless then).

No Qt is imported here.
"""

from __future__ import annotations

import os
import sys

__all__ = ["NO_DISPLAY_ADVICE", "display_problem"]

WINDOWLESS_PLATFORMS = ("offscreen", "minimal", "vnc", "eglfs", "linuxfb", "vkkhrdisplay")
"""Qt platforms that need no display server (tests run ``offscreen``)."""

NO_DISPLAY_ADVICE = ("start it from the desktop session, set DISPLAY to a display you may "
                     "use, or run the server without a window: moas-server --headless FILE")


def display_problem() -> str | None:
    """None when a window can open; else ``cannot open the display ...`` with the reason."""
    if sys.platform in ("win32", "darwin"):
        return None
    platform = os.environ.get("QT_QPA_PLATFORM", "").split(":", 1)[0].strip()
    if platform in WINDOWLESS_PLATFORMS:
        return None
    wayland = os.environ.get("WAYLAND_DISPLAY", "")
    if platform.startswith("wayland") or (not platform and wayland):
        if _wayland_reachable(wayland or "wayland-0"):
            return None
        if platform.startswith("wayland"):
            return f"cannot open the display: the Wayland display {wayland or 'wayland-0'} " \
                   "does not answer"
    display = os.environ.get("DISPLAY", "")
    if not display:
        return "cannot open the display: DISPLAY is not set (no desktop session here)"
    return _x11_problem(display)


def _wayland_reachable(name: str) -> bool:
    runtime = os.environ.get("XDG_RUNTIME_DIR", "")
    path = name if os.path.isabs(name) else os.path.join(runtime, name)
    return bool(runtime or os.path.isabs(name)) and os.path.exists(path)


def _x11_problem(display: str) -> str | None:
    # ctypes only here: under Wayland, Windows, macOS or a windowless platform
    # (offscreen) the check loads none of it
    import ctypes
    import ctypes.util

    found = ctypes.util.find_library("xcb")
    if found is None:
        return (f"cannot open the display {display}: libxcb is not installed "
                "(on Debian or Ubuntu: sudo apt install libxcb1)")
    try:
        xcb = ctypes.CDLL(found)
    except OSError as exc:
        return f"cannot open the display {display}: libxcb cannot be loaded ({exc})"
    xcb.xcb_connect.restype = ctypes.c_void_p
    xcb.xcb_connect.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_int)]
    xcb.xcb_connection_has_error.restype = ctypes.c_int
    xcb.xcb_connection_has_error.argtypes = [ctypes.c_void_p]
    xcb.xcb_disconnect.argtypes = [ctypes.c_void_p]
    connection = xcb.xcb_connect(display.encode(), None)
    try:
        error = xcb.xcb_connection_has_error(connection) if connection else 1
    finally:
        if connection:
            xcb.xcb_disconnect(connection)
    if error:
        return (f"cannot open the display {display}: no X server answers there, or it "
                "does not let this user in")
    if ctypes.util.find_library("xcb-cursor") is None:
        return (f"cannot open the display {display}: Qt's X11 plugin needs libxcb-cursor "
                "(on Debian or Ubuntu: sudo apt install libxcb-cursor0)")
    return None


def main() -> int:
    problem = display_problem()
    if problem is None:
        return 0
    print(problem)
    return 1


if __name__ == "__main__":
    sys.exit(main())
