"""The server window's questions are non-blocking dialogs: a hand-over or menu item
arriving while the loop runs tasks never stops the loop; plus what the window
shows around them (status bar on menu hover, emulator windows after a new file)."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import shiboken6
from client_support import run_on_qt
from helpers import until
from PySide6.QtGui import QStatusTipEvent
from test_server_window import EXAMPLES, Harness

from moas_gui.ui.qt import QApplication, QMessageBox


@pytest.fixture
def harness(tmp_path: Path) -> Iterator[Harness]:
    yield Harness(tmp_path)


def gone(widget: Any) -> bool:
    """Closed (and maybe already deleted)."""
    return not shiboken6.isValid(widget) or not widget.isVisible()


def real_dialogs(harness: Harness) -> Any:
    window = harness.make()
    window.ask = window._ask_dialog
    window.choose_file = window._file_dialog
    return window


def test_a_hand_over_inside_a_task_asks_without_stopping_the_loop(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = real_dialogs(harness)
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        ticks = 0

        async def ticker() -> None:
            nonlocal ticks
            while True:
                ticks += 1
                await asyncio.sleep(0.01)

        beat = asyncio.ensure_future(ticker())

        async def hand_over() -> None:  # as the instance server calls it: inside a task
            window.open_file(str(EXAMPLES / "2x6.moas"))

        await asyncio.wait_for(hand_over(), 2)
        box = window.last_dialog
        assert box is not None and box.isVisible() and "open 2x6.moas?" in box.text()
        before = ticks
        await until(lambda: ticks > before + 5, what="the loop running while the question waits")
        box.button(QMessageBox.StandardButton.Yes).click()
        await until(lambda: len(window._tasks) == 0 and harness.app is not None
                    and harness.app.status.file == "2x6.moas", timeout=10)
        beat.cancel()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_no_in_the_real_dialog_keeps_the_running_file(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = real_dialogs(harness)
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.open_file(str(EXAMPLES / "2x6.moas"))
        assert window.last_dialog is not None
        window.last_dialog.button(QMessageBox.StandardButton.No).click()
        await asyncio.sleep(0.05)
        await window.idle()
        assert harness.app is not None and harness.app.status.file == "small-station.moas"
        await harness.close()
    run_on_qt(qapp, scenario())


def test_a_newer_question_replaces_the_open_one_and_only_its_answer_counts(
        qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = real_dialogs(harness)
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.open_file(str(EXAMPLES / "big-station.moas"))
        older = window.last_dialog
        assert older is not None and "open big-station.moas?" in older.text()
        window.open_file(str(EXAMPLES / "2x6.moas"))  # a second quick launch
        newer = window.last_dialog
        assert newer is not older and "open 2x6.moas?" in newer.text()
        assert gone(older), "the older question is closed, not left underneath"
        questions = [w for w in window.findChildren(QMessageBox) if w.isVisible()]
        assert questions == [newer]
        window._answered(2, str(EXAMPLES / "big-station.moas"), True)  # a late older Yes
        await window.idle()
        assert harness.app is not None and harness.app.status.file == "small-station.moas"
        newer.button(QMessageBox.StandardButton.Yes).click()
        await until(lambda: len(window._tasks) == 0 and harness.app is not None
                    and harness.app.status.file == "2x6.moas", timeout=10)
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_open_dialog_starts_in_the_open_files_folder(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = real_dialogs(harness)
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.action_open.trigger()
        dialog = window.file_dialog
        assert dialog is not None and dialog.isVisible()
        assert Path(dialog.directory().absolutePath()) == EXAMPLES.resolve()
        dialog.reject()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_hovering_a_menu_does_not_blank_the_status_bar(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        await until(lambda: "switch 1 ok" in window.statusBar().currentMessage())
        QApplication.sendEvent(window, QStatusTipEvent(""))  # what a hovered menu item sends
        assert "switch 1 ok" in window.statusBar().currentMessage()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_emulator_window_follows_a_new_file_and_a_restart(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "big-station.moas"))
        await window.idle()
        window.emulator_menu.actions()[0].trigger()
        old = window.emulator_windows[1]
        assert old.isVisible()
        harness.answers.append(True)
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        assert gone(old), "the old station's emulator window is closed"
        app = harness.app
        assert app is not None
        window.emulator_menu.actions()[0].trigger()
        new = window.emulator_windows[1]
        assert new is not old and new.box is app.emulators()[1]
        window.action_restart.trigger()
        await window.idle()
        assert gone(new)
        window.emulator_menu.actions()[0].trigger()
        assert window.emulator_windows[1].box is app.emulators()[1]
        await harness.close()
    run_on_qt(qapp, scenario())


def test_log_errors_shows_errors_only(qapp: Any, harness: Harness) -> None:
    import logging

    from moas_gui.ui.log_view import LogLevel

    async def scenario() -> None:
        window = harness.make()
        window.level_actions[LogLevel.ERRORS].trigger()
        product = logging.getLogger("moas_gui.test")
        product.warning("a warning for the journal")
        product.error("an error for the operator")
        await asyncio.sleep(0.05)
        shown = window.log_view.shown_lines()
        assert any("an error for the operator" in line for line in shown)
        assert not any("a warning for the journal" in line for line in shown)
        await harness.close()
    run_on_qt(qapp, scenario())


def test_stop_and_start_each_log_one_line(qapp: Any, harness: Harness) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        window.action_stop_start.trigger()
        window.action_stop_start.trigger()
        await asyncio.sleep(0.05)
        lines = window.log_view.shown_lines()
        assert sum("Switches stopped" in line for line in lines) == 1, lines
        assert sum("Switches started" in line for line in lines) == 1, lines
        await harness.close()
    run_on_qt(qapp, scenario())


def test_help_manual_shows_the_manual_rendered_in_the_program(
        qapp: Any, harness: Harness) -> None:
    """Help > Manual renders the Markdown itself (never the desktop's opener, which once
    started a terminal editor with no terminal): its first heading shows, a link to
    another page opens it in the same window, Back returns, Contents starts again."""
    from moas_gui.ui.server_window import docs_path

    async def scenario() -> None:
        window = harness.make()
        window.action_manual.trigger()
        manual = window.manual_window
        assert manual is not None and manual.isVisible()
        first = next(line for line in (docs_path() / "README.md").read_text().splitlines()
                     if line.startswith("# "))
        assert manual.first_heading() == first[2:].strip()
        assert "#" not in manual.browser.toPlainText().splitlines()[0]  # rendered, not raw
        manual.show_page("server.md")
        assert manual.page == "server.md" and manual.first_heading() != first[2:].strip()
        assert manual.back.isEnabled()
        manual.back.click()
        assert manual.page in ("server.md", "README.md")
        manual.contents.click()
        assert manual.page == "README.md"
        manual.grab().save(str(harness.tmp_path / "manual.png"))
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_manual_ships_inside_the_package() -> None:
    from moas_gui.ui.server_window import docs_path

    manual = docs_path()
    assert manual.parent.name == "moas_gui" or (manual / "architecture.md").is_file()
    import tomllib

    project = tomllib.loads((EXAMPLES.parent / "pyproject.toml").read_text())
    shipped = project["tool"]["setuptools"]["package-data"]["moas_gui"]
    assert "manual/*.md" in shipped and "manual/images/*.png" in shipped
    assert (EXAMPLES.parent / "moas_gui" / "manual" / "README.md").is_file()


@pytest.mark.parametrize(("screen", "scale"), [((1280, 800), 1), ((1920, 1080), 2)])
def test_client_and_emulator_windows_fit_a_laptop_and_a_scaled_screen(
        qapp: Any, harness: Harness, screen: tuple[int, int], scale: int) -> None:
    """The minimum size (in device-independent pixels, times the scale factor) fits the
    screen less a taskbar and title bar, on big-station, the widest example."""
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "big-station.moas"))
        await window.idle()
        window.action_client.trigger()
        (client,) = window.client_windows
        await until(lambda: bool(client.grid.buttons), timeout=10)
        window.open_emulator(1)
        for shown in (client, window.emulator_windows[1]):
            hint = shown.minimumSizeHint().expandedTo(shown.minimumSize())
            assert hint.width() * scale <= screen[0] - 40, (type(shown).__name__, hint)
            assert hint.height() * scale <= screen[1] - 100, (type(shown).__name__, hint)
        client.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_the_client_content_fits_a_laptop_without_scrolling(qapp: Any, harness: Harness) -> None:
    """On big-station, tuned to the band with the longest antenna names, the client's
    content needs no more than a 1280x800 laptop gives it: nothing scrolls there."""
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "big-station.moas"))
        await window.idle()
        app = harness.app
        assert app is not None
        app.apply_changes(app.engine.set_frequency(1, 1, 14025.0))
        window.action_client.trigger()
        (client,) = window.client_windows
        await until(lambda: "stack" in client.display.text(), timeout=10)
        content = client.scroll_area.widget().minimumSizeHint()
        assert content.width() <= 1240 and content.height() <= 720, content
        client.close()
        await harness.close()
    run_on_qt(qapp, scenario())


def test_a_start_that_fails_half_way_shows_no_configuration(
        qapp: Any, harness: Harness, monkeypatch: pytest.MonkeyPatch) -> None:
    async def scenario() -> None:
        window = harness.make()
        window.open_file(str(EXAMPLES / "small-station.moas"))
        await window.idle()
        app = harness.app
        assert app is not None and app.client_address is not None
        port = app.client_address[1]

        async def broken(*_: Any) -> None:
            raise RuntimeError("the N1MM listener broke")

        monkeypatch.setattr("moas_gui.app.start_sources", broken)
        harness.answers.append(True)
        window.open_file(str(EXAMPLES / "2x6.moas"))
        await window.idle()
        assert app.config is None and app.client_address is None
        assert window.statusBar().currentMessage() == "No configuration open"
        assert window.windowTitle() == "MOAS Server"
        with pytest.raises(OSError):
            await asyncio.open_connection("127.0.0.1", port)
        assert any("could not be started" in line for line in window.log_view.shown_lines())
        await harness.close()
    run_on_qt(qapp, scenario())
