"""macOS hands a double-clicked ``.moas`` file to the application as a ``QFileOpenEvent``,
not on the command line: both when the double-click starts the application and when it
already runs.  :class:`FileOpenEvents` catches those events on the ``QApplication`` from
the start, keeps the files that come before the window exists, and hands each to
``window.take_hand_over`` (what a second launch's hand-over does on every system).

The frozen app's ``Info.plist`` declares the ``.moas`` type (packaging/moas-gui.spec);
other systems never send the event, and the filter then does nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from .qt import QEvent, QFileOpenEvent, QObject

Receiver = Callable[[Path | None], None]


class FileOpenEvents(QObject):
    """An event filter on the application for ``QFileOpenEvent``."""

    def __init__(self, application: QObject) -> None:
        super().__init__(application)
        self._receiver: Receiver | None = None
        self.waiting: list[Path] = []
        application.installEventFilter(self)

    def attach(self, receiver: Receiver) -> None:
        """From now on hand files to ``receiver``; the ones that came before first."""
        self._receiver = receiver
        waiting, self.waiting = self.waiting, []
        for path in waiting:
            receiver(path)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() != QEvent.Type.FileOpen or not isinstance(event, QFileOpenEvent):
            return False
        name = event.file() or event.url().toLocalFile()
        if not name:
            return False
        path = Path(name)
        if self._receiver is None:
            self.waiting.append(path)
        else:
            self._receiver(path)
        return True


__all__ = ["FileOpenEvents"]
