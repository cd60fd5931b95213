"""Colours and fonts of the client window, chosen for a dark shack at 3 a.m.

Every state has a second cue besides its colour, for operators who do not
tell red from green:

=============  =================================================================
selected       amber fill, black **bold** text, a check mark, a thick white frame
available      slate-blue fill, white text, a thin frame
unavailable    near-black fill with diagonal hatching, grey struck-through text,
               a dashed frame; the button cannot be pressed
greyed         dark grey fill, grey plain text, a dotted frame, no check mark:
               not connected or switches stopped, nothing is shown as selected
=============  =================================================================

The three differ in brightness as well as hue, so they read apart even in
grey.  Function buttons are violet when available, to set them apart from
antennas.
"""

from __future__ import annotations

from .qt import QColor, QPalette

__all__ = ["CLIENT_STYLESHEET", "Colours", "dark_palette"]


class Colours:
    WINDOW = QColor("#101418")
    PANEL = QColor("#1b2228")
    TEXT = QColor("#eef3f6")
    DIM_TEXT = QColor("#8a949c")

    SELECTED = QColor("#ffc107")
    SELECTED_TEXT = QColor("#000000")
    SELECTED_FRAME = QColor("#ffffff")
    AVAILABLE = QColor("#2d4a63")
    AVAILABLE_TEXT = QColor("#ffffff")
    AVAILABLE_FRAME = QColor("#7fa7c4")
    FUNCTION = QColor("#4b3470")
    FUNCTION_FRAME = QColor("#b39ddb")
    UNAVAILABLE = QColor("#181b1e")
    UNAVAILABLE_TEXT = QColor("#737b82")
    UNAVAILABLE_HATCH = QColor("#3a4046")
    PRESSED = QColor("#ffffff")
    GREYED = QColor("#24282c")
    GREYED_TEXT = QColor("#80878d")
    GREYED_FRAME = QColor("#4a5056")

    TRANSMIT = QColor("#e53935")
    INHIBIT = QColor("#ff6d00")
    CONNECTED = QColor("#43a047")
    RECONNECTING = QColor("#ffb300")
    CLOSED = QColor("#757575")

    COMPASS_FACE = QColor("#0b1014")
    COMPASS_RING = QColor("#5d7180")
    COMPASS_TICK = QColor("#9fb1bd")
    COMPASS_NORTH = QColor("#ff5252")
    HEADING = QColor("#ffc107")
    TARGET = QColor("#4dd0e1")
    DRAG = QColor("#ffffff")
    DEAD_ZONE = QColor(183, 28, 28, 150)
    OVERLAP = QColor(255, 193, 7, 45)
    STOP = QColor("#ff5252")
    DIRECTION = QColor("#80cbc4")
    OFFLINE = QColor("#5f6468")


CLIENT_STYLESHEET = """
QWidget#clientRoot, QMainWindow { background: #101418; }
QMenuBar { background: #1b2228; color: #eef3f6; }
QMenuBar::item:selected { background: #34414b; }
QLabel#display { font-size: 15pt; font-weight: bold; padding: 6px 10px;
                 background: #1b2228; border: 1px solid #34414b; border-radius: 6px; }
QLabel#link { font-size: 11pt; font-weight: bold; padding: 3px 8px; border-radius: 4px; }
QLabel#badgeTx { background: #e53935; color: white; font-weight: bold; font-size: 13pt;
                 padding: 3px 10px; border-radius: 4px; }
QLabel#badgeInhibit { background: #ff6d00; color: black; font-weight: bold; font-size: 12pt;
                      padding: 3px 10px; border-radius: 4px; }
QLabel#badgeActive { background: #fdd835; color: black; font-weight: bold; font-size: 11pt;
                     padding: 3px 8px; border-radius: 4px; border: 2px solid black; }
QLabel#badgeFocus { background: transparent; color: #80deea; font-weight: bold; font-size: 11pt;
                    padding: 2px 8px; border-radius: 4px; border: 2px dashed #80deea; }
QLabel#heading { font-size: 16pt; font-weight: bold; }
QLabel { color: #eef3f6; font-size: 11pt; }
QCheckBox { color: #eef3f6; font-size: 11pt; }
QGroupBox { color: #eef3f6; font-size: 11pt; border: 1px solid #34414b; border-radius: 6px; margin-top: 14px; padding: 6px;
            font-weight: bold; }
QGroupBox::title { subcontrol-origin: margin; left: 10px; padding: 0 4px; color: #9fb1bd; }
QPushButton { color: #eef3f6; font-size: 11pt; background: #26323b; border: 1px solid #5d7180; border-radius: 5px;
              padding: 5px 12px; min-height: 24px; font-weight: bold; }
QPushButton:hover { border-color: #9fb1bd; }
QPushButton:pressed { background: #3b4b57; }
QPushButton:disabled { color: #5f6468; border-color: #30383e; }
QPushButton[greyed="true"] { color: #5f6468; border: 1px dotted #4a5056; background: #1c2126; }
QPushButton:checked { background: #ffc107; color: black; border: 2px solid white; }
QPushButton#stop { background: #b71c1c; border: 2px solid #ff8a80; color: white;
                   font-size: 13pt; min-height: 34px; }
QPushButton#stop:disabled { background: #2a2022; color: #6d5f60; border-color: #3b2f30; }
QPushButton#stop[greyed="true"] { background: #2a2022; color: #6d5f60; border: 2px dotted #3b2f30; }
QCheckBox { spacing: 6px; }
QStatusBar { background: #1b2228; }
QLabel#statusLine { color: #e0e6ea; background: #1b2228; padding: 3px 6px; min-height: 1.2em; }
QLabel#statusLine[tone="warning"] { color: #ffab91; font-weight: bold; }
"""


def dark_palette(base: QPalette) -> QPalette:
    """``base`` turned dark, for the widgets the style sheet leaves to the style
    (combo boxes and spin boxes keep their own arrows this way)."""
    palette = QPalette(base)
    roles = QPalette.ColorRole
    for role, colour in (
        (roles.Window, Colours.WINDOW), (roles.WindowText, Colours.TEXT),
        (roles.Base, Colours.PANEL), (roles.AlternateBase, QColor("#222b32")),
        (roles.Text, Colours.TEXT), (roles.Button, QColor("#26323b")),
        (roles.ButtonText, Colours.TEXT), (roles.Highlight, Colours.AVAILABLE),
        (roles.HighlightedText, QColor("#ffffff")), (roles.ToolTipBase, Colours.PANEL),
        (roles.ToolTipText, Colours.TEXT), (roles.PlaceholderText, Colours.DIM_TEXT),
    ):
        palette.setColor(role, colour)
    for role in (roles.Text, roles.WindowText, roles.ButtonText):
        palette.setColor(QPalette.ColorGroup.Disabled, role, Colours.DIM_TEXT)
    return palette
