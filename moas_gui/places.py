"""Where moas-gui keeps its files on each system, written once.

=============  ==========================================  =====================================  ==================================
               Linux (and other Unix)                      macOS                                  Windows
=============  ==========================================  =====================================  ==================================
state          ``$XDG_STATE_HOME/moas-gui``                ``~/Library/Application Support/       ``%LOCALAPPDATA%\\moas-gui\\state``
               (``~/.local/state/moas-gui``)               moas-gui``
logs           ``$XDG_STATE_HOME/moas-gui/log``            ``~/Library/Logs/moas-gui``            ``%LOCALAPPDATA%\\moas-gui\\Logs``
config         ``$XDG_CONFIG_HOME/moas-gui``                ``~/Library/Application Support/       ``%LOCALAPPDATA%\\moas-gui``
(operators,    (``~/.config/moas-gui``)                    moas-gui``
TLS)
data           ``$XDG_DATA_HOME/moas-gui``                 ``~/Library/Application Support/       ``%LOCALAPPDATA%\\moas-gui``
(antenna       (``~/.local/share/moas-gui``)               moas-gui``
journals)
settings       ``$XDG_CONFIG_HOME/moas-gui/*.conf``        ``~/Library/Preferences/               the registry, ``HKCU\\Software\\
(Qt's)                                                     com.moas-gui.*.plist``                 moas-gui``
=============  ==========================================  =====================================  ==================================

The state and log directories come from :mod:`platformdirs` (on Windows it asks the
system for the Local AppData folder).  ``$XDG_STATE_HOME``, when set to an absolute
path, is used on every system (platformdirs does so on macOS too; on Windows this
module does): the test suite gives each test its own that way; the window programs' settings (recent files, the
window's place) are Qt's ``QSettings``, which uses each system's own place.  Nothing is
made here: whoever writes makes the directory.  See ``docs/platforms.md``.

A window program started without a console (``pythonw``, the Windows ``gui-scripts``
launchers, a frozen app started from the Finder or Explorer) has no standard output or
error: :func:`output_without_console` sends both to a log file, so that what the
program says, and any traceback, can still be read.
"""

from __future__ import annotations

import contextlib
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Final, TextIO

if TYPE_CHECKING:  # platformdirs is loaded when a directory is first asked for
    from platformdirs import PlatformDirsABC

APP: Final = "moas-gui"
LOG_KEEP_BYTES: Final = 1_000_000
"""A log file that has grown past this is moved to ``NAME.log.1`` at the next start."""


def _dirs(platform: str) -> PlatformDirsABC:
    if platform == "win32" and not _xdg_state_home():
        from platformdirs.windows import Windows

        return Windows(APP, appauthor=False)
    if platform == "darwin":
        from platformdirs.macos import MacOS

        return MacOS(APP, appauthor=False)
    from platformdirs.unix import Unix

    return Unix(APP, appauthor=False)


def _xdg_state_home() -> bool:
    value = os.environ.get("XDG_STATE_HOME", "")
    return bool(value) and os.path.isabs(value)


def state_dir(platform: str = sys.platform) -> Path:
    """The per-user directory for the saved state of each configuration.
    ``$XDG_STATE_HOME``, when set to an absolute path, is used on every system (what
    platformdirs answers then, without loading it: every test's server asks at start)."""
    if _xdg_state_home():
        return Path(os.environ["XDG_STATE_HOME"]) / APP
    base = Path(_dirs(platform).user_state_dir)
    # Windows' state directory is the application's own folder: keep state apart in it
    return base / "state" if platform == "win32" else base


def config_dir(platform: str = sys.platform) -> Path:
    """The per-user directory for what the server is told once and keeps: its operators
    (:mod:`moas_gui.operators`) and its TLS certificate (:mod:`moas_gui.tls`).
    ``$XDG_CONFIG_HOME``, when set to an absolute path, is used on every system (tests)."""
    value = os.environ.get("XDG_CONFIG_HOME", "")
    if value and os.path.isabs(value):
        return Path(value) / APP
    return Path(_dirs(platform).user_config_dir)


def data_dir(platform: str = sys.platform) -> Path:
    """The per-user directory for what the server records over time: its antenna
    journals (:mod:`moas_gui.antenna_log`).  ``$XDG_DATA_HOME``, when set to an absolute
    path, is used on every system (the test suite gives each test its own)."""
    value = os.environ.get("XDG_DATA_HOME", "")
    if value and os.path.isabs(value):
        return Path(value) / APP
    return Path(_dirs(platform).user_data_dir)


def log_dir(platform: str = sys.platform) -> Path:
    """The per-user directory for the log files of programs without a console."""
    return Path(_dirs(platform).user_log_dir)


def log_file(program: str, platform: str = sys.platform) -> Path:
    return log_dir(platform) / f"{program}.log"


def output_without_console(program: str) -> Path | None:
    """When standard output or error is missing (no console), send them to
    ``log_dir()/PROGRAM.log`` (appended; an old large one is moved aside first).
    Returns that file's path, or None when the program has a console, or when the
    log cannot be written (then the output is dropped, as before)."""
    if sys.stdout is not None and sys.stderr is not None:
        return None
    path = log_file(program)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with contextlib.suppress(FileNotFoundError):
            if path.stat().st_size > LOG_KEEP_BYTES:
                path.replace(path.with_name(path.name + ".1"))
        stream: TextIO = open(path, "a", encoding="utf-8", buffering=1,  # noqa: SIM115
                              errors="backslashreplace")
    except OSError:
        return None
    if sys.stdout is None:
        sys.stdout = stream
    if sys.stderr is None:
        sys.stderr = stream
    return path


__all__ = ["APP", "config_dir", "data_dir", "log_dir", "log_file", "output_without_console", "state_dir"]
