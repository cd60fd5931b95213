"""The server window: the log, the File/View/Help menus, the status bar and the tray.

It mirrors the original server (manual chapter 3) and holds no state of its
own beyond what the user sees: everything it shows comes from the
:class:`~moas_gui.app.ServerApp` it is given, and every menu item calls that.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
from collections.abc import Callable, Coroutine, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from moas_gui import __version__
from moas_gui.aio import BackgroundTasks
from moas_gui.log_repeats import fold_repeats
from moas_gui.status import ServerState, ServerStatus

from .dialogs import ask_yes_no, choose_file, docs_path, show_message, show_problems
from .holds_bar import HoldsBar
from .icons import app_icon, status_icon
from .log_view import LogLevel, LogView, QtLogHandler
from .manual_window import ManualWindow
from .qt import (
    QAction,
    QActionGroup,
    QApplication,
    QCloseEvent,
    QEvent,
    QFileDialog,
    QIcon,
    QLabel,
    QMainWindow,
    QMenu,
    QMessageBox,
    QSettings,
    QSystemTrayIcon,
    Qt,
    QVBoxLayout,
    QWidget,
    added,
)
from .screen_fit import fit_to_screen

if TYPE_CHECKING:
    from moas_gui.app import ServerApp

    from .client_window import ClientWindow

log = logging.getLogger(__name__)


def _load_charts() -> None:
    """Imports what the contest report draws with (matplotlib, its fonts), off the loop."""
    import matplotlib.backends.backend_agg
    import matplotlib.dates
    import matplotlib.figure  # noqa: F401

    import moas_gui.antenna_log.report_charts  # noqa: F401

RECENT_MAX = 4


class ServerWindow(QMainWindow):
    """The main window of ``moas-server``."""

    def __init__(self, app: ServerApp, settings: QSettings, quit_requested: Callable[[], None],
                 parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.app = app
        self.settings = settings
        self._quit_requested = quit_requested
        self._tasks = BackgroundTasks(self._task_failed)
        """The menu actions and the ends of closed client windows: :meth:`idle` waits."""
        """The menu actions that run (open, restart, save switch data, the plan) and the
        ends of client windows' connections; :meth:`idle` waits for them."""
        self._state: ServerState | None = None
        self.client_windows: list[ClientWindow] = []
        self.emulator_windows: dict[int, QWidget] = {}
        self.plan_window: QWidget | None = None
        """View > Station plan, while open."""
        self.builder_windows: list[QWidget] = []
        """File > Edit Station..., while open."""
        self.report_window: QWidget | None = None
        """View > Contest report, while open."""
        self.export_window: QWidget | None = None
        """File > Export antenna log, while open."""
        self.last_dialog: QMessageBox | None = None
        self._question: QMessageBox | None = None
        """The open "Stop ... and open ...?" question, if any: one at a time."""
        self._question_number = 0
        self.file_dialog: QFileDialog | None = None
        self.manual_window: ManualWindow | None = None
        """Help > Manual, once opened (kept: it opens again at its contents)."""
        self.ask: Callable[[str, str, Callable[[bool], None]], None] = self._ask_dialog
        """Asks the user a yes/no question without waiting (a window-modal dialog
        opened with ``open()``): the answer comes later to the callback.  Tests
        replace it with a fake that answers."""
        self.choose_file: Callable[[str, bool, Callable[[str], None]], None] = self._file_dialog
        """Asks for a file name (title, saving, then the callback with the name), the same way."""

        self.setWindowTitle("MOAS Server")
        fit_to_screen(self, 760, 420)
        self.log_view = LogView(self)
        self.holds_bar = HoldsBar(self)
        """Each held radio, who holds it since when, and its Release (docs/antenna-genius.md)."""
        central = QWidget(self)
        column = QVBoxLayout(central)
        column.setContentsMargins(0, 0, 0, 0)
        column.setSpacing(0)
        column.addWidget(self.holds_bar)
        column.addWidget(self.log_view, 1)
        self.setCentralWidget(central)
        self.log_handler = fold_repeats(QtLogHandler())
        self.log_handler.bridge.record.connect(self.log_view.add_record)
        product_log = logging.getLogger("moas_gui")
        product_log.addHandler(self.log_handler)
        product_log.setLevel(logging.DEBUG)  # the view filters by the chosen level

        self._build_menus()
        self._build_tray()
        self._summary = "No configuration open"
        self.statusBar().showMessage(self._summary)
        self.security_label = QLabel(self)
        """Who may connect: an open LAN, TLS and its fingerprint (ServerApp.security)."""
        self.statusBar().addPermanentWidget(self.security_label)
        self.pair_dialog: Any = None
        show_bar = self.settings.value("view/statusBar", True, type=bool)
        self.statusBar().setVisible(bool(show_bar))
        self.action_status_bar.setChecked(bool(show_bar))
        level = LogLevel(str(self.settings.value("view/logLevel", LogLevel.INFO.value)))
        self.set_log_level(level)
        app.add_status_listener(self.show_status)
        app.add_alert_listener(self.alert)
        app.add_hold_listener(self.holds_bar.show_holds)
        self.holds_bar.release_requested.connect(self.release_hold)
        self.holds_bar.show_holds(app.holds())
        self.show_status(app.status)

    # -- menus -------------------------------------------------------------------
    def _build_menus(self) -> None:
        bar = self.menuBar()
        file_menu = bar.addMenu("&File")
        self.action_open = added(file_menu.addAction("&Open...", self.open_dialog))
        self.action_open.setShortcut("Ctrl+O")
        self.recent_menu = file_menu.addMenu("Recent &Files")
        file_menu.addSeparator()
        self.action_edit_station = added(file_menu.addAction("&Edit Station...", self.edit_station))
        self.action_reset = added(file_menu.addAction("&Reset Switches", self.reset_switches))
        self.action_save_data = added(file_menu.addAction("&Save Switch Data...", self.save_switch_data))
        self.action_export_log = added(file_menu.addAction("Export Antenna &Log...",
                                                     self.export_antenna_log))
        self.action_antenna_log = added(file_menu.addAction("&Keep an Antenna Log"))
        """On: the antenna journal is written (docs/antenna-log.md); off for SD-card wear
        or privacy, as ``--no-antenna-log`` starts it."""
        self.action_antenna_log.setCheckable(True)
        self.action_antenna_log.setChecked(self.app.antenna_log_on)
        self.action_antenna_log.toggled.connect(
            lambda on: self._spawn(self.app.set_antenna_log(on)))
        self.action_stop_start = added(file_menu.addAction("S&top Switches", self.toggle_switches))
        file_menu.addSeparator()
        self.action_restart = added(file_menu.addAction("Rest&art", self.restart))
        self.action_exit = added(file_menu.addAction("E&xit", self.exit))
        self.action_exit.setShortcut("Ctrl+Q")

        view = bar.addMenu("&View")
        self.action_status_bar = added(view.addAction("&Status Bar"))
        self.action_status_bar.setCheckable(True)
        self.action_status_bar.toggled.connect(self._toggle_status_bar)
        view.addSeparator()
        group = QActionGroup(self)
        self.level_actions: dict[LogLevel, QAction] = {}
        for level, label in ((LogLevel.ERRORS, "Log &Errors"), (LogLevel.INFO, "Log &Info"),
                             (LogLevel.DEBUG, "Log &Debug")):
            action = added(view.addAction(label))
            action.setCheckable(True)
            group.addAction(action)
            action.triggered.connect(lambda _=False, lv=level: self.set_log_level(lv))
            self.level_actions[level] = action
        view.addSeparator()
        self.action_client = added(view.addAction("&Client", self.open_client))
        self.action_plan = added(view.addAction("Station &Plan", self.open_plan))
        self.action_report = added(view.addAction("Contest &Report...", self.open_report))
        self.action_pair = added(view.addAction("P&air a Device...", self.pair_device))
        self.emulator_menu = view.addMenu("E&mulator")

        help_menu = bar.addMenu("&Help")
        self.action_about = added(help_menu.addAction("&About MOAS Server", self.about))
        self.action_manual = added(help_menu.addAction("&Manual", self.open_manual))
        self._refresh_recent()

    def _build_tray(self) -> None:
        self.tray = QSystemTrayIcon(self)
        menu = QMenu(self)
        self.tray_show = added(menu.addAction("Hide Window", self.toggle_visible))
        self.tray_stop_start = added(menu.addAction("Stop Switches", self.toggle_switches))
        menu.addSeparator()
        menu.addAction("Exit", self.exit)
        self.tray_menu = menu
        self.tray.setContextMenu(menu)
        self.tray.activated.connect(self._tray_activated)
        self.tray.setIcon(status_icon(self.app.status.state))
        if QSystemTrayIcon.isSystemTrayAvailable():
            self.tray.show()

    def _tray_activated(self, reason: QSystemTrayIcon.ActivationReason) -> None:
        if reason == QSystemTrayIcon.ActivationReason.Trigger:
            self.toggle_visible()

    # -- status ----------------------------------------------------------------------
    def show_status(self, status: ServerStatus) -> None:
        """Show ``status`` in the title, status bar, window icon and tray (called on every change)."""
        if status.state is not self._state:
            self._state = status.state
            icon = status_icon(status.state)
            self.setWindowIcon(icon)
            self.tray.setIcon(icon)
        self._summary = status.summary
        self.statusBar().showMessage(status.summary)
        self.tray.setToolTip(f"MOAS Server: {status.summary}")
        security = self.app.security
        self.security_label.setText(security[0] if security is not None else "")
        self.security_label.setToolTip(security[1] if security is not None else "")
        title = "MOAS Server" if status.file is None else f"{status.file} - MOAS Server"
        self.setWindowTitle(title)
        self._refresh_actions()

    def event(self, event: QEvent) -> bool:
        """A menu item without a status tip sends an empty one on hover, which would
        blank the status bar until the next change: show the status again instead."""
        if event.type() == QEvent.Type.StatusTip and not event.tip():  # type: ignore[attr-defined]
            self.statusBar().showMessage(self._summary)
            return True
        return super().event(event)

    def release_hold(self, station: int, radio: int) -> None:
        """A hold's Release: the server window may release any (it is this computer)."""
        refusal = self.app.release_hold(station, radio)
        if refusal is not None:
            self._message(QMessageBox.Icon.Warning, "Release", refusal)

    def alert(self, title: str, message: str) -> None:
        """A critical event (a switch lost): a tray message when there is a tray."""
        if self.tray.isVisible() and QSystemTrayIcon.supportsMessages():
            self.tray.showMessage(title, message, QSystemTrayIcon.MessageIcon.Critical, 10_000)

    def _refresh_actions(self) -> None:
        running = self.app.config is not None
        stopped = self.app.switches_stopped
        for action in (self.action_reset, self.action_save_data, self.action_stop_start,
                       self.tray_stop_start, self.action_restart, self.action_plan):
            action.setEnabled(running)
        label = "S&tart Switches" if stopped else "S&top Switches"
        self.action_stop_start.setText(label)
        self.tray_stop_start.setText(label.replace("&", ""))
        self.emulator_menu.clear()
        emulators = self.app.emulators()
        self._close_stale_emulator_windows(emulators)
        for switch_id in sorted(emulators):
            self.emulator_menu.addAction(f"Switch {switch_id}",
                                         functools.partial(self.open_emulator, switch_id))
        self.emulator_menu.menuAction().setVisible(bool(emulators))

    def _close_stale_emulator_windows(self, emulators: dict[int, Any]) -> None:
        """An emulator window whose switch no longer runs (another file, Restart) would
        show frozen relays: close it."""
        for switch_id, window in list(self.emulator_windows.items()):
            if emulators.get(switch_id) is not getattr(window, "box", None):
                del self.emulator_windows[switch_id]
                window.close()
                window.deleteLater()

    # -- file menu -------------------------------------------------------------------
    def open_dialog(self) -> None:
        self.choose_file("Open configuration", False,
                         lambda path: self.open_file(path) if path else None)

    def take_hand_over(self, path: Path | None) -> None:
        """Another launch handed ``path`` over: the same file (or none) brings this window
        forward; another file is asked about (without waiting)."""
        self.bring_to_front()
        if path is None:
            return
        running = self.app.path
        if running is not None and self.app.config is not None and \
                Path(path).resolve() == running.resolve():
            log.info("%s is already open", Path(path).name)
            return
        self.open_file(str(path))

    def open_file(self, path: str) -> None:
        """Open ``path``; when one runs already, ask first, then restart on the new one.

        Returns at once: the question is a non-blocking dialog whose answer
        opens the file later (never a nested event loop, see docs/architecture.md).
        One question at a time: a newer one (another launch, File > Open) closes
        the one on screen, and only the answer to the newest takes effect."""
        self._question_number += 1
        number = self._question_number
        self._close_question()
        if self.app.config is not None:
            current = self.app.status.file or "the current configuration"
            self.ask("Open configuration",
                     f"Stop {current} and open {Path(path).name}?\n\n"
                     f"{path}\n\n"
                     "The switches will be re-initialised from the new file.",
                     lambda yes: self._answered(number, path, yes))
            return
        self._spawn(self._open(path))

    def _answered(self, number: int, path: str, yes: bool) -> None:
        if number != self._question_number:  # replaced by a newer question: not on screen
            log.info("The question about %s was replaced by a newer one; its answer is ignored",
                     Path(path).name)
            return
        self._question = None
        if yes:
            self._spawn(self._open(path))

    def _close_question(self) -> None:
        """Closes the open question (its late answer is ignored, see :meth:`_answered`)."""
        question, self._question = self._question, None
        if question is not None:
            with contextlib.suppress(RuntimeError):  # already deleted by Qt
                if question.isVisible():
                    question.done(int(QMessageBox.StandardButton.No))

    async def _open(self, path: str) -> None:
        result = await self.app.open(path)
        if result.config is None:
            self._show_problems(path, result)
            return
        self._remember_recent(str(Path(path).resolve()))
        self._follow_client_port()

    def _follow_client_port(self) -> None:
        """Built-in clients of a configuration with another ``TCPPort`` would knock on
        the old port for ever: replace them with ones on the new port."""
        address = self.app.client_address
        if address is None:
            return
        stale = [w for w in self.client_windows
                 if getattr(getattr(w, "connection", None), "port", address[1]) != address[1]]
        for window in stale:
            self.client_windows.remove(window)
            self._close_client(window)
            self.open_client()

    def _remember_recent(self, path: str) -> None:
        recent = [p for p in self.recent_files() if p != path]
        recent.insert(0, path)
        self.settings.setValue("recentFiles", recent[:RECENT_MAX])
        self._refresh_recent()

    def recent_files(self) -> list[str]:
        value = self.settings.value("recentFiles", [])
        if isinstance(value, str):
            return [value]
        if not isinstance(value, list):
            return []
        return [str(v) for v in value][:RECENT_MAX]

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        recent = self.recent_files()
        for number, path in enumerate(recent, 1):
            self.recent_menu.addAction(f"&{number} {path}", functools.partial(self.open_file, path))
        self.recent_menu.setEnabled(bool(recent))

    def save_switch_data(self) -> None:
        self.choose_file("Save switch data", True,
                         lambda path: self._spawn(self._save_switch_data(path)) if path else None)

    async def _save_switch_data(self, path: str) -> None:
        try:
            await self.app.save_switch_data(path)
        except OSError as exc:
            log.error("Could not save switch data to %s: %s", path, exc.strerror or exc)
        else:
            log.info("Switch data saved to %s", path)

    def toggle_switches(self) -> None:
        if self.app.switches_stopped:
            self.app.start_switches()
        else:
            self.ask_first("Stop Switches", "opens every relay of every switch at once",
                           self.app.stop_switches)

    def reset_switches(self) -> None:
        self.ask_first("Reset Switches", "resets every switch: every relay opens at once, "
                       "then the antennas in use are set again", self.app.reset_switches)

    def ask_first(self, what: str, effect: str, act: Callable[[], None],
                  named: Sequence[str] = ()) -> None:
        """Do ``act`` (Stop or Reset Switches) at once while nobody transmits; else ask
        first, naming who does.  Confirmed, it looks again: a station keyed since the
        question was put is asked about too, before anything happens."""
        keyed = self.app.keyed_radios()
        if not keyed or set(keyed) <= set(named):
            if keyed:
                log.warning("%s while %s transmit%s, confirmed by the operator", what,
                            ", ".join(keyed), "s" if len(keyed) == 1 else "")
            act()
            return
        who = "\n".join(f"  {name}" for name in keyed)
        self.ask(f"{what} while transmitting?",
                 f"{what} {effect}.\n\nTransmitting now:\n{who}\n\n"
                 "Their relays would open under the key (hot switching): unkey first, or "
                 f"{what.lower()} anyway?",
                 lambda yes: self.ask_first(what, effect, act, keyed) if yes else None)

    def edit_station(self) -> None:
        """File > Edit Station...: the station builder on the open configuration (or on a
        file chosen, a new name starting a new station); its Save and Restart comes back to
        :meth:`restart_on`."""
        if self.app.path is not None:
            self._open_builder(Path(self.app.path))
            return
        dialog = QFileDialog(self, "Edit a station (a new name starts a new station)",
                             str(Path.home()), "MOAS stations (*.moas);;All files (*)")
        dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
        dialog.setOption(QFileDialog.Option.DontConfirmOverwrite, True)
        dialog.setDefaultSuffix("moas")
        dialog.fileSelected.connect(lambda name: self._open_builder(Path(name)))
        self.file_dialog = dialog
        dialog.open()

    def _open_builder(self, path: Path) -> None:
        from .builder_window import open_builder

        def refused(reason: str) -> None:
            log.error("%s", reason)
            self.last_dialog = show_message(self, QMessageBox.Icon.Warning, "Station builder",
                                            reason)
        window = open_builder(path, self.restart_on, refused)
        if window is not None:
            self.builder_windows.append(window)
            window.destroyed.connect(lambda *_: self.builder_windows.remove(window)
                                     if window in self.builder_windows else None)

    def restart_on(self, path: Path) -> None:
        """The builder's Save and Restart: File > Restart on the saved file when it is the
        running one (else File > Open's path, which asks first); while a station transmits,
        asked first, naming who does."""
        running = self.app.path
        if running is not None and Path(running).resolve() == path.resolve():
            self.ask_first("Restart", "restarts the server on the saved file: the antennas "
                           "of every radio are chosen again", self.restart)
            return
        self.ask_first("Open", f"stops the running configuration and opens {path}",
                       lambda: self.open_file(str(path)))

    def restart(self) -> None:
        """File > Restart: the file is checked first; with errors it is not restarted,
        the running configuration carries on and a dialog shows the problems."""
        self._spawn(self._restart())

    async def _restart(self) -> None:
        path = self.app.path
        result = await self.app.restart()
        if result is not None and result.config is None and path is not None:
            self._show_problems(str(path), result, restarting=True)

    async def restart_file(self, path: Path) -> Any:
        """The station builder's Save and Restart from another process: File > Restart when
        ``path`` is the running file, else File > Open's opening (the builder asked the
        operator first); a file with errors is not taken, the running configuration
        carries on and the problems are shown here too."""
        running = self.app.path
        if running is not None and Path(running).resolve() == path.resolve():
            result = await self.app.restart()
        else:
            result = await self.app.open(path)
            if result.config is not None:
                self._remember_recent(str(path.resolve()))
                self._follow_client_port()
        if result is not None and result.config is None:
            self._show_problems(str(path), result, restarting=True)
        return result

    def _show_problems(self, path: str, result: Any, restarting: bool = False) -> None:
        # the path is said once above; each problem with its line and column
        shown = "\n".join((f"line {p.line}, column {p.column}: " if p.line else "")
                          + p.message for p in result.errors[:20])
        more = f"\n... and {len(result.errors) - 20} more" if len(result.errors) > 20 else ""
        running = self.app.config is not None
        if restarting:
            title = "Not restarted: the file has errors"
            text = (f"{path} has errors, so it was not restarted: the running configuration "
                    "carries on unchanged (switches, clients, rotators and loggers).")
        else:
            title = "Configuration not opened"
            text = (f"{path} has errors and was not opened"
                    f"{'; the running configuration carries on' if running else ''}.")
        self.last_dialog = show_problems(self, title, f"{text}\n\nFix the file, then "
                                         f"{'Restart' if restarting else 'open it'} again.",
                                         shown + more, Path(path).resolve().parent)

    def exit(self) -> None:
        self.tray.hide()
        self._quit_requested()

    # -- view menu -------------------------------------------------------------------
    def set_log_level(self, level: LogLevel) -> None:
        self.log_view.set_level(level)
        self.level_actions[level].setChecked(True)
        self.settings.setValue("view/logLevel", level.value)

    def _toggle_status_bar(self, visible: bool) -> None:
        self.statusBar().setVisible(visible)
        self.settings.setValue("view/statusBar", visible)

    def open_client(self) -> None:
        """View > Client: the built-in client, talking to this server over loopback."""
        if self.app.client_address is None:
            log.error("The client needs a running configuration: open one first")
            return
        from .client_window import open_builtin_client

        self.client_windows.append(open_builtin_client(self.app))

    def pair_device(self) -> None:
        """View > Pair a device: a new operator's token as a QR code (opened with open(),
        never exec(): the loop keeps running)."""
        from .pair_dialog import PairDialog

        if self.pair_dialog is not None:
            self.pair_dialog.close()
        self.pair_dialog = PairDialog(self, self.app.web_page)
        self.pair_dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose, False)
        self.pair_dialog.open()

    def open_plan(self) -> None:
        """View > Station plan: the plan of the open configuration (the switches are not
        touched); made off the event loop's thread, then shown with ``show()``."""
        config, path = self.app.config, self.app.path
        if config is None:
            log.error("The station plan needs an open configuration: open one first")
            return
        self._spawn(self._open_plan(config, path))

    async def _open_plan(self, config: Any, path: Path | None) -> None:
        from moas_gui.plan import plan_of

        plan, error = await asyncio.to_thread(plan_of, config, path)
        if plan is None:
            log.error("%s", error)
            return
        from .plan_window import PlanWindow

        if self.plan_window is not None:
            self.plan_window.close()
        self.plan_window = PlanWindow(plan)
        self.plan_window.show()
        log.info("Station plan of %s: %d finding%s", plan.file, len(plan.findings),
                 "" if len(plan.findings) == 1 else "s")

    def open_report(self) -> None:
        """View > Contest report: the antenna journal's charts for a chosen period (the
        window says so when the journal is off or empty)."""
        self._spawn(self._open_antenna_log_window(report=True))

    def export_antenna_log(self) -> None:
        """File > Export antenna log: the journal's contacts of a chosen period as ADIF."""
        self._spawn(self._open_antenna_log_window(report=False))

    async def _open_antenna_log_window(self, report: bool) -> None:
        # matplotlib loads off the event loop's thread (the first time takes a while)
        await asyncio.to_thread(_load_charts)
        from .report_window import AdifExportWindow, ReportWindow

        journal = getattr(self.app, "antenna_journal", None)
        old = self.report_window if report else self.export_window
        if old is not None:
            old.close()
        window: QWidget = ReportWindow(journal) if report else AdifExportWindow(journal)
        if report:
            self.report_window = window
        else:
            self.export_window = window
        window.show()

    def open_emulator(self, switch_id: int) -> None:
        emulator = self.app.emulators().get(switch_id)
        if emulator is None:
            return
        window = self.emulator_windows.get(switch_id)
        if window is None or getattr(window, "box", None) is not emulator:
            from .emulator_window import EmulatorWindow

            window = EmulatorWindow(emulator, port=f"switch {switch_id} (built in)")
            window.setWindowTitle(f"MOAS II Emulator - switch {switch_id}")
            self.emulator_windows[switch_id] = window
        window.show()
        window.raise_()

    # -- help menu -------------------------------------------------------------------
    def about(self) -> None:
        self._message(QMessageBox.Icon.Information, "About MOAS Server",
                      f"MOAS Server (moas-gui) version {__version__}\n\n"
                      "An open-source server for the YCCC MOAS II antenna switch.")

    def open_manual(self) -> None:
        """Help > Manual: the manual rendered in a window of its own (Qt renders Markdown),
        never handed raw to the desktop's opener."""
        if self.manual_window is None:
            self.manual_window = ManualWindow(docs_path())
        else:
            self.manual_window.home()
        self.manual_window.show()
        self.manual_window.raise_()
        self.manual_window.activateWindow()

    # -- window and tray -------------------------------------------------------------
    def bring_to_front(self) -> None:
        """Show the window on top (another launch without a file asked for it)."""
        self.show()
        self.raise_()
        self.activateWindow()

    def toggle_visible(self) -> None:
        if self.isVisible():
            self.hide()
        else:
            self.show()
            self.raise_()
            self.activateWindow()

    def hideEvent(self, event: object) -> None:
        self.tray_show.setText("Show Window")
        super().hideEvent(event)  # type: ignore[arg-type]

    def showEvent(self, event: object) -> None:
        self.tray_show.setText("Hide Window")
        super().showEvent(event)  # type: ignore[arg-type]

    def closeEvent(self, event: QCloseEvent) -> None:
        """Closing the window hides it to the tray when there is one; otherwise it exits."""
        if self.tray.isVisible():
            event.ignore()
            self.hide()
            if not self.settings.value("tray/noticeShown", False, type=bool):
                self.settings.setValue("tray/noticeShown", True)
                self.tray.showMessage("MOAS Server", "The server keeps running in the tray. "
                                      "Use Exit in its menu to stop it.",
                                      QSystemTrayIcon.MessageIcon.Information, 8000)
            return
        event.accept()
        self.exit()

    def shutdown(self) -> None:
        logging.getLogger("moas_gui").removeHandler(self.log_handler)
        self.tray.hide()
        for client in self.client_windows:
            self._close_client(client)
        for window in self.emulator_windows.values():
            window.close()
        for other in (self.plan_window, self.report_window, self.export_window):
            if other is not None:
                other.close()

    # -- helpers ---------------------------------------------------------------------
    def _close_client(self, window: ClientWindow) -> None:
        """Close a View > Client window; the end of its connection and its requests is
        one of this window's tasks (:meth:`idle` waits for it)."""
        window.close()
        self._spawn(window.aclose())

    def _spawn(self, coroutine: Coroutine[Any, Any, object]) -> None:
        self._tasks.spawn(coroutine, getattr(coroutine, "__qualname__", "a menu action"))

    @staticmethod
    def _task_failed(what: str, error: BaseException) -> None:
        log.error("Internal error in %s: %s", what, error, exc_info=error)

    async def idle(self) -> None:
        """Wait for every menu action started so far, and for the end of the client
        windows' connections closed so far (for tests and orderly exit: once before the
        server closes, once after :meth:`shutdown`)."""
        await self._tasks.idle()

    def _message(self, icon: QMessageBox.Icon, title: str, text: str) -> None:
        self.last_dialog = show_message(self, icon, title, text)

    def _ask_dialog(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        self.bring_to_front()
        self.last_dialog = self._question = ask_yes_no(self, title, text, answered)

    def _file_dialog(self, title: str, saving: bool, chosen: Callable[[str], None]) -> None:
        self.file_dialog = choose_file(self, title, saving, self._start_directory(), chosen)

    def _start_directory(self) -> Path:
        """Where the Open and Save dialogs start: the open file's folder, else the last one."""
        if self.app.path is not None:
            return self.app.path.resolve().parent
        recent = self.recent_files()
        if recent:
            return Path(recent[0]).parent
        return Path.home()


def application_icon() -> QIcon:
    return app_icon()


def ensure_application() -> QApplication:
    existing = QApplication.instance()
    if isinstance(existing, QApplication):
        return existing
    application = QApplication([])
    application.setApplicationName("moas-server")
    application.setOrganizationName("moas-gui")
    application.setQuitOnLastWindowClosed(False)
    return application


__all__ = ["ServerWindow", "application_icon", "docs_path", "ensure_application"]
