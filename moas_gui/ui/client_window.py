"""The button and compass client window (manual 4.3, 5.15-5.20).

One window serves one radio at a time, chosen by station and radio.  It shows
only what the server says (through a
:class:`~moas_gui.client.connection.ClientConnection`) and sends every wish as
a protocol request; it holds no selection logic of its own.  The built-in
client of the server window and ``moas-client`` on another computer are the
same window over the same protocol (the built-in one over loopback)::

    +-------------------------------------------------------------------------+
    | (o) Connected to 127.0.0.1:12059                          big-station   |
    | Station [1] Radio [1]   Select for [TX+RX][TX][RX]   Rows [4] Cols [3]  |
    | 14025.0 kHz   TX 20m stack   RX Beverage NE           [TX] [INHIBITED]  |
    | +-------------------------------------------+  +----------------------+ |
    | |  button grid (layout)                     |  | rotator [v]          | |
    | +-------------------------------------------+  |     compass          | |
    | Relative  [< Prev] [list v] [Go] [Next >]      |  045 deg   [STOP]    | |
    | Frequency [14025.0] [ ] split TX [     ] [Set] +----------------------+ |
    | status line: the server's last refusal                                  |
    +-------------------------------------------------------------------------+
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Coroutine
from typing import Any, Protocol

from moas_gui.client.connection import ClientConnection, ClientError, ServerError, Target
from moas_gui.client.events import (
    ClientEvent,
    LayoutChanged,
    LinkChanged,
    LinkState,
    ProblemSeen,
    RadioChanged,
    RotatorChanged,
    StateReceived,
    SwitchChanged,
)
from moas_gui.client.keys import ClientKeys
from moas_gui.client.model import (
    ButtonState,
    ButtonType,
    ButtonView,
    LayoutView,
    RadioView,
    Snapshot,
    explain,
    may_release,
)
from moas_gui.client.screen import (
    Screen,
    ScreenState,
    StatusMessage,
    Tone,
    button_answer,
    screen_state,
)

from .button_grid import ButtonGrid
from .client_panels import FrequencyBox, RelativeStrip, frequency_text
from .client_style import CLIENT_STYLESHEET, Colours, dark_palette
from .compass import CompassPanel, compass_targets
from .elided_label import ElidedLabel
from .knob import KnobControl
from .qt import (
    QAction,
    QButtonGroup,
    QCloseEvent,
    QComboBox,
    QCursor,
    QFrame,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMenu,
    QPushButton,
    QScrollArea,
    QSpinBox,
    Qt,
    QToolTip,
    QVBoxLayout,
    QWidget,
    Signal,
)
from .screen_fit import fit_to_screen
from .token_dialog import TokenKeeper

__all__ = ["ClientWindow", "open_builtin_client"]

log = logging.getLogger(__name__)

TARGETS: tuple[tuple[Target, str, str], ...] = (
    ("both", "TX + RX", "A press selects the antenna for transmit and receive"),
    ("tx", "TX only", "A press selects the transmit antenna only"),
    ("rx", "RX only", "A press selects a different receive antenna"),
)


class ServerAppLike(Protocol):
    @property
    def client_address(self) -> tuple[str, int] | None: ...

    @property
    def client_fingerprint(self) -> str | None: ...


def loopback_for(host: str) -> str:
    """The address a client on the same computer uses for a server bound to ``host``."""
    if host in ("", "0.0.0.0"):
        return "127.0.0.1"
    if host == "::":
        return "::1"
    return host


def open_builtin_client(server_app: ServerAppLike) -> ClientWindow:
    """The server's View > Client: a client window connected over loopback, shown."""
    address = server_app.client_address
    if address is None:
        raise ValueError("the server is not accepting clients: no configuration is open")
    host, port = address
    pin = server_app.client_fingerprint  # over TLS: the server's own certificate, pinned
    connection = ClientConnection(loopback_for(host), port, name="built-in client",
                                  tls=pin is not None, pin=pin)
    window = ClientWindow(connection)
    window.start()
    window.show()
    return window


