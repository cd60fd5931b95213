"""``moas_gui/app.py`` stays a door and a fan-out: under 350 lines (issue 41).

What the window reads is ``server_view.py``, the switch links' callbacks
``switch_events.py``, the antenna log's wiring ``antenna_feed.py``, opening a file
``opening.py`` and the parts one configuration runs ``running.py``; a job that grows
back into the app shows here first."""

from __future__ import annotations

from pathlib import Path

APP = Path(__file__).resolve().parents[2] / "moas_gui" / "app.py"
MOST = 349
"""The most lines app.py may have."""


def too_long(text: str, most: int = MOST) -> str | None:
    """Why ``text`` (a module's source) is too long for the app, or None."""
    lines = len(text.splitlines())
    if lines > most:
        return f"app.py has {lines} lines, more than {most}: move a job into a part of its own"
    return None


def test_app_py_is_under_350_lines() -> None:
    assert too_long(APP.read_text(encoding="utf-8")) is None


def test_the_rule_fires_on_an_app_grown_back() -> None:
    grown = APP.read_text(encoding="utf-8") + "\n" * (MOST + 1)
    why = too_long(grown)
    assert why is not None and "more than 349" in why
