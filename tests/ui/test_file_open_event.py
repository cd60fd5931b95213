"""macOS: a double-clicked ``.moas`` file arrives as a ``QFileOpenEvent`` on the
application (moas_gui.ui.file_open); posted here offscreen, it is handed over to the
server window, which opens it, as a second launch's hand-over does."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from client_support import run_on_qt
from helpers import until
from test_server_window import EXAMPLES, Harness

from moas_gui.ui.file_open import FileOpenEvents
from moas_gui.ui.qt import QApplication, QFileOpenEvent, QUrl


def test_a_file_open_event_before_the_window_waits_then_opens_it(qapp: Any,
                                                                 tmp_path: Path) -> None:
    """The double-click that starts the application: the event comes before the window."""
    harness = Harness(tmp_path)
    events = FileOpenEvents(qapp)
    path = EXAMPLES / "small-station.moas"
    try:
        QApplication.postEvent(qapp, QFileOpenEvent(str(path)))
        QApplication.processEvents()
        assert events.waiting == [path]

        async def scenario() -> None:
            window = harness.make()
            events.attach(window.take_hand_over)
            assert events.waiting == []
            await window.idle()
            assert harness.app is not None
            await until(lambda: harness.app is not None and harness.app.path == path)
            assert harness.app.config is not None
            await harness.close()
        run_on_qt(qapp, scenario())
    finally:
        qapp.removeEventFilter(events)
        events.deleteLater()


def test_a_file_open_event_while_running_is_handed_over_at_once(qapp: Any,
                                                                tmp_path: Path) -> None:
    """A double-click while it runs: the URL form of the event, another file: asked first
    (the harness answers yes), then opened."""
    harness = Harness(tmp_path)
    events = FileOpenEvents(qapp)
    first, second = EXAMPLES / "small-station.moas", EXAMPLES / "2x6.moas"
    try:
        async def scenario() -> None:
            window = harness.make()
            events.attach(window.take_hand_over)
            window.open_file(str(first))
            await window.idle()
            await until(lambda: harness.app is not None and harness.app.path == first)
            harness.answers.append(True)
            QApplication.postEvent(qapp, QFileOpenEvent(QUrl.fromLocalFile(str(second))))
            await until(lambda: harness.app is not None and harness.app.path == second)
            assert harness.questions and "2x6.moas" in harness.questions[0]
            await harness.close()
        run_on_qt(qapp, scenario())
    finally:
        qapp.removeEventFilter(events)
        events.deleteLater()


def test_other_events_pass_through(qapp: Any) -> None:
    received: list[Path | None] = []
    events = FileOpenEvents(qapp)
    events.attach(received.append)
    try:
        QApplication.postEvent(qapp, QFileOpenEvent(""))  # no file, no URL: not ours
        QApplication.processEvents()
        assert received == [] and events.waiting == []
    finally:
        qapp.removeEventFilter(events)
        events.deleteLater()
