"""The compass: where a rotator points, and a place to click to turn it (manual 5.15).

:class:`CompassWidget` draws one rotator as the antenna on it sees the world
(the antenna's offset added): the current heading as a thick amber needle,
the target as a dashed cyan line while turning, the travel's dead zone
hatched red, an overlap tinted, the stop as a red mark on the rim, and an electrical
system's directions as dots (the one in use filled).  An offline rotator is
drawn grey and ignores the mouse.  Press, drag and release anywhere on the
face to ask for a heading: :attr:`CompassWidget.rotate_requested` carries the
*rotator's* heading (offset taken off), rounded to a whole degree.  Which
direction of an electrical system is nearest is the server's business.

:class:`CompassPanel` adds a choice of rotator, the heading in figures and a
Stop button.  :func:`compass_targets` decides which rotators a radio's
compass offers: those of its transmit and receive antennas first, then those
of the antennas on its buttons.

While the window is not connected, :meth:`CompassPanel.set_greyed` draws the
compass grey with the reason across it and no heading in figures (the last
one heard is not the heading now); a click or Stop then emits
:attr:`CompassPanel.refused` for the window to answer, instead of nothing.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from moas_gui.client.model import ButtonType, LayoutView, RadioView, RotatorView, Snapshot

from .client_style import Colours
from .compass_geometry import (
    antenna_heading,
    heading_at,
    point_at,
    qt_arc,
    rotator_heading,
    travel_marks,
)
from .qt import (
    QBrush,
    QColor,
    QComboBox,
    QFont,
    QHBoxLayout,
    QLabel,
    QMouseEvent,
    QPainter,
    QPainterPath,
    QPaintEvent,
    QPen,
    QPointF,
    QPushButton,
    QRectF,
    QSize,
    QSizePolicy,
    Qt,
    QVBoxLayout,
    QWidget,
    Signal,
)

__all__ = ["CompassPanel", "CompassTarget", "CompassWidget", "Direction", "compass_targets"]

CARDINALS = {0: "N", 90: "E", 180: "S", 270: "W"}


@dataclass(frozen=True, slots=True)
class Direction:
    """One direction of an electrical system (a 4-square's antenna)."""

    heading: float
    label: str
    active: bool = False


@dataclass(frozen=True, slots=True)
class CompassTarget:
    """A rotator as a radio's compass shows it."""

    rotator: RotatorView
    antenna: str = ""
    """The antenna whose direction is shown (its offset applies)."""
    offset: float = 0.0
    directions: tuple[Direction, ...] = ()

    @property
    def title(self) -> str:
        return f"{self.rotator.name} \u2013 {self.antenna}" if self.antenna else self.rotator.name


def compass_targets(snapshot: Snapshot, radio: RadioView | None,
                    layout: LayoutView | None, *,
                    selection_known: bool = True) -> tuple[CompassTarget, ...]:
    """The rotators the radio's compass offers (see the module notes).  Without
    ``selection_known`` (the switches are stopped) no direction of an electrical
    system is marked as in use."""
    if radio is None:
        return ()
    in_use = [i for i in (radio.tx, radio.rx) if i is not None]
    marked = in_use if selection_known else []
    on_buttons = [b.id for b in (layout.buttons if layout else ())
                  if b.type is ButtonType.ANTENNA]
    seen: dict[int, CompassTarget] = {}
    for antenna_id in _unique(in_use + on_buttons):
        antenna = snapshot.antenna(antenna_id)
        if antenna is None or antenna.rotator is None or antenna.rotator in seen:
            continue
        rotator = snapshot.rotator(antenna.rotator)
        if rotator is None:
            continue
        if rotator.electrical:
            directions = tuple(
                Direction(a.offset, a.short or a.name, a.id in marked)
                for a in snapshot.antennas_with_rotator(rotator.id))
            seen[rotator.id] = CompassTarget(rotator, "", 0.0, directions)
        else:
            seen[rotator.id] = CompassTarget(rotator, antenna.short or antenna.name,
                                             antenna.offset)
    return tuple(seen.values())


def _unique(items: Iterable[int]) -> list[int]:
    return list(dict.fromkeys(items))


class CompassWidget(QWidget):
    """A round compass for one :class:`CompassTarget`; see the module notes."""

    rotate_requested = Signal(float)
    """The rotator heading the user asked for (degrees, whole)."""
    refused = Signal()
    """A click while greyed: the window says why nothing turns."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.target: CompassTarget | None = None
        self._drag: float | None = None
        self.greyed = ""
        """Why the compass is grey and a click is answered, not sent ("" when live)."""
        self.setMinimumSize(220, 220)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setCursor(Qt.CursorShape.CrossCursor)

    def sizeHint(self) -> QSize:
        return QSize(340, 340)

    def heightForWidth(self, width: int) -> int:
        return width

    def show_target(self, target: CompassTarget | None) -> None:
        self.target = target
        if target is None or not target.rotator.online:
            self._drag = None
        self.update()

    @property
    def usable(self) -> bool:
        return self.target is not None and self.target.rotator.online

    # -- geometry ---------------------------------------------------------------------------------
    def face(self) -> tuple[float, float, float]:
        """Centre x, centre y and radius of the dial, in widget pixels."""
        w, h = self.width(), self.height()
        return w / 2.0, h / 2.0, max(10.0, min(w, h) / 2.0 - 26.0)

    def heading_for_point(self, x: float, y: float) -> float | None:
        """The antenna heading under the widget point ``(x, y)``."""
        cx, cy, _ = self.face()
        return heading_at(cx, cy, x, y)

    def point_for_heading(self, heading: float, fraction: float = 0.8) -> QPointF:
        """A widget point at ``fraction`` of the radius towards antenna ``heading``."""
        cx, cy, radius = self.face()
        x, y = point_at(cx, cy, radius * fraction, heading)
        return QPointF(x, y)

    # -- mouse ----------------------------------------------------------------------------------
    def mousePressEvent(self, event: QMouseEvent) -> None:
        if not self.usable or self.greyed or event.button() != Qt.MouseButton.LeftButton:
            super().mousePressEvent(event)
            return
        self._drag = self.heading_for_point(event.position().x(), event.position().y())
        self.update()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if self.greyed:
            return
        if self._drag is not None or (self.usable and event.buttons()
                                      & Qt.MouseButton.LeftButton):
            heading = self.heading_for_point(event.position().x(), event.position().y())
            if heading is not None:
                self._drag = heading
                self.update()

    def set_greyed(self, why: str) -> None:
        if why != self.greyed:
            self.greyed = why
            self._drag = None
            self.setToolTip(f"Rotator: {why}" if why else "")
            self.update()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton:
            return
        if self.greyed:
            self.refused.emit()
            return
        if self.target is None:
            return
        heading = self.heading_for_point(event.position().x(), event.position().y())
        if heading is None:
            heading = self._drag
        self._drag = None
        self.update()
        if heading is None or not self.usable:
            return
        wanted = rotator_heading(heading, self.target.offset)
        self.rotate_requested.emit(float(round(wanted) % 360))

    # -- painting -------------------------------------------------------------------------------
    def paintEvent(self, event: QPaintEvent) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        cx, cy, radius = self.face()
        centre = QPointF(cx, cy)
        dial = QRectF(cx - radius, cy - radius, 2 * radius, 2 * radius)
        target = self.target
        online = target is not None and target.rotator.online and not self.greyed

        painter.setPen(QPen(Colours.COMPASS_RING, 3))
        painter.setBrush(QBrush(Colours.COMPASS_FACE))
        painter.drawEllipse(dial)
        if target is not None:
            self._paint_travel(painter, dial, target)
        self._paint_scale(painter, cx, cy, radius, online)
        if target is None or self.greyed:
            if self.greyed:
                painter.setPen(Qt.PenStyle.NoPen)
                painter.setBrush(QBrush(QColor(0, 0, 0, 140)))
                painter.drawEllipse(dial)
            self._centre_text(painter, dial, "NOT CONNECTED" if self.greyed else "no rotator",
                              Colours.OFFLINE.lighter(160) if self.greyed else Colours.DIM_TEXT)
            painter.end()
            return
        rotator = target.rotator
        if online and rotator.target is not None and (rotator.moving or rotator.target
                                                        != rotator.heading):
            aim = antenna_heading(rotator.target, target.offset)
            painter.setPen(QPen(Colours.TARGET, 3, Qt.PenStyle.DashLine))
            painter.drawLine(centre, self.point_for_heading(aim, 0.97))
            painter.setBrush(QBrush(Colours.TARGET))
            painter.drawEllipse(self.point_for_heading(aim, 0.97), 6, 6)
        if self._drag is not None:
            painter.setPen(QPen(Colours.DRAG, 2, Qt.PenStyle.DotLine))
            painter.drawLine(centre, self.point_for_heading(self._drag, 1.0))
        if rotator.heading is not None:
            self._paint_needle(painter, antenna_heading(rotator.heading, target.offset), online)
        for direction in target.directions:  # on top of the needle: the one in use stays seen
            self._paint_direction(painter, direction, online)
        painter.setPen(Qt.PenStyle.NoPen)
        painter.setBrush(QBrush(Colours.COMPASS_RING))
        painter.drawEllipse(centre, 7, 7)
        if not online:
            painter.setBrush(QBrush(QColor(0, 0, 0, 140)))
            painter.drawEllipse(dial)
            self._centre_text(painter, dial, "OFFLINE", Colours.OFFLINE.lighter(160))
        painter.end()

    def _paint_travel(self, painter: QPainter, dial: QRectF, target: CompassTarget) -> None:
        rotator = target.rotator
        marks = travel_marks(rotator.ccw_limit, rotator.rotation, rotator.has_stop,
                             target.offset)
        inner = dial.adjusted(2, 2, -2, -2)
        if marks.overlap is not None:
            start, span = qt_arc(*marks.overlap)
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QBrush(Colours.OVERLAP))
            painter.drawPie(inner, start, span)
        if marks.dead is not None:
            start, span = qt_arc(*marks.dead)
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QBrush(Colours.DEAD_ZONE))
            painter.drawPie(inner, start, span)
            painter.setBrush(QBrush(QColor("#ff8a80"), Qt.BrushStyle.BDiagPattern))
            painter.drawPie(inner, start, span)
        if marks.stop is not None:
            # a mark on the rim, not a spoke from the centre: with no heading to draw, a
            # spoke would read as a needle pointing at the stop
            painter.setPen(QPen(Colours.STOP, 5))
            painter.drawLine(self.point_for_heading(marks.stop, 0.78),
                             self.point_for_heading(marks.stop, 1.0))

    def _paint_scale(self, painter: QPainter, cx: float, cy: float, radius: float,
                     online: bool) -> None:
        tick = Colours.COMPASS_TICK if online else Colours.OFFLINE
        font = QFont(self.font())
        font.setPointSizeF(max(8.0, radius / 12.0))
        font.setBold(True)
        painter.setFont(font)
        for degree in range(0, 360, 10):
            major = degree % 30 == 0
            x1, y1 = point_at(cx, cy, radius - (12 if major else 6), degree)
            x2, y2 = point_at(cx, cy, radius, degree)
            painter.setPen(QPen(tick, 2.5 if major else 1.2))
            painter.drawLine(QPointF(x1, y1), QPointF(x2, y2))
            if major:
                text = CARDINALS.get(degree, str(degree))
                colour = Colours.COMPASS_NORTH if degree == 0 and online else (
                    Colours.TEXT if degree in CARDINALS and online else tick)
                lx, ly = point_at(cx, cy, radius + 14, degree)
                painter.setPen(colour)
                painter.drawText(QRectF(lx - 20, ly - 10, 40, 20),
                                 int(Qt.AlignmentFlag.AlignCenter), text)

    def _paint_direction(self, painter: QPainter, direction: Direction, online: bool) -> None:
        colour = Colours.DIRECTION if online else Colours.OFFLINE
        point = self.point_for_heading(direction.heading, 0.72)
        painter.setPen(QPen(colour, 2))
        painter.setBrush(QBrush(colour) if direction.active else Qt.BrushStyle.NoBrush)
        painter.drawEllipse(point, 9, 9)
        label = self.point_for_heading(direction.heading, 0.55)
        painter.drawText(QRectF(label.x() - 40, label.y() - 10, 80, 20),
                         int(Qt.AlignmentFlag.AlignCenter), direction.label)

    def _paint_needle(self, painter: QPainter, heading: float, online: bool) -> None:
        colour = Colours.HEADING if online else Colours.OFFLINE
        cx, cy, radius = self.face()
        tip = self.point_for_heading(heading, 0.9)
        left = point_at(cx, cy, radius * 0.72, heading - 5)
        right = point_at(cx, cy, radius * 0.72, heading + 5)
        painter.setPen(QPen(colour, 6, Qt.PenStyle.SolidLine, Qt.PenCapStyle.RoundCap))
        painter.drawLine(QPointF(cx, cy), self.point_for_heading(heading, 0.74))
        arrow = QPainterPath(tip)
        arrow.lineTo(QPointF(*left))
        arrow.lineTo(QPointF(*right))
        arrow.closeSubpath()
        painter.setPen(Qt.PenStyle.NoPen)
        painter.setBrush(QBrush(colour))
        painter.drawPath(arrow)

    def _centre_text(self, painter: QPainter, dial: QRectF, text: str, colour: QColor) -> None:
        font = QFont(self.font())
        font.setPointSizeF(max(10.0, dial.height() / 14.0))
        font.setBold(True)
        painter.setFont(font)
        painter.setPen(colour)
        box = QRectF(dial.left(), dial.center().y() + dial.height() * 0.12, dial.width(),
                     dial.height() * 0.2)
        painter.drawText(box, int(Qt.AlignmentFlag.AlignCenter), text)


class CompassPanel(QWidget):
    """A rotator chooser, the compass, the heading in figures and a Stop button."""

    rotate_requested = Signal(int, float)
    """(rotator, rotator heading)"""
    stop_requested = Signal(int)
    refused = Signal(str)
    """A click or Stop while greyed ("Turn" or "Stop"): the window answers why not."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.targets: tuple[CompassTarget, ...] = ()
        self._user_choice: int | None = None
        self._prefer: int | None = None
        self.chooser = QComboBox(self)
        self.chooser.setSizeAdjustPolicy(
            QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon)
        self.chooser.setMinimumContentsLength(16)
        self.chooser.setAccessibleName("Rotator")
        self.compass = CompassWidget(self)
        self.heading_label = QLabel("\u2013", self)
        self.heading_label.setObjectName("heading")
        self.heading_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.stop_button = QPushButton("\u25a0 STOP", self)
        self.stop_button.setObjectName("stop")
        self.stop_button.setToolTip("Stop this rotator where it is")

        box = QVBoxLayout(self)
        box.setContentsMargins(0, 0, 0, 0)
        box.addWidget(self.chooser)
        box.addWidget(self.compass, 1)
        row = QHBoxLayout()
        row.addWidget(self.heading_label, 1)
        row.addWidget(self.stop_button)
        box.addLayout(row)

        self.greyed = ""
        self.chooser.currentIndexChanged.connect(self._chosen)
        self.chooser.activated.connect(self._picked)
        self.compass.rotate_requested.connect(self._rotate)
        self.compass.refused.connect(lambda: self.refused.emit("Turn"))
        self.stop_button.clicked.connect(self._stop)
        self._chosen()

    @property
    def current(self) -> CompassTarget | None:
        index = self.chooser.currentIndex()
        return self.targets[index] if 0 <= index < len(self.targets) else None

    def show_targets(self, targets: tuple[CompassTarget, ...], prefer: int | None = None) -> None:
        """Shows ``targets``: the rotator the user chose while it is there (until
        ``prefer`` changes), else rotator ``prefer`` (the transmit antenna's),
        else the one shown before, else the first."""
        before = self.current.rotator.id if self.current else None
        if prefer != self._prefer:  # a new antenna in use: the chooser follows its rotator
            self._prefer = prefer
            if prefer is not None:
                self._user_choice = None
        self.targets = targets
        present = {t.rotator.id for t in targets}
        wanted = next((r for r in (self._user_choice, prefer, before) if r in present), None)
        index = next((i for i, t in enumerate(targets) if t.rotator.id == wanted), 0)
        self.chooser.blockSignals(True)
        self.chooser.clear()
        for target in targets:
            state = "" if target.rotator.online else " (offline)"
            self.chooser.addItem(target.title + state)
        self.chooser.setCurrentIndex(index if targets else -1)
        self.chooser.blockSignals(False)
        self._chosen()

    def choose(self, rotator_id: int) -> bool:
        """Shows rotator ``rotator_id`` as if the user had picked it."""
        for index, target in enumerate(self.targets):
            if target.rotator.id == rotator_id:
                self.chooser.setCurrentIndex(index)
                self._user_choice = rotator_id
                return True
        return False

    def _picked(self, _index: int) -> None:
        current = self.current
        self._user_choice = current.rotator.id if current else None

    def set_greyed(self, why: str) -> None:
        """Grey with ``why`` (not connected), or live again with ""."""
        self.greyed = why
        self.compass.set_greyed(why)
        self.stop_button.setProperty("greyed", "true" if why else "false")
        self.stop_button.setToolTip(f"Stop: {why}" if why else "Stop this rotator where it is")
        style = self.stop_button.style()
        style.unpolish(self.stop_button)
        style.polish(self.stop_button)
        self._chosen()

    def _chosen(self, _index: int = 0) -> None:
        target = self.current
        self.compass.show_target(target)
        self.chooser.setEnabled(bool(self.targets))
        self.stop_button.setEnabled(
            target is not None and (bool(self.greyed) or target.rotator.online))
        self.heading_label.setText("not connected" if self.greyed and target is not None
                                   else _heading_text(target))

    def _rotate(self, heading: float) -> None:
        target = self.current
        if target is not None:
            self.rotate_requested.emit(target.rotator.id, heading)

    def _stop(self) -> None:
        target = self.current
        if self.greyed:
            self.refused.emit("Stop")
        elif target is not None:
            self.stop_requested.emit(target.rotator.id)


def _heading_text(target: CompassTarget | None) -> str:
    if target is None:
        return "no rotator"
    rotator = target.rotator
    if not rotator.online:
        return "offline"
    if rotator.heading is None:
        return "heading unknown"
    text = f"{antenna_heading(rotator.heading, target.offset):.0f}\u00b0"
    if rotator.target is not None and rotator.moving:
        text += f" \u2192 {antenna_heading(rotator.target, target.offset):.0f}\u00b0"
    return text
