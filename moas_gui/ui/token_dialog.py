"""The desktop client's request for an operator's token (no terminal needed).

When a station refuses the client's ``hello`` for want of a token, the client
window opens this dialog (with ``open()``, never ``exec()``: the window runs on
qasync's loop).  The operator types the token an admin gave, or pastes the
pairing link a station shows as a QR code (``https://HOST:PORT/#token=...``),
whose token is taken from it.  *Sign in* emits :attr:`TokenDialog.token_given`;
the window tries the token with the station (a ``hello``) and tells the dialog
how it went (:meth:`TokenDialog.checking`, :meth:`TokenDialog.refused`), keeping
the token only once the station took it.  The token is never shown in clear,
never logged.
"""

from __future__ import annotations

from typing import Any
from urllib.parse import parse_qs, urlsplit

from moas_gui.client.connection import ClientConnection
from moas_gui.client.events import (
    TOKEN_ASKED,
    TOKEN_REFUSED,
    ClientEvent,
    LinkChanged,
    LinkState,
    StateReceived,
    TokenWanted,
)
from moas_gui.client.keys import ClientKeys

from .client_style import Colours, dark_palette
from .qt import (
    QAction,
    QApplication,
    QDialog,
    QDialogButtonBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
    Signal,
)

__all__ = ["TokenDialog", "TokenKeeper", "token_from_text"]


def token_from_text(text: str) -> str:
    """The token in what the operator typed or pasted: a pairing link's ``#token=``
    fragment (or ``?token=``), else the text itself, trimmed ("" when none: a link
    without a token)."""
    text = text.strip()
    if "://" not in text:
        return text
    parts = urlsplit(text)
    for piece in (parts.fragment, parts.query):
        found = parse_qs(piece).get("token")
        if found and found[0].strip():
            return found[0].strip()
    return ""


class TokenDialog(QDialog):
    """See the module notes."""

    token_given = Signal(str)
    """The operator signed in with this token (to be checked with the station)."""

    def __init__(self, parent: QWidget | None, station: str) -> None:
        super().__init__(parent)
        self.setWindowTitle("Operator's token")
        self.setObjectName("tokenDialog")
        # the client window's dark look, its background included (a child dialog takes
        # the window's style sheet but not its background)
        self.setPalette(dark_palette(self.palette()))
        self.setAutoFillBackground(True)
        self.setStyleSheet(f"QDialog#tokenDialog {{ background: {Colours.WINDOW.name()}; }}"
                           f"QLabel {{ color: {Colours.TEXT.name()}; }}")
        self.station = station
        layout = QVBoxLayout(self)
        self.message = QLabel(TOKEN_ASKED + ".", self)
        self.message.setWordWrap(True)
        layout.addWidget(self.message)
        where = QLabel(f"Station: {station}", self)
        where.setStyleSheet(f"color: {Colours.DIM_TEXT.name()};")
        layout.addWidget(where)
        row = QHBoxLayout()
        self.field = QLineEdit(self)
        self.field.setEchoMode(QLineEdit.EchoMode.Password)
        self.field.setPlaceholderText("the token, or the pairing link")
        self.field.setMinimumWidth(320)
        row.addWidget(self.field, 1)
        self.paste_button = QPushButton("&Paste a Pairing Link", self)
        self.paste_button.setToolTip("Takes the token from a link like "
                                     "https://host:port/#token=\u2026 copied from the "
                                     "station's pairing code")
        row.addWidget(self.paste_button)
        layout.addLayout(row)
        self.hint = QLabel("This client keeps it for this station (in the system keyring "
                           "where there is one); Operator > Forget the Token removes it.", self)
        self.hint.setWordWrap(True)
        layout.addWidget(self.hint)
        self.buttons = QDialogButtonBox(self)
        self.sign_in = self.buttons.addButton("&Sign In", QDialogButtonBox.ButtonRole.AcceptRole)
        self.buttons.addButton(QDialogButtonBox.StandardButton.Cancel)
        layout.addWidget(self.buttons)
        self.sign_in.setDefault(True)
        self.sign_in.clicked.connect(self._give)
        self.field.returnPressed.connect(self._give)
        self.paste_button.clicked.connect(self.paste_link)
        self.buttons.rejected.connect(self.reject)
        self.is_checking = False

    def asked(self) -> None:
        """The station asks for a token (again): ready for one."""
        self.is_checking = False
        self.message.setText(TOKEN_ASKED + ".")
        self._ready()

    def paste_link(self) -> None:
        """Takes the token from the clipboard's text (a pairing link or a bare token)."""
        clipboard = QApplication.clipboard()
        token = token_from_text(clipboard.text() if clipboard is not None else "")
        if not token:
            self.message.setText("The clipboard holds no pairing link or token: copy the link "
                                 "the station's pairing code shows, then paste it here.")
            return
        self.field.setText(token)
        self.message.setText("The token was taken from the pairing link: sign in to use it.")

    def _give(self) -> None:
        token = token_from_text(self.field.text())
        if not token:
            self.message.setText("Type the operator's token, or paste the pairing link, "
                                 "first.")
            return
        self.checking()
        self.token_given.emit(token)

    def checking(self) -> None:
        """The token went to the station: waiting for its answer."""
        self.is_checking = True
        self.message.setText("Checking the token with the station\u2026")
        for widget in (self.field, self.paste_button, self.sign_in):
            widget.setEnabled(False)

    def refused(self) -> None:
        """The station did not take the token: said in words, the field ready again."""
        self.is_checking = False
        self.message.setText(TOKEN_REFUSED + ".")
        self.field.clear()
        self._ready()

    def _ready(self) -> None:
        for widget in (self.field, self.paste_button, self.sign_in):
            widget.setEnabled(True)
        self.field.setFocus()


