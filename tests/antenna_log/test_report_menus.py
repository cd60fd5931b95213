"""The server window's View > Contest report... and File > Export antenna log... (offscreen,
on a qasync loop): each opens its window on the server's journal, or says there is none."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from antenna_log_support import charts_loaded, contest_journal
from client_support import run_on_qt

from moas_gui.app import ServerApp, ServerOptions
from moas_gui.ui.qt import QSettings
from moas_gui.ui.server_window import ServerWindow


@pytest.fixture(scope="module", autouse=True)
def _charts_loaded() -> None:
    charts_loaded()  # matplotlib, imported here and kept out of the collector (see there)


def make_window(tmp_path: Path) -> tuple[ServerWindow, ServerApp]:
    app = ServerApp(
        ServerOptions(
            bind="127.0.0.1",
            tcp_port=0,
            udp_port=0,
            udp_bind="127.0.0.1",
            start_rotator_program=False,
        )
    )
    settings = QSettings(str(tmp_path / "s.ini"), QSettings.Format.IniFormat)
    return ServerWindow(app, settings, lambda: None), app


async def close(window: ServerWindow, app: ServerApp) -> None:
    await window.idle()
    window.shutdown()
    window.close()
    await app.close()


def test_view_contest_report_shows_the_servers_journal(
    qapp: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from moas_gui.ui.report_window import ReportWindow

    async def scenario() -> None:
        window, app = make_window(tmp_path)
        journal = contest_journal()
        monkeypatch.setattr(type(app), "antenna_journal", property(lambda _self: journal))
        assert window.action_report.text() == "Contest &Report..."
        window.action_report.trigger()
        await window.idle()
        report = window.report_window
        assert isinstance(report, ReportWindow) and report.isVisible()
        assert report.report is not None and report.report.contacts == 15
        window.action_report.trigger()  # again: a fresh window in place of the old
        await window.idle()
        assert window.report_window is not report and not report.isVisible()
        await close(window, app)
        assert not window.report_window.isVisible()

    run_on_qt(qapp, scenario())


def test_without_a_journal_the_report_says_so(qapp: Any, tmp_path: Path) -> None:
    from moas_gui.ui.report_window import NO_JOURNAL, ReportWindow

    async def scenario() -> None:
        window, app = make_window(tmp_path)
        window.action_report.trigger()
        await window.idle()
        report = window.report_window
        assert isinstance(report, ReportWindow)
        assert report.notice.text() == NO_JOURNAL
        await close(window, app)

    run_on_qt(qapp, scenario())


def test_file_export_antenna_log_opens_the_export(
    qapp: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from moas_gui.ui.report_window import AdifExportWindow

    async def scenario() -> None:
        window, app = make_window(tmp_path)
        journal = contest_journal()
        monkeypatch.setattr(type(app), "antenna_journal", property(lambda _self: journal))
        assert window.action_export_log.text() == "Export Antenna &Log..."
        window.action_export_log.trigger()
        await window.idle()
        export = window.export_window
        assert isinstance(export, AdifExportWindow) and export.isVisible()
        assert export.save.isEnabled()
        assert export.chooser.start.text() == "2026-11-18T11:00Z"
        await close(window, app)
        assert not export.isVisible()

    run_on_qt(qapp, scenario())


def test_file_keep_an_antenna_log_turns_the_running_journal_off_and_on(
    qapp: Any, tmp_path: Path
) -> None:
    from helpers import until

    examples = Path(__file__).resolve().parents[2] / "examples"

    async def scenario() -> None:
        window, app = make_window(tmp_path)
        assert window.action_antenna_log.isChecked()
        window.open_file(str(examples / "small-station.moas"))
        await window.idle()
        await until(lambda: app.antenna_journal is not None, what="the journal opened")
        window.action_antenna_log.setChecked(False)  # as a click on the menu item does
        await window.idle()
        assert app.antenna_journal is None and not app.antenna_log_on
        window.action_report.trigger()
        await window.idle()
        assert window.report_window is not None and window.report_window.report is None
        window.action_antenna_log.setChecked(True)
        await window.idle()
        assert app.antenna_journal is not None and app.antenna_log_on
        await close(window, app)

    run_on_qt(qapp, scenario())
