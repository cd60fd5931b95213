"""The one place moas-gui imports Qt from (PySide6-Essentials).

Windows import their Qt names from here, so a change of binding or a missing
module shows up in one file.
"""

from __future__ import annotations

import os
from types import ModuleType
from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

if TYPE_CHECKING:
    from PySide6.QtCore import (
        QByteArray,
        QEvent,
        QObject,
        QPoint,
        QPointF,
        QProcess,
        QRect,
        QRectF,
        QSettings,
        QSize,
        Qt,
        QTimer,
        QUrl,
        Signal,
        Slot,
    )
    from PySide6.QtGui import (
        QAction,
        QActionGroup,
        QBrush,
        QCloseEvent,
        QColor,
        QContextMenuEvent,
        QCursor,
        QDesktopServices,
        QFileOpenEvent,
        QFont,
        QFontDatabase,
        QIcon,
        QKeySequence,
        QMouseEvent,
        QPainter,
        QPainterPath,
        QPaintEvent,
        QPalette,
        QPen,
        QPixmap,
        QResizeEvent,
        QShortcut,
        QShowEvent,
        QTextBlockFormat,
        QTextCursor,
        QWheelEvent,
    )
    from PySide6.QtWidgets import (
        QAbstractButton,
        QAbstractItemView,
        QApplication,
        QButtonGroup,
        QCheckBox,
        QComboBox,
        QDialog,
        QDialogButtonBox,
        QDoubleSpinBox,
        QFileDialog,
        QFormLayout,
        QFrame,
        QGridLayout,
        QGroupBox,
        QHBoxLayout,
        QInputDialog,
        QLabel,
        QLineEdit,
        QListWidget,
        QListWidgetItem,
        QMainWindow,
        QMenu,
        QMessageBox,
        QPlainTextEdit,
        QPushButton,
        QScrollArea,
        QSizePolicy,
        QSpinBox,
        QSplitter,
        QStackedWidget,
        QStatusBar,
        QSystemTrayIcon,
        QTableWidget,
        QTableWidgetItem,
        QTabWidget,
        QTextBrowser,
        QTextEdit,
        QToolButton,
        QToolTip,
        QVBoxLayout,
        QWidget,
    )

_FROM_CORE = (
    "QByteArray", "QEvent", "QObject", "QPoint", "QPointF", "QProcess", "QRect", "QRectF",
    "QSettings", "QSize", "Qt", "QTimer", "QUrl", "Signal", "Slot",
)
_FROM_GUI = (
    "QAction", "QActionGroup", "QBrush", "QCloseEvent", "QColor", "QContextMenuEvent",
    "QCursor", "QDesktopServices", "QFileOpenEvent", "QFont", "QFontDatabase", "QIcon",
    "QKeySequence", "QMouseEvent", "QPainter", "QPainterPath", "QPaintEvent", "QPalette",
    "QPen", "QPixmap", "QResizeEvent", "QShortcut", "QShowEvent", "QTextBlockFormat",
    "QTextCursor", "QWheelEvent",
)
_FROM_WIDGETS = (
    "QAbstractButton", "QAbstractItemView", "QApplication", "QButtonGroup", "QCheckBox",
    "QComboBox", "QDialog", "QDialogButtonBox", "QDoubleSpinBox", "QFileDialog", "QFormLayout",
    "QFrame", "QGridLayout", "QGroupBox", "QHBoxLayout", "QInputDialog", "QLabel", "QLineEdit",
    "QListWidget", "QListWidgetItem", "QMainWindow", "QMenu", "QMessageBox", "QPlainTextEdit",
    "QPushButton", "QScrollArea", "QSizePolicy", "QSpinBox", "QSplitter", "QStackedWidget",
    "QStatusBar", "QSystemTrayIcon", "QTableWidget", "QTableWidgetItem", "QTabWidget",
    "QTextBrowser", "QTextEdit", "QToolButton", "QToolTip", "QVBoxLayout", "QWidget",
)
_WHERE: dict[str, ModuleType] = {
    **dict.fromkeys(_FROM_CORE, QtCore),
    **dict.fromkeys(_FROM_GUI, QtGui),
    **dict.fromkeys(_FROM_WIDGETS, QtWidgets),
}
"""The Qt module of each name handed out.  A name is looked up in its module when first
asked for (PySide6 builds a class's Python type on that first look-up): a program
builds the types of the windows it opens, not all of these (the server window needs
about a third of them)."""


def __getattr__(name: str) -> object:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value: object = getattr(module, name)
    globals()[name] = value
    return value


__all__ = [
    "QAbstractButton",
    "QAbstractItemView",
    "QAction",
    "QActionGroup",
    "QApplication",
    "QBrush",
    "QButtonGroup",
    "QByteArray",
    "QCheckBox",
    "QCloseEvent",
    "QColor",
    "QComboBox",
    "QContextMenuEvent",
    "QCursor",
    "QDesktopServices",
    "QDialog",
    "QDialogButtonBox",
    "QDoubleSpinBox",
    "QEvent",
    "QFileDialog",
    "QFileOpenEvent",
    "QFont",
    "QFontDatabase",
    "QFormLayout",
    "QFrame",
    "QGridLayout",
    "QGroupBox",
    "QHBoxLayout",
    "QIcon",
    "QInputDialog",
    "QKeySequence",
    "QLabel",
    "QLineEdit",
    "QListWidget",
    "QListWidgetItem",
    "QMainWindow",
    "QMenu",
    "QMessageBox",
    "QMouseEvent",
    "QObject",
    "QPaintEvent",
    "QPainter",
    "QPainterPath",
    "QPalette",
    "QPen",
    "QPixmap",
    "QPlainTextEdit",
    "QPoint",
    "QPointF",
    "QProcess",
    "QPushButton",
    "QRect",
    "QRectF",
    "QResizeEvent",
    "QScrollArea",
    "QSettings",
    "QShortcut",
    "QShowEvent",
    "QSize",
    "QSizePolicy",
    "QSpinBox",
    "QSplitter",
    "QStackedWidget",
    "QStatusBar",
    "QSystemTrayIcon",
    "QTabWidget",
    "QTableWidget",
    "QTableWidgetItem",
    "QTextBlockFormat",
    "QTextBrowser",
    "QTextCursor",
    "QTextEdit",
    "QTimer",
    "QToolButton",
    "QToolTip",
    "QUrl",
    "QVBoxLayout",
    "QWheelEvent",
    "QWidget",
    "Qt",
    "Signal",
    "Slot",
    "added",
    "load_qasync",
]


def load_qasync() -> ModuleType:
    """qasync, on PySide6 whatever else is installed: qasync picks the first Qt binding
    it finds (PyQt6 before PySide6, and a logger such as not1mm brings PyQt6), or the one
    ``QT_API`` names; this process uses PySide6, so ``QT_API`` says so (matplotlib's Qt
    canvas reads it too)."""
    os.environ["QT_API"] = "pyside6"
    import qasync

    module: ModuleType = qasync
    return module


def added(action: QAction | None) -> QAction:
    """The action a menu's ``addAction`` just made (the type information of some PySide6
    releases, 6.8 among them, says it may be None; Qt always makes one)."""
    if action is None:
        raise RuntimeError("Qt made no menu action")
    return action
