"""The server log view: a wrapped record's next lines start under its message."""

from __future__ import annotations

import logging
from typing import Any

from moas_gui.ui.log_view import PREFIX_CHARS, LogLevel, LogView


def test_a_wrapped_record_continues_under_its_message(qapp: Any) -> None:
    view = LogView()
    view.resize(400, 300)
    view.show()
    view.add_record(logging.INFO, "07:30:54  info    short")
    view.add_record(logging.WARNING, "07:30:55  warning " + "word " * 40)
    qapp.processEvents()
    layout = view.document().lastBlock().layout()
    message_x = view.fontMetrics().horizontalAdvance("07:30:55  warning ")
    assert len("07:30:55  warning ") == PREFIX_CHARS
    assert layout.lineCount() > 1
    assert layout.lineAt(0).x() == 0
    assert all(layout.lineAt(n).x() == message_x for n in range(1, layout.lineCount()))
    assert view.shown_lines()[0] == "07:30:54  info    short"
    view.set_level(LogLevel.ERRORS)
    assert view.shown_lines() == []
    view.set_level(LogLevel.INFO)
    assert len(view.shown_lines()) == 2
    view.close()