class ClientWindow(QMainWindow):
    """See the module notes.  ``start()`` begins connecting (needs a running loop)."""

    closed = Signal()
    """The window was closed (its connection is closing)."""

    def __init__(self, connection: ClientConnection, *, station: int | None = None,
                 radio: int | None = None, rows: int = 4, columns: int = 3,
                 parent: QWidget | None = None, keys: ClientKeys | None = None) -> None:
        super().__init__(parent)
        self.connection = connection
        self.snapshot: Snapshot | None = None
        self.layout_view: LayoutView | None = None
        self._link_detail = ""
        self._wanted_radio = (station, radio)
        self._layout_asked: tuple[int, int, int, int] | None = None
        self._layout_shape: tuple[int, int] | None = None
        self._tasks: set[asyncio.Task[Any]] = set()
        self._closed = False
        self._stations: list[int] = []
        self._radios: list[int] = []
        self.link_state = connection.link
        self._screen_shown: Screen | None = None

        self.setWindowTitle(f"MOAS Client \u2013 {connection.address}")
        self.setPalette(dark_palette(self.palette()))
        self.setStyleSheet(CLIENT_STYLESHEET)
        self._build(rows, columns)
        self._darken_inputs()
        self._show_link(connection.link, "")
        self._unsubscribe = connection.subscribe(self._on_event)
        self.tokens = TokenKeeper(self, keys) if keys is not None else None
        """The Operator menu and the token request (moas-client; the built-in client on
        this computer needs no token)."""
        fit_to_screen(self, 1040, 660)

    # -- building ---------------------------------------------------------------------------------
    def _build(self, rows: int, columns: int) -> None:
        root = QWidget(self)
        root.setObjectName("clientRoot")
        # on a small screen (a laptop, or scale 2) the window may be smaller than its
        # content: the content scrolls instead of squeezing labels into each other
        self.scroll_area = fit_small_screens(root, self)
        frame = QWidget(self)
        framed = QVBoxLayout(frame)
        framed.setContentsMargins(0, 0, 0, 0)
        framed.setSpacing(0)
        framed.addWidget(self.scroll_area, 1)
        self.status_line = QLabel(frame)
        """The status line: one :class:`StatusMessage` at a time, wrapped, never cut off,
        always in view below the scrolling content (a layout gives a wrapped label the
        height its text needs at the window's width, and no more)."""
        self.status_line.setObjectName("statusLine")
        self.status_line.setWordWrap(True)
        self.status_line.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        framed.addWidget(self.status_line)
        self.setCentralWidget(frame)
        outer = QVBoxLayout(root)
        outer.setContentsMargins(10, 8, 10, 6)
        outer.setSpacing(8)

        top = QHBoxLayout()
        self.link_label = ElidedLabel("", root)  # a long reason must not widen the window
        self.link_label.setObjectName("link")
        self.config_label = QLabel(root)
        self.config_label.setStyleSheet("color: #9fb1bd;")
        top.addWidget(self.link_label)
        top.addStretch(1)
        top.addWidget(self.config_label)
        outer.addLayout(top)

        choose = QHBoxLayout()
        self.station_box = QComboBox(root)
        self.radio_box = QComboBox(root)
        self.station_box.setMinimumWidth(70)
        self.radio_box.setMinimumWidth(70)
        choose.addWidget(QLabel("Station", root))
        choose.addWidget(self.station_box)
        choose.addWidget(QLabel("Radio", root))
        choose.addWidget(self.radio_box)
        choose.addSpacing(18)
        choose.addWidget(QLabel("Select for", root))
        self.target_group = QButtonGroup(self)
        self.target_buttons: dict[Target, QPushButton] = {}
        for target, text, tip in TARGETS:
            button = QPushButton(text, root)
            button.setCheckable(True)
            button.setToolTip(tip)
            self.target_group.addButton(button)
            self.target_buttons[target] = button
            choose.addWidget(button)
        self.target_buttons["both"].setChecked(True)
        choose.addStretch(1)
        self.rows_box = QSpinBox(root)
        self.columns_box = QSpinBox(root)
        for box, value in ((self.rows_box, rows), (self.columns_box, columns)):
            box.setRange(1, 50)
            box.setValue(value)
        choose.addWidget(QLabel("Rows", root))
        choose.addWidget(self.rows_box)
        choose.addWidget(QLabel("Columns", root))
        choose.addWidget(self.columns_box)
        outer.addLayout(choose)

        display_row = QHBoxLayout()
        self.display = ElidedLabel("\u2013", root)
        self.display.setObjectName("display")
        self.display.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.badge_tx = QLabel("\u25cf TRANSMITTING", root)
        self.badge_tx.setObjectName("badgeTx")
        self.badge_inhibit = QLabel("INHIBITED", root)
        self.badge_inhibit.setObjectName("badgeInhibit")
        self.badge_active = QLabel("TX FOCUS", root)
        self.badge_active.setObjectName("badgeActive")
        self.badge_active.setToolTip("The logger says this radio transmits next (SO2R)")
        self.badge_focus = QLabel("RX FOCUS", root)
        self.badge_focus.setObjectName("badgeFocus")
        self.badge_focus.setToolTip("The logger says the operator is on this radio")
        for badge in (self.badge_tx, self.badge_inhibit, self.badge_active, self.badge_focus):
            badge.hide()
        display_row.addWidget(self.display, 1)
        display_row.addWidget(self.badge_active)
        display_row.addWidget(self.badge_focus)
        display_row.addWidget(self.badge_tx)
        display_row.addWidget(self.badge_inhibit)
        outer.addLayout(display_row)
        self.note_label = QLabel(root)
        self.note_label.setStyleSheet("color: #ffab40; font-weight: bold;")
        self.note_label.setWordWrap(True)
        self.note_label.hide()
        note_row = QHBoxLayout()
        note_row.addWidget(self.note_label, 1)
        self.release_button = QPushButton("Release", root)
        """Shown while the radio is held and this client may release it: the hold goes,
        the antennas follow the frequency again (docs/antenna-genius.md)."""
        self.release_button.setToolTip("Release the hold: the antennas follow the "
                                       "radio's frequency again")
        self.release_button.hide()
        self.release_button.clicked.connect(self._release)
        note_row.addWidget(self.release_button, 0, Qt.AlignmentFlag.AlignTop)
        outer.addLayout(note_row)

        body = QHBoxLayout()
        left = QVBoxLayout()
        self.grid = ButtonGrid(root)
        left.addWidget(self.grid, 1)
        self.relative_strip = RelativeStrip(root)
        self.frequency_box = FrequencyBox(root)
        left.addWidget(self.relative_strip)
        left.addWidget(self.frequency_box)
        self.previous_button = self.relative_strip.previous_button
        self.next_button = self.relative_strip.next_button
        self.relative_box = self.relative_strip.list_box
        self.relative_go = self.relative_strip.use_button
        self.khz_box = self.frequency_box.khz_box
        self.split_box = self.frequency_box.split_box
        self.tx_khz_box = self.frequency_box.tx_khz_box
        self.frequency_button = self.frequency_box.set_button
        body.addLayout(left, 3)
        compass_box = QGroupBox("Rotator", root)
        compass_layout = QVBoxLayout(compass_box)
        self.compass_panel = CompassPanel(compass_box)
        compass_layout.addWidget(self.compass_panel)
        body.addWidget(compass_box, 2)
        outer.addLayout(body, 1)


        self.message: StatusMessage | None = None
        """What the status line shows now (None: nothing)."""

        self.station_box.currentIndexChanged.connect(self._station_chosen)
        self.radio_box.currentIndexChanged.connect(lambda _i: self._radio_chosen())
        self.rows_box.valueChanged.connect(lambda _v: self._ask_layout())
        self.columns_box.valueChanged.connect(lambda _v: self._ask_layout())
        self.grid.pressed.connect(lambda view: self._pressed(view, exclusive=False))
        self.grid.double_pressed.connect(lambda view: self._pressed(view, exclusive=True))
        self.compass_panel.rotate_requested.connect(self._rotate)
        self.compass_panel.stop_requested.connect(self._stop)
        self.relative_strip.step_requested.connect(lambda step: self._relative(step=step))
        self.relative_strip.index_requested.connect(lambda index: self._relative(index=index))
        self.frequency_box.frequency_requested.connect(self._send_frequency)
        self.compass_panel.refused.connect(self._refused)
        self.why_action = QAction("Why?", self)
        """On the button grid's context menu: why the button under the pointer is as it
        is (between buttons: why the radio has its antennas)."""
        self.why_action.triggered.connect(lambda: self._show_why(self._why_view))
        self._why_view: ButtonView | None = None
        self.grid.why_asked.connect(self._why_menu)
        self.knob = KnobControl(self)
        """Mouse wheel, keys and USB knobs step through the antennas (docs/web-client.md)."""

    def _darken_inputs(self) -> None:
        """Combo and spin boxes are drawn by the style (so they keep their arrows):
        they get the dark palette and a larger font one by one."""
        palette = dark_palette(self.palette())
        for widget in (self.station_box, self.radio_box, self.rows_box, self.columns_box,
                       self.relative_box, self.khz_box, self.tx_khz_box,
                       self.compass_panel.chooser):
            widget.setPalette(palette)
            font = widget.font()
            font.setPointSizeF(max(font.pointSizeF(), 11.0))
            widget.setFont(font)
            widget.setMinimumHeight(30)

    # -- life -----------------------------------------------------------------------------------
    def start(self) -> None:
        """Starts the connection on the running loop."""
        self.connection.start()

    async def aclose(self) -> None:
        """Closes the window's connection and waits for its requests to end (also after
        the window was closed, whose close only asks them to end)."""
        self._closed = True
        self._unsubscribe()
        self.knob.close()
        tasks = list(self._tasks)
        for task in tasks:
            task.cancel()
        if tasks:
            await asyncio.wait(tasks)
        await self.connection.aclose()

    def closeEvent(self, event: QCloseEvent) -> None:
        self._closed = True
        self._unsubscribe()
        self.knob.close()
        for task in list(self._tasks):
            task.cancel()
        self.connection.close()
        super().closeEvent(event)
        self.closed.emit()

    # The numbers behind the combo boxes are kept here, not as item data:
    # PySide6 6.12's QComboBox.currentData() loses a reference to None each time
    # it returns None, which ends in a crash when Python exits.
    @property
    def station(self) -> int | None:
        return _at(self._stations, self.station_box.currentIndex())

    @property
    def radio(self) -> int | None:
        return _at(self._radios, self.radio_box.currentIndex())

    @property
    def radio_view(self) -> RadioView | None:
        if self.snapshot is None or self.station is None or self.radio is None:
            return None
        return self.snapshot.radio(self.station, self.radio)

    @property
    def target(self) -> Target:
        for target, button in self.target_buttons.items():
            if button.isChecked():
                return target
        return "both"

    def status_text(self) -> str:
        """The status line's text with its mark (⚠ or ℹ), "" when empty."""
        return self.message.shown if self.message is not None else ""

    @property
    def last_error(self) -> str:
        """The warning the status line shows ("" when it shows none, or an answer)."""
        message = self.message
        return message.text if message is not None and message.tone is Tone.WARNING else ""

    @property
    def radio_key(self) -> tuple[int, int] | None:
        if self.station is None or self.radio is None:
            return None
        return (self.station, self.radio)

    # -- events from the server -----------------------------------------------------------------
    def _on_event(self, event: ClientEvent) -> None:
        if self._closed:
            return
        match event:
            case LinkChanged(state, detail):
                self._show_link(state, detail)
            case StateReceived(snapshot):
                self._clear_message()  # a fresh state for everyone: old answers are old
                self._show_snapshot(snapshot)
                self._show_link(self.link_state, self._link_detail)
            case SwitchChanged():
                self.snapshot = self.connection.snapshot
                self._show_link(self.link_state, self._link_detail)
                self._show_radio()
            case RadioChanged(radio):
                self.snapshot = self.connection.snapshot
                if radio.key == (self.station, self.radio):
                    self._show_radio()
                    self._show_compass()
            case RotatorChanged():
                self.snapshot = self.connection.snapshot
                self._show_compass()
            case LayoutChanged(layout):
                if self._layout_asked is not None and layout.key == self._layout_asked[:2] \
                        and (layout.rows, layout.columns) == self._layout_shape:
                    self._show_layout(layout)
            case ProblemSeen(message):
                self._error(message)
            case _:
                pass

    @property
    def screen_now(self) -> ScreenState:
        """Where the window stands in the table of :mod:`moas_gui.client.screen`."""
        return screen_state(self.link_state, self.snapshot)

    def _show_link(self, state: LinkState, detail: str) -> None:
        self._link_detail = detail
        self.link_state = state
        screen = self.screen_now
        colour = {LinkState.CONNECTED: Colours.CONNECTED,
                  LinkState.RECONNECTING: Colours.RECONNECTING}.get(state, Colours.CLOSED)
        text = {
            LinkState.CONNECTING: f"\u25cc Connecting to {self.connection.address}\u2026",
            LinkState.CONNECTED: f"\u25cf Connected to {detail or self.connection.address}",
            LinkState.RECONNECTING: f"\u25cc {detail}",
            LinkState.CLOSED: "\u2715 Closed",
        }[state]
        if screen.screen is Screen.STOPPED:
            colour, text = Colours.INHIBIT, "\u25a0 Switches stopped: all relays off"
        elif screen.screen is Screen.NO_CONFIGURATION:
            colour, text = Colours.CLOSED, "\u25cb Connected; the server has no configuration open"
        elif screen.screen is Screen.UNRESPONSIVE:
            which = ", ".join(str(i) for i in screen.unresponsive)
            colour = Colours.RECONNECTING
            text = (f"\u25b2 Switch {which} not answering: its relays may not match "
                    "what is shown")
        self.link_label.setText(text)
        fg = "white" if colour in (Colours.CLOSED,) else "black"
        self.link_label.setStyleSheet(f"background: {colour.name()}; color: {fg};")
        self.link_label.updateGeometry()
        self._show_screen()

    def _show_screen(self) -> None:
        """Greys what cannot be pressed now, with the reason, and shows no stale selection."""
        screen = self.screen_now
        refusal = "" if screen.can_select else screen.refusal
        self.grid.set_greyed(refusal)
        for widget in (self.previous_button, self.next_button, self.relative_go,
                       self.frequency_button):
            widget.setProperty("greyed", "true" if refusal else "false")
            widget.setToolTip(refusal[:1].upper() + refusal[1:] if refusal else "")
            widget.style().unpolish(widget)
            widget.style().polish(widget)
        self.compass_panel.set_greyed("" if screen.can_turn else screen.refusal)
        self._expire_message()
        if screen.screen is not self._screen_shown:
            self._screen_shown = screen.screen
            self._show_radio()
            self._show_compass()

    def _refused(self, what: str) -> bool:
        """Answers a press that cannot go to the server now; True when it was answered."""
        screen = self.screen_now
        if screen.can_select or (what in ("Turn", "Stop") and screen.can_turn):
            return False
        self._error(f"{what}: {screen.refusal}")
        return True

    def _expire_message(self) -> None:
        """The status line's table (docs/client.md): a message goes with the state and
        the radio it was shown in."""
        message = self.message
        if message is not None and not message.still_true(self.screen_now.screen,
                                                          self.radio_key):
            self._clear_message()

    @property
    def switches_stopped(self) -> bool:
        """Every switch is stopped (File > Stop Switches): no antenna is connected."""
        return self.screen_now.screen is Screen.STOPPED

    def _show_snapshot(self, snapshot: Snapshot) -> None:
        self.snapshot = snapshot
        self.config_label.setText(snapshot.config)
        keep_station = self.station if self.station is not None else self._wanted_radio[0]
        self.station_box.blockSignals(True)
        self.station_box.clear()
        self._stations = list(snapshot.stations)
        for station in self._stations:
            self.station_box.addItem(f"{station}")
        index = _index_of(self._stations, keep_station)
        self.station_box.setCurrentIndex(index if self._stations else -1)
        self.station_box.blockSignals(False)
        self._fill_radios()

    def _station_chosen(self, _index: int = 0) -> None:
        self._fill_radios()

    def _fill_radios(self) -> None:
        keep_radio = self.radio if self.radio is not None else self._wanted_radio[1]
        self.radio_box.blockSignals(True)
        self.radio_box.clear()
        self._radios = []
        if self.snapshot is not None and self.station is not None:
            self._radios = list(self.snapshot.radios_of(self.station))
            for radio in self._radios:
                self.radio_box.addItem(f"{radio}")
        index = _index_of(self._radios, keep_radio)
        self.radio_box.setCurrentIndex(index if self._radios else -1)
        self.radio_box.blockSignals(False)
        self._radio_chosen()

    def _radio_chosen(self) -> None:
        self._expire_message()
        self.frequency_box.show_radio(self.radio_view)
        self._show_radio()
        self._ask_layout(force=True)
        self._show_compass()

    def _show_radio(self) -> None:
        radio = self.radio_view
        snapshot = self.snapshot
        screen = self.screen_now.screen
        if radio is None or snapshot is None or not self.screen_now.shows_selection:
            self.display.setText({
                Screen.STOPPED: "Switches stopped: no antenna is connected",
                Screen.RECONNECTING: "Not connected: the antennas in use are not known",
                Screen.NO_CONFIGURATION: "The server has no configuration open",
            }.get(screen, "no radio"))
            if radio is not None and snapshot is not None:  # no antenna marked in use
                self.relative_strip.show_list(radio, snapshot, mark=False)
            self.badge_tx.hide()
            self.badge_inhibit.hide()
            self.badge_active.hide()
            self.badge_focus.hide()
            self.note_label.hide()
            self.release_button.hide()
            self.display.set_detail("")
            return
        parts = [frequency_text(radio)]
        tx = snapshot.antenna(radio.tx)
        rx = snapshot.antenna(radio.rx)
        parts.append(f"TX  {tx.name if tx else 'none'}")
        parts.append(f"RX  {rx.name if rx else 'none'}")
        alt = snapshot.antenna(radio.alt)
        if alt is not None:
            parts.append(f"ALT  {alt.name}")
        self.display.setText("     ".join(parts))
        self.display.set_detail(explain(radio, snapshot))
        self.badge_tx.setVisible(radio.transmitting)
        self.badge_inhibit.setVisible(radio.inhibited)
        self.badge_active.setVisible(radio.active)
        self.badge_focus.setVisible(radio.focus)
        note = "\n".join(text for text in (radio.note, radio.held_text) if text)
        self.note_label.setText(note)
        self.note_label.setVisible(bool(note))
        self.release_button.setVisible(bool(radio.held_by) and may_release(
            self.connection.server.get("operator"), radio.station, radio.radio))
        self.relative_strip.show_list(radio, snapshot)

    def why_text(self) -> str:
        """Why the radio shown has its antennas, in words (empty when the server did not say)."""
        radio = self.radio_view
        return explain(radio, self.snapshot) if radio is not None else ""

    def why_answer(self, view: ButtonView | None) -> str:
        """What Why? says about ``view`` (None: about the radio's antennas)."""
        why = self.why_text().replace("\n", ";").replace(";  ", "; ")
        if view is None:
            if not self.screen_now.shows_selection:
                return self.screen_now.refusal[:1].upper() + self.screen_now.refusal[1:]
            return why or "The server has not said why (no decision yet)"
        return button_answer(view, self.screen_now, why)

    def _why_menu(self, view: ButtonView | None) -> None:
        """The grid's right-click menu (opened with ``popup``: no nested event loop)."""
        self._why_view = view
        menu = QMenu(self)
        menu.addAction(self.why_action)
        menu.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
        menu.popup(QCursor.pos())

    def _show_why(self, view: ButtonView | None = None) -> None:
        """The "Why?" action: the answer in the status line and next to the pointer."""
        text = self.why_answer(view)
        self._say(text, Tone.INFO)
        QToolTip.showText(QCursor.pos(), text, self.grid)

    def _show_compass(self) -> None:
        snapshot = self.snapshot
        if snapshot is None:
            self.compass_panel.show_targets(())
            return
        radio = self.radio_view
        targets = compass_targets(snapshot, radio, self.layout_view,
                                  selection_known=self.screen_now.shows_selection)
        tx = snapshot.antenna(radio.tx) if radio else None
        self.compass_panel.show_targets(targets, prefer=tx.rotator if tx else None)

    def _ask_layout(self, force: bool = False) -> None:
        if self.station is None or self.radio is None:
            self.layout_view = None
            self.grid.show_layout(None, self.rows_box.value(), self.columns_box.value())
            return
        key = (self.station, self.radio, self.rows_box.value(), self.columns_box.value())
        if key == self._layout_asked and not force:
            return
        self._layout_asked = key
        self._spawn(self._fetch_layout(key), "Layout")

    async def _fetch_layout(self, key: tuple[int, int, int, int]) -> None:
        layout = await self.connection.layout(*key)
        if key == self._layout_asked:
            self._layout_shape = (layout.rows, layout.columns)
            self._show_layout(layout)

    def _show_layout(self, layout: LayoutView) -> None:
        self.layout_view = layout
        self.grid.show_layout(layout, self.rows_box.value(), self.columns_box.value())
        self._show_compass()

    # -- the user's wishes ----------------------------------------------------------------------
    def _pressed(self, view: ButtonView, exclusive: bool) -> None:
        station, radio = self.station, self.radio
        kind = "Function" if view.type is ButtonType.FUNCTION else "Select"
        if self._refused(f"{kind} {view.label}") or station is None or radio is None:
            return
        if view.state is ButtonState.UNAVAILABLE:  # answered here with its reason; nothing sent
            self._say(button_answer(view, self.screen_now), Tone.INFO)
            return
        if view.type is ButtonType.FUNCTION:
            if not exclusive:
                self._spawn(self.connection.function(station, radio, view.id),
                            f"Function {view.label}")
            return
        self._spawn(self.connection.select(station, radio, view.id, self.target, exclusive),
                    f"Select {view.label}")

    def _release(self) -> None:
        if self._refused("Release") or self.station is None or self.radio is None:
            return
        self._spawn(self.connection.release(self.station, self.radio), "Release")

    def _relative(self, *, step: int | None = None, index: int | None = None) -> None:
        if self._refused("Relative") or self.station is None or self.radio is None:
            return
        self._spawn(self.connection.relative(self.station, self.radio, step=step, index=index),
                    "Relative")

    def _send_frequency(self, khz: float, tx_khz: float | None) -> None:
        if self._refused("Frequency") or self.station is None or self.radio is None:
            return
        self._spawn(self.connection.frequency(self.station, self.radio, khz, tx_khz),
                    "Frequency")

    def _rotate(self, rotator: int, heading: float) -> None:
        if self._refused("Turn"):
            return
        self._spawn(self.connection.rotate(rotator, heading), f"Turn to {heading:.0f}\u00b0")

    def _stop(self, rotator: int) -> None:
        if self._refused("Stop"):
            return
        self._spawn(self.connection.stop(rotator), "Stop")

    # -- running requests -----------------------------------------------------------------------
    def _spawn(self, coro: Coroutine[Any, Any, Any], what: str) -> None:
        if self._closed:
            coro.close()
            return
        try:
            task = asyncio.ensure_future(self._guarded(coro, what))
        except RuntimeError:
            coro.close()
            self._error(f"{what}: no event loop is running")
            return
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        # a task cancelled before its first step (the window closing at once) never
        # starts ``coro``: closed here, it is not reported as "never awaited"
        task.add_done_callback(lambda _task: coro.close())

    async def _guarded(self, coro: Coroutine[Any, Any, Any], what: str) -> None:
        try:
            await coro
        except ServerError as exc:
            self._error(f"{what}: {exc.message}")
        except ClientError as exc:
            self._error(f"Connection: {what}: {exc}")
        except asyncio.CancelledError:
            raise
        except Exception:
            log.exception("%s failed in the client window", what)
            self._error(f"{what} failed; the log says why")

    def _error(self, message: str) -> None:
        self._say(message, Tone.WARNING)

    def tell(self, text: str) -> None:
        """Says ``text`` in the status line (as information, not a warning)."""
        self._say(text, Tone.INFO)

    def _say(self, text: str, tone: Tone) -> None:
        """Shows one message in the status line, tied to the state and radio now."""
        if self._closed:
            return
        self.message = StatusMessage(text, tone, self.screen_now.screen, self.radio_key)
        self.status_line.setText(self.message.shown)
        self.status_line.setToolTip(self.message.shown)
        self.status_line.setProperty("tone", tone.value)
        self.status_line.style().unpolish(self.status_line)
        self.status_line.style().polish(self.status_line)

    def _clear_message(self) -> None:
        self.message = None
        self.status_line.setText("")
        self.status_line.setToolTip("")

    @property
    def pending(self) -> int:
        """Requests still waiting for their reply."""
        return len(self._tasks)


def fit_small_screens(content: QWidget, parent: QWidget) -> QScrollArea:
    """``content`` in a frameless scroll area: the window's minimum size no longer
    grows with the content (long names, a big layout), so it fits any screen."""
    area = QScrollArea(parent)
    area.setWidgetResizable(True)
    area.setFrameShape(QFrame.Shape.NoFrame)
    area.setWidget(content)
    area.setMinimumSize(480, 320)
    return area


def _at(items: list[int], index: int) -> int | None:
    return items[index] if 0 <= index < len(items) else None


def _index_of(items: list[int], wanted: int | None) -> int:
    return items.index(wanted) if wanted in items else 0
