"""View > Pair a device: a new operator for a tablet or phone, as a QR code.

The dialog asks the operator's name and role, adds it to the station's operators
(:class:`~moas_gui.operators.OperatorBook`), and shows a QR code of the browser
page's address with the token in the URL's fragment (``#token=...``): a browser
never sends a fragment to the server, the page reads it, keeps the token and
clears it from the address bar.  The token is shown in this dialog only: it is
never logged (the log says which operator was added).  Opened with ``open()``,
never ``exec()`` (the window runs on qasync's loop).
"""

from __future__ import annotations

import logging

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


class PairDialog(QDialog):
    """Asks a name and a role, then shows the QR code (see the module's docstring)."""

    def __init__(self, parent: QWidget | None, page: tuple[str, int, bool] | None,
                 book: OperatorBook | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Pair a device")
        self.page = page
        self.book = book if book is not None else OperatorBook()
        self.url: str | None = None
        layout = QVBoxLayout(self)
        form = QFormLayout()
        self.name = QLineEdit(self)
        self.name.setPlaceholderText("e.g. tablet-40m")
        form.addRow("Operator's name:", self.name)
        self.role = QComboBox(self)
        for label, role in ROLES:
            self.role.addItem(label, role.value)
        form.addRow("Role:", self.role)
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
        layout.addWidget(self.buttons)
        if page is None:
            self.message.setText("The browser page is not served: set WebPort in the "
                                 "configuration (or moas-server --web-port) first.")
            self.create_button.setEnabled(False)
        elif not page[2]:
            self.message.setText("The page is served without TLS: the token crosses the "
                                 "network readable (moas-server --tls encrypts it).")

    def make(self) -> None:
        """Adds the operator and shows the code; a refusal is said in the dialog."""
        if self.page is None:
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
        host, port, tls = self.page
        self.url = pairing_url(host, port, tls, token)
        self.code.setPixmap(qr_pixmap(self.url))
        self.code.show()
        self.address.setText(f"Scan it with the device's camera, or open:\n{self.url}")
        self.address.show()
        self.message.setText(f'Operator "{operator.name}" ({role.value}) was added. The code '
                             "holds its token: it is shown here only, once.")
        self.create_button.setEnabled(False)
        self.name.setEnabled(False)
        self.role.setEnabled(False)
        self.adjustSize()


__all__ = ["PairDialog", "pairing_url", "qr_pixmap"]
