"""View > Pair a device: a new operator for a tablet or phone, as a QR code.

The dialog asks the operator's name and role, adds it to the station's operators
(:class:`~moas_gui.operators.OperatorBook`), and shows a QR code of the browser
page's address with the token in the URL's fragment (``#token=...``): a browser
never sends a fragment to the server, the page reads it, keeps the token and
clears it from the address bar.  The token is shown in this dialog only: it is
never logged (the log says which operator was added).  Opened with ``open()``,
never ``exec()`` (the window runs on qasync's loop).

The code names only an address a phone can reach: the LAN addresses the page
listens on (a choice when there are several).  A page bound to loopback only
gets no code: the dialog says so and how to open it (``--bind 0.0.0.0``), and
changes nothing.  Over TLS it shows the certificate's SHA-256 fingerprint, the
one the phone's browser shows for the page it opens.
"""

from __future__ import annotations

import logging

from moas_gui.addresses import WebPage
from moas_gui.operators import OperatorBook, OperatorError, Role

from .qt import (
    QColor,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QPainter,
    QPixmap,
    Qt,
    QVBoxLayout,
    QWidget,
)

log = logging.getLogger(__name__)

ROLES = (("operate: selects, tunes and turns for its radios", Role.OPERATE),
         ("view: sees everything, changes nothing", Role.VIEW),
         ("admin: everything, the switches too", Role.ADMIN))


def qr_pixmap(text: str, module: int = 6, border: int = 4) -> QPixmap:
    """``text`` as a QR code, ``module`` pixels a square (the ``qrcode`` package makes the
    pattern; Qt paints it)."""
    import qrcode

    code = qrcode.QRCode(border=border, error_correction=qrcode.constants.ERROR_CORRECT_M)
    code.add_data(text)
    code.make(fit=True)
    matrix = code.get_matrix()
    size = len(matrix) * module
    pixmap = QPixmap(size, size)
    pixmap.fill(QColor("white"))
    painter = QPainter(pixmap)
    try:
        for y, row in enumerate(matrix):
            for x, dark in enumerate(row):
                if dark:
                    painter.fillRect(x * module, y * module, module, module, QColor("black"))
    finally:
        painter.end()
    return pixmap


def pairing_url(host: str, port: int, tls: bool, token: str) -> str:
    shown = f"[{host}]" if ":" in host else host
    return f"{'https' if tls else 'http'}://{shown}:{port}/#token={token}"


def loopback_only_text(bind: str) -> str:
    """What the dialog says when the page listens where no phone can reach it."""
    return (f"The page listens on {bind} only, on this computer: a phone cannot reach it. "
            "To pair one, start the server on the station's network: moas-server "
            "--bind 0.0.0.0 (every interface), or --bind with this computer's LAN address. "
            "Nothing was changed here.")


def fingerprint_lines(fingerprint: str) -> str:
    """A SHA-256 fingerprint in two lines of 16 pairs (as it is compared, pair by pair)."""
    pairs = fingerprint.split(":")
    return ":".join(pairs[:16]) + "\n" + ":".join(pairs[16:])


class PairDialog(QDialog):
    """Asks a name and a role, then shows the QR code (see the module's docstring)."""

    def __init__(self, parent: QWidget | None, page: WebPage | None,
                 book: OperatorBook | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Pair a device")
        self.page = page
        self.book = book if book is not None else OperatorBook()
        self.url: str | None = None
        self._token: str | None = None
        self.addresses = page.reachable if page is not None else []
        """The addresses a phone can open the page at (the LAN addresses it listens on)."""
        layout = QVBoxLayout(self)
        form = QFormLayout()
        self.name = QLineEdit(self)
        self.name.setPlaceholderText("e.g. tablet-40m")
        form.addRow("Operator's name:", self.name)
        self.role = QComboBox(self)
        for label, role in ROLES:
            self.role.addItem(label, role.value)
        form.addRow("Role:", self.role)
        self.address_box = QComboBox(self)
        for address in self.addresses:
            self.address_box.addItem(address)
        self.address_box.setToolTip("The station's address on the network the phone is on")
        self.address_box.setPlaceholderText("none a phone can reach")
        self.address_box.setEnabled(bool(self.addresses))
        form.addRow("The phone opens:", self.address_box)
        self.fingerprint = QLabel(self)
        self.fingerprint.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.fingerprint.setStyleSheet("font-family: monospace;")
        if page is not None and page.fingerprint:
            self.fingerprint.setText(fingerprint_lines(page.fingerprint))
            self.fingerprint.setToolTip("The SHA-256 fingerprint of the page's certificate: "
                                        "the phone's browser shows the same one for the page "
                                        "it opens (docs/security.md)")
            form.addRow("Certificate (SHA-256):", self.fingerprint)
        layout.addLayout(form)
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        layout.addWidget(self.message)
        self.code = QLabel(self)
        self.code.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.code.hide()
        layout.addWidget(self.code)
        self.address = QLabel(self)
        self.address.setWordWrap(True)
        self.address.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.address.hide()
        layout.addWidget(self.address)
        self.buttons = QDialogButtonBox(self)
        self.create_button = self.buttons.addButton("Create and show the code",
                                             QDialogButtonBox.ButtonRole.AcceptRole)
        self.buttons.addButton(QDialogButtonBox.StandardButton.Close)
        self.create_button.clicked.connect(self.make)
        self.buttons.rejected.connect(self.close)
        self.address_box.currentIndexChanged.connect(lambda _i: self._show_code())
        layout.addWidget(self.buttons)
        self.setMaximumWidth(560)
        self._say_page()

    def _say_page(self) -> None:
        page = self.page
        if page is None:
            self.message.setText("The browser page is not served: set WebPort in the "
                                 "configuration (or moas-server --web-port) first.")
            self.create_button.setEnabled(False)
        elif not self.addresses:
            self.message.setText(loopback_only_text(page.bind))
            self.create_button.setEnabled(False)
        elif not page.tls:
            self.message.setText("The page is served without TLS: the token crosses the "
                                 "network readable (moas-server --tls encrypts it).")

    def make(self) -> None:
        """Adds the operator and shows the code; a refusal is said in the dialog."""
        if self.page is None or not self.addresses:
            return
        name = self.name.text().strip()
        role = Role(self.role.currentData())
        try:
            operator, token = self.book.add(name, role)
        except OperatorError as exc:
            self.message.setText(str(exc))
            return
        except OSError as exc:
            self.message.setText(f"cannot write {self.book.path}: {exc.strerror or exc}")
            return
        log.info('Paired a device: operator "%s" (%s) added', operator.name, role.value)
        self._token = token
        self._show_code()
        self.message.setText(f'Operator "{operator.name}" ({role.value}) was added. The code '
                             "holds its token: it is shown here only, once.")
        self.create_button.setEnabled(False)
        self.name.setEnabled(False)
        self.role.setEnabled(False)
        self.adjustSize()

    def _show_code(self) -> None:
        """The QR code for the address chosen (the same token at any address)."""
        if self.page is None or self._token is None or not self.addresses:
            return
        host = self.address_box.currentText() or self.addresses[0]
        self.url = pairing_url(host, self.page.port, self.page.tls, self._token)
        self.code.setPixmap(qr_pixmap(self.url, module=5))
        self.code.show()
        compare = ("The browser warns about the certificate once: its fingerprint must be "
                   "the one above." if self.page.fingerprint else "")
        self.address.setText(f"Scan it with the phone's camera, or open:\n{self.url}\n{compare}")
        self.address.show()


__all__ = ["PairDialog", "fingerprint_lines", "loopback_only_text", "pairing_url", "qr_pixmap"]