class TokenKeeper:
    """The client window's *Operator* menu and token request: opens :class:`TokenDialog`
    when the station asks for a token, tries the one given, keeps it
    (:class:`~moas_gui.client.keys.ClientKeys`) once the station took it, and forgets
    it on request (the connection then says hello again without it)."""

    def __init__(self, window: Any, keys: ClientKeys) -> None:
        self.window = window
        self.connection: ClientConnection = window.connection
        self.keys = keys
        self.server = f"{self.connection.host}:{self.connection.port}"
        """The name tokens are kept under: as ``moas-client --token`` keeps them."""
        self.dialog: TokenDialog | None = None
        self.offered: str | None = None
        """A token given in the dialog, not yet taken by the station."""
        self.dismissed = False
        """The request was cancelled: not opened again until asked from the menu."""
        self._note = ""
        """What to say once the station's state arrives (where the token was kept)."""
        self._state_seen = False
        """The connection's state came (it may come just before its link is up)."""
        menu = window.menuBar().addMenu("&Operator")
        self.menu = menu
        self.give_action = QAction("&Give a Token\u2026", window)
        self.give_action.triggered.connect(self.ask)
        self.forget_action = QAction("&Forget the Token", window)
        self.forget_action.triggered.connect(self.forget)
        menu.addAction(self.give_action)
        menu.addAction(self.forget_action)
        self._unsubscribe = self.connection.subscribe(self._on_event)
        window.closed.connect(self._unsubscribe)

    def _on_event(self, event: ClientEvent) -> None:
        if isinstance(event, TokenWanted):
            self._wanted(event.refused)
        elif isinstance(event, LinkChanged):
            if event.state is LinkState.CONNECTED:
                self._taken()
            else:
                self._state_seen = False
        elif isinstance(event, StateReceived):
            # the window clears its status line for a new state (this listener comes after
            # the window's): what the keeper says comes after the connection's first state
            self._state_seen = True
            self._say()

    def _say(self) -> None:
        if self._note and self._state_seen:
            note, self._note = self._note, ""
            self.window.tell(note)

    def _wanted(self, refused: bool) -> None:
        if self.offered is not None and not refused:
            return  # a hello sent before the token was given: its answer is coming
        if self.offered is not None:  # the station answered the token just given
            self.offered = None
            self.connection.token = None  # not said again until another is given
            self.open().refused()
            return
        if refused:  # a kept token the station no longer takes
            self.connection.token = None
            self.open().refused()
            return
        if self.dismissed or (self.dialog is not None and self.dialog.isVisible()):
            return
        self.open().asked()

    def ask(self) -> None:
        """Operator > Give a Token: the request, whether or not the station asked."""
        self.dismissed = False
        self.open().asked()

    def open(self) -> TokenDialog:
        """The request, shown (with ``open()``: no nested event loop)."""
        if self.dialog is None:
            self.dialog = TokenDialog(self.window, self.server)
            self.dialog.token_given.connect(self._try)
            self.dialog.rejected.connect(self._cancelled)
        if not self.dialog.isVisible():
            self.dialog.open()
        return self.dialog

    def _cancelled(self) -> None:
        self.dismissed = True
        self.offered = None

    def _try(self, token: str) -> None:
        self.offered = token
        self.connection.use_token(token)

    def _taken(self) -> None:
        token, self.offered = self.offered, None
        if token is None:
            return
        if self.dialog is not None:
            self.dialog.accept()
        try:
            where = self.keys.set_token(self.server, token)
        except OSError as exc:
            self._note = (f"Signed in; the token could not be kept ({exc.strerror or exc}): "
                          "this client asks for it again next time")
        else:
            self._note = f"Signed in; the token is kept in {where}"
        self._say()

    def forget(self) -> None:
        """Operator > Forget the Token: gone from the keyring and the file; the station
        is greeted again without it (and asks for one if it needs one)."""
        try:
            self.keys.forget_token(self.server)
        except OSError as exc:
            self.window.tell(f"The token could not be forgotten: {exc.strerror or exc}")
            return
        self.dismissed = False
        self.offered = None
        self.connection.use_token(None)
        self.window.tell("This station's token is forgotten")
