"""The server's status icons, the application icon and the ``.moas`` file icon as ``QIcon``.

The drawings are SVG files in ``moas_gui/resources/icons`` (drawn on a 16-unit
pixel grid, so they are sharp at 16, 32, 48 px and up); beside each are PNG
renderings at 16-256 px made by ``scripts/make_icons.py``.  When Qt's SVG icon
engine is present the icon is drawn from the SVG at whatever size is asked;
otherwise it is built from the PNGs.

The four states differ by shape as well as colour, for colour-blind operators:

=================  ======  =================================
state              colour  badge (lower right)
=================  ======  =================================
``NORMAL``         green   none
``UNRESPONSIVE``   orange  warning triangle with ``!``
``STOPPED``        red     square stop sign
``NO_CONFIG``      grey    round question mark
=================  ======  =================================

Needs a ``QGuiApplication``.  Icons are made once and cached.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Final

from moas_gui.status import ServerState

from .qt import QIcon, QSize

ICON_DIR: Final = Path(__file__).resolve().parent.parent / "resources" / "icons"
PNG_SIZES: Final = (16, 22, 24, 32, 48, 64, 128, 256)
APP_ICON: Final = "moas-normal"
FILE_ICON: Final = "application-x-moas"


_ICON_NAMES: Final = {
    ServerState.NORMAL: "moas-normal",
    ServerState.UNRESPONSIVE: "moas-unresponsive",
    ServerState.STOPPED: "moas-stopped",
    ServerState.NO_CONFIG: "moas-unconfigured",
}


def status_icon_name(state: ServerState) -> str:
    """The file name (without extension) of the icon for ``state``."""
    return _ICON_NAMES[state]


def icon_path(name: str, size: int | None = None) -> Path:
    """The SVG file of icon ``name``, or its PNG rendering at ``size`` px."""
    return ICON_DIR / (f"{name}.svg" if size is None else f"{name}-{size}.png")


@functools.cache
def svg_icons_available() -> bool:
    """True when Qt can draw an SVG icon at any size (its SVG icon engine is installed).

    Without the engine Qt may still read the SVG as one 16 px picture, which
    it will not enlarge: asking for 64 px tells the two apart.
    """
    probe = QIcon(str(icon_path(APP_ICON)))
    return probe.actualSize(QSize(64, 64)) == QSize(64, 64)


def build_icon(name: str, *, use_svg: bool) -> QIcon:
    """Icon ``name`` from its SVG, or from its PNG renderings when ``use_svg`` is false."""
    if use_svg:
        return QIcon(str(icon_path(name)))
    icon = QIcon()
    for size in PNG_SIZES:
        icon.addFile(str(icon_path(name, size)), QSize(size, size))
    return icon


@functools.cache
def named_icon(name: str) -> QIcon:
    return build_icon(name, use_svg=svg_icons_available())


def status_icon(state: ServerState) -> QIcon:
    """The icon for ``state`` (cached: the same ``QIcon`` every time)."""
    return named_icon(status_icon_name(state))


def app_icon() -> QIcon:
    """The application's icon (the normal status icon)."""
    return named_icon(APP_ICON)


def file_icon() -> QIcon:
    """The icon of a ``.moas`` configuration file."""
    return named_icon(FILE_ICON)


__all__ = [
    "APP_ICON", "FILE_ICON", "ICON_DIR", "PNG_SIZES", "app_icon", "build_icon",
    "file_icon", "icon_path", "named_icon", "status_icon", "status_icon_name",
    "svg_icons_available",
]
