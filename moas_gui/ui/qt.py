"""The one place moas-gui imports Qt from (PySide6-Essentials).

Windows import their Qt names from here, so a change of binding or a missing
module shows up in one file.
"""

from __future__ import annotations

from PySide6.QtCore import (
    QByteArray,
    QEvent,
    QObject,
    QPoint,
    QPointF,
    QRectF,
    QSettings,
    QSize,
    Qt,
    QTimer,
    QUrl,
    Signal,
)
from PySide6.QtGui import (
    QAction,
    QActionGroup,
    QBrush,
    QCloseEvent,
    QColor,
    QDesktopServices,
    QFont,
    QFontDatabase,
    QIcon,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPaintEvent,
    QPalette,
    QPen,
    QPixmap,
    QTextCursor,
)
from PySide6.QtWidgets import (
    QAbstractButton,
    QApplication,
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFrame,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QMainWindow,
    QMenu,
    QMessageBox,
    QPlainTextEdit,
    QScrollArea,
    QPushButton,
    QSizePolicy,
    QSpinBox,
    QStatusBar,
    QSystemTrayIcon,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

__all__ = [
    "QAbstractButton", "QAction", "QActionGroup", "QApplication", "QBrush", "QButtonGroup",
    "QByteArray", "QCheckBox",
    "QCloseEvent", "QColor", "QComboBox", "QDesktopServices", "QDialog", "QDialogButtonBox",
    "QDoubleSpinBox", "QEvent", "QFileDialog", "QFont", "QFontDatabase", "QFrame", "QGridLayout",
    "QGroupBox", "QHBoxLayout", "QIcon", "QLabel", "QLineEdit", "QMainWindow", "QMenu",
    "QMessageBox", "QMouseEvent", "QObject", "QPaintEvent", "QPainter", "QPainterPath",
    "QPalette", "QPen",
    "QPixmap", "QPlainTextEdit", "QScrollArea", "QPoint", "QPointF", "QPushButton", "QRectF", "QSettings",
    "QSize", "QSizePolicy", "QSpinBox", "QStatusBar", "QSystemTrayIcon", "QTextCursor",
    "QTimer", "QToolButton", "QUrl", "QVBoxLayout", "QWidget", "Qt", "Signal",
]
