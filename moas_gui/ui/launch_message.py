"""A launch that cannot go on says so where the person looks.

A double-click on a ``.moas`` file or a menu entry has no terminal: a reason
printed on standard error alone is never seen.  :func:`tell_launch_refused`
prints the reason on standard error *and*, when a window can be shown, shows
it in a message window (with what to do) before the program exits non-zero.
Without a display only standard error is left, and says so.

It runs before any event loop (the program has not started serving), so the
message window's own ``exec()`` is the only loop there is.  On a platform with
no screen (``QT_QPA_PLATFORM=offscreen``, which tests use) nobody could press
OK: the window is shown, closed at once, and the terminal says it was.
"""

from __future__ import annotations

import os
import sys
from typing import Any

from .display import display_problem

__all__ = ["refusal_box", "tell_launch_refused"]


def tell_launch_refused(program: str, reason: str, advice: str, *, detail: str = "",
                        window: bool = True, title: str = "",
                        window_detail: str | None = None) -> None:
    """``program: reason; advice`` on stderr, and in a message window when ``window``
    and a display can be opened.  Returns once the window is closed."""
    line = f"{program}: {reason}"
    if advice:
        line += f"; {advice}"
    if detail:
        print(detail, file=sys.stderr)
    print(line, file=sys.stderr)
    if not window:
        return
    problem = display_problem()
    if problem is not None:
        print(f"{program}: no message window either: {problem}", file=sys.stderr)
        return
    _show(program, reason, advice, detail if window_detail is None else window_detail, title)


def refusal_box(program: str, reason: str, advice: str, detail: str, title: str = "") -> Any:
    """The message window: the reason, then what to do, then the details (a file's
    problems) in the window itself, not behind a "Show Details" button."""
    from .qt import QMessageBox

    box = QMessageBox(QMessageBox.Icon.Critical, title or f"{program} did not start",
                      f"{reason[:1].upper()}{reason[1:]}." if title
                      else f"{program} did not start: {reason}.",
                      QMessageBox.StandardButton.Ok)
    informative = f"What to do: {advice[:1].upper()}{advice[1:]}." if advice else ""
    if detail:
        informative = f"{detail}\n\n{informative}" if informative else detail
    box.setInformativeText(informative)
    return box


def _show(program: str, reason: str, advice: str, detail: str, title: str) -> None:
    from .qt import QApplication, QTimer

    existing = QApplication.instance()
    application = existing if isinstance(existing, QApplication) else QApplication([program])
    box = refusal_box(program, reason, advice, detail, title)
    platform = os.environ.get("QT_QPA_PLATFORM", "") or application.platformName()
    if platform.split(":", 1)[0] in ("offscreen", "minimal"):
        QTimer.singleShot(0, box.accept)
        print(f"{program}: showed a message window (closed at once: the '{platform}' "
              "platform has no screen)", file=sys.stderr)
    box.exec()
