"""``moas-server --install-desktop``: make a double-click on a ``.moas`` file start the server.

What :func:`install_desktop` does, per system, for the current user only (no
administrator rights):

Linux and other freedesktop systems (under ``$XDG_DATA_HOME``, by default
``~/.local/share``)
    ``applications/moas-server.desktop`` (a menu entry whose ``Exec`` is the
    absolute path of the installed ``moas-server`` followed by ``%f``),
    ``mime/packages/moas-gui.xml`` (the type ``application/x-moas`` for
    ``*.moas``), the icons under ``icons/hicolor/<size>/apps`` and
    ``.../mimetypes``; then ``update-mime-database``,
    ``update-desktop-database`` and ``xdg-mime default`` when they are installed
    (when one is not, the report says so; the desktop picks the files up at the
    next log-in).
Windows
    ``HKCU\\Software\\Classes``: ``.moas`` names the ProgID
    ``MOASGui.Configuration``, which has a ``DefaultIcon`` and
    ``shell\\open\\command`` = ``"...\\pythonw.exe" -m moas_gui.cli.server "%1"``
    (or ``moas-server.exe "%1"`` when there is no ``pythonw.exe``).
macOS
    nothing is written: double-clicking needs an application bundle; the report
    says how to make one with Automator.

Each function returns the list of sentences saying what was done, for the
command line to print.  :func:`uninstall_desktop` undoes it.  The pieces that
decide contents (:func:`desktop_entry`, :func:`mime_package`,
:func:`windows_registry_values`, ...) are pure, so they are tested everywhere.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path, PureWindowsPath
from typing import Any, Final, Protocol

from .files import write_atomic, write_text_atomic

MIME_TYPE: Final = "application/x-moas"
DESKTOP_FILE: Final = "moas-server.desktop"
MIME_PACKAGE: Final = "moas-gui.xml"
APP_ICON_NAME: Final = "moas-server"
FILE_ICON_NAME: Final = "application-x-moas"
PROG_ID: Final = "MOASGui.Configuration"
ICON_SIZES: Final = (16, 22, 24, 32, 48, 64, 128, 256)
ICON_DIR: Final = Path(__file__).resolve().parent / "resources" / "icons"
_ICON_SOURCES: Final = {("apps", APP_ICON_NAME): "moas-normal",
                        ("mimetypes", FILE_ICON_NAME): "application-x-moas"}

Runner = Callable[[Sequence[str]], subprocess.CompletedProcess[str]]
"""Runs a command (the tests pass a fake); the default is :func:`run_tool`."""


def run_tool(command: Sequence[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(list(command), capture_output=True, text=True, timeout=60, check=False)


# -- Linux and other freedesktop systems ------------------------------------------------


def data_home(environ: Mapping[str, str] = os.environ) -> Path:
    """``$XDG_DATA_HOME`` when it is an absolute path, else ``~/.local/share``."""
    value = environ.get("XDG_DATA_HOME", "")
    return Path(value) if value and os.path.isabs(value) else Path.home() / ".local" / "share"


def config_home(environ: Mapping[str, str] = os.environ) -> Path:
    value = environ.get("XDG_CONFIG_HOME", "")
    return Path(value) if value and os.path.isabs(value) else Path.home() / ".config"


def server_command() -> list[str]:
    """How to start this installation's server: its ``moas-server`` script, absolute."""
    beside = Path(sys.executable).parent / "moas-server"
    if beside.is_file():
        return [str(beside.absolute())]
    found = shutil.which("moas-server")
    if found:
        return [str(Path(found).absolute())]
    return [str(Path(sys.executable).absolute()), "-m", "moas_gui.cli.server"]


_EXEC_RESERVED: Final = set(" \t\n\"'\\><~|&;$*?#()`")


def exec_quote(argument: str) -> str:
    """One argument of a desktop entry's ``Exec`` key, quoted and escaped as the spec asks."""
    argument = argument.replace("%", "%%")
    if argument and not (_EXEC_RESERVED & set(argument)):
        return argument
    inner = "".join("\\" + c if c in '"`$\\' else c for c in argument)
    # the key's value is itself a string in which a backslash is written twice
    return '"' + inner.replace("\\", "\\\\") + '"'


def desktop_entry(command: Sequence[str]) -> str:
    """The text of ``moas-server.desktop``."""
    exec_line = " ".join(exec_quote(part) for part in command) + " %f"
    return "\n".join([
        "[Desktop Entry]",
        "Type=Application",
        "Version=1.4",
        "Name=MOAS Server",
        "GenericName=Antenna Switch Server",
        "Comment=Drive YCCC MOAS II antenna switches from a .moas configuration",
        f"Exec={exec_line}",
        f"Icon={APP_ICON_NAME}",
        "Terminal=false",
        "StartupNotify=true",
        "Categories=Network;HamRadio;",
        "Keywords=antenna;switch;contest;MOAS;SO2R;amateur radio;",
        f"MimeType={MIME_TYPE};",
        "",
    ])


def mime_package() -> str:
    """The text of the shared-mime-info package that names ``*.moas`` files.

    The glob weighs more than the default 50 of the ``*.json`` glob and of the
    JSON content sniffing, so desktops that only read shared-mime-info answer
    ``application/x-moas`` rather than ``application/json``."""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<mime-info xmlns="http://www.freedesktop.org/standards/shared-mime-info">
  <mime-type type="{MIME_TYPE}">
    <comment>MOAS II configuration</comment>
    <sub-class-of type="application/json"/>
    <icon name="{FILE_ICON_NAME}"/>
    <glob pattern="*.moas" weight="80"/>
  </mime-type>
</mime-info>
"""


def linux_files(command: Sequence[str], data: Path) -> dict[Path, bytes]:
    """Every file the Linux installation writes, with its content."""
    files: dict[Path, bytes] = {
        data / "applications" / DESKTOP_FILE: desktop_entry(command).encode(),
        data / "mime" / "packages" / MIME_PACKAGE: mime_package().encode(),
    }
    hicolor = data / "icons" / "hicolor"
    for (context, name), source in _ICON_SOURCES.items():
        files[hicolor / "scalable" / context / f"{name}.svg"] = (
            ICON_DIR / f"{source}.svg").read_bytes()
        for size in ICON_SIZES:
            files[hicolor / f"{size}x{size}" / context / f"{name}.png"] = (
                ICON_DIR / f"{source}-{size}.png").read_bytes()
    return files


def _run_if_present(tool: str, arguments: Sequence[str], run: Runner,
                    which: Callable[[str], str | None], absent: str) -> str:
    path = which(tool)
    if path is None:
        return f"{tool} is not installed: {absent}"
    try:
        done = run([path, *arguments])
    except (OSError, subprocess.SubprocessError) as exc:
        return f"{tool} could not run: {exc}"
    if done.returncode != 0:
        detail = (done.stderr or done.stdout).strip().splitlines()
        return f"{tool} failed (exit {done.returncode}): {detail[-1] if detail else 'no message'}"
    return f"ran {tool} {' '.join(arguments)}"


def install_linux(command: Sequence[str], data: Path, run: Runner = run_tool,
                  which: Callable[[str], str | None] = shutil.which) -> list[str]:
    done: list[str] = []
    for path, content in linux_files(command, data).items():
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, content)
    done.append(f"wrote the menu entry {data / 'applications' / DESKTOP_FILE} "
                f"(starts {' '.join(command)})")
    done.append(f"wrote the file type {MIME_TYPE} for *.moas in "
                f"{data / 'mime' / 'packages' / MIME_PACKAGE}")
    done.append(f"copied the icons into {data / 'icons' / 'hicolor'}")
    done.extend(_refresh_linux(data, run, which))
    done.append(_run_if_present("xdg-mime", ["default", DESKTOP_FILE, MIME_TYPE], run, which,
                                "choose MOAS Server once with 'Open With' for a .moas file"))
    return done


def _refresh_linux(data: Path, run: Runner, which: Callable[[str], str | None]) -> list[str]:
    results = [
        _run_if_present("update-mime-database", [str(data / "mime")], run, which,
                        "the .moas file type is known after the next log-in"),
        _run_if_present("update-desktop-database", [str(data / "applications")], run, which,
                        "the menu entry is used after the next log-in"),
    ]
    hicolor = data / "icons" / "hicolor"
    if (hicolor / "icon-theme.cache").exists():
        results.append(_run_if_present("gtk-update-icon-cache", ["-f", "-t", str(hicolor)], run,
                                       which, "the icons appear after the next log-in"))
    return results


def uninstall_linux(data: Path, config: Path, run: Runner = run_tool,
                    which: Callable[[str], str | None] = shutil.which) -> list[str]:
    done: list[str] = []
    icons = 0
    for path in linux_files([], data):
        if path.exists():
            path.unlink()
            if path.suffix in (".png", ".svg"):
                icons += 1
            else:
                done.append(f"removed {path}")
    if icons:
        done.append(f"removed {icons} icons from {data / 'icons' / 'hicolor'}")
    mimeapps = config / "mimeapps.list"
    if mimeapps.exists() and _forget_default(mimeapps):
        done.append(f"removed the .moas association from {mimeapps}")
    if not done:
        return ["nothing to remove: the desktop integration was not installed"]
    return done + _refresh_linux(data, run, which)


def _forget_default(mimeapps: Path) -> bool:
    """Drop ``moas-server.desktop`` from the ``application/x-moas`` lines; True if changed."""
    lines = mimeapps.read_text(encoding="utf-8", errors="replace").splitlines(keepends=True)
    kept: list[str] = []
    for line in lines:
        key, sep, value = line.partition("=")
        if sep and key.strip() == MIME_TYPE:
            apps = [a for a in value.strip().split(";") if a and a != DESKTOP_FILE]
            if apps:
                kept.append(f"{MIME_TYPE}={';'.join(apps)};\n")
            continue
        kept.append(line)
    if kept == lines:
        return False
    write_text_atomic(mimeapps, "".join(kept))  # the user's other choices never lost
    return True


# -- Windows -------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class RegistryValue:
    """A string value under ``HKEY_CURRENT_USER``; ``name`` ``""`` is the key's default value."""

    key: str
    name: str
    value: str


def windows_command(executable: PureWindowsPath, exists: Callable[[PureWindowsPath], bool],
                    frozen: bool = False) -> list[str]:
    """The server's command for Explorer, one that opens no console window: the frozen
    app's ``moas-server-gui.exe``, else the ``moas-server-gui.exe`` a pip or pipx install
    puts beside Python, else ``pythonw.exe -m moas_gui.cli.server``; the console
    ``moas-server.exe`` only when there is none of those."""
    folder = executable.parent
    if frozen:
        return [str(folder / "moas-server-gui.exe")]
    for candidate in (folder / "moas-server-gui.exe", folder / "Scripts" / "moas-server-gui.exe"):
        if exists(candidate):
            return [str(candidate)]
    if exists(folder / "pythonw.exe"):
        return [str(folder / "pythonw.exe"), "-m", "moas_gui.cli.server"]
    for candidate in (folder / "moas-server.exe", folder / "Scripts" / "moas-server.exe"):
        if exists(candidate):
            return [str(candidate)]
    return [str(executable), "-m", "moas_gui.cli.server"]


def _windows_quote(argument: str, always: bool = False) -> str:
    return f'"{argument}"' if always or " " in argument or not argument else argument


def windows_registry_values(command: Sequence[str], icon_dir: PureWindowsPath
                            ) -> list[RegistryValue]:
    """Every value :func:`install_desktop` writes on Windows, in the order it writes them."""
    classes = "Software\\Classes"
    prog = f"{classes}\\{PROG_ID}"
    open_command = " ".join(
        [_windows_quote(command[0], always=True), *(_windows_quote(a) for a in command[1:]),
         '"%1"'])
    return [
        RegistryValue(f"{classes}\\.moas", "", PROG_ID),
        RegistryValue(f"{classes}\\.moas", "Content Type", MIME_TYPE),
        RegistryValue(f"{classes}\\.moas\\OpenWithProgids", PROG_ID, ""),
        RegistryValue(prog, "", "MOAS II configuration"),
        RegistryValue(f"{prog}\\DefaultIcon", "", f'"{icon_dir / "application-x-moas.ico"}",0'),
        RegistryValue(f"{prog}\\shell", "", "open"),
        RegistryValue(f"{prog}\\shell\\open", "", "Open with MOAS Server"),
        RegistryValue(f"{prog}\\shell\\open", "Icon", f'"{icon_dir / "moas-server.ico"}",0'),
        RegistryValue(f"{prog}\\shell\\open\\command", "", open_command),
    ]


class Registry(Protocol):
    """What of ``winreg`` the association uses (the tests pass a fake with a dict inside)."""

    HKEY_CURRENT_USER: int
    KEY_SET_VALUE: int
    KEY_ALL_ACCESS: int
    REG_SZ: int

    def CreateKeyEx(self, key: int, sub_key: str, reserved: int = ...,
                    access: int = ...) -> Any: ...

    def OpenKey(self, key: int, sub_key: str, reserved: int = ...,
                access: int = ...) -> Any: ...

    def SetValueEx(self, key: Any, name: str, reserved: int, type: int,
                   value: str) -> None: ...

    def QueryValueEx(self, key: Any, name: str) -> tuple[Any, int]: ...

    def EnumKey(self, key: Any, index: int) -> str: ...

    def DeleteKey(self, key: int, sub_key: str) -> None: ...

    def DeleteValue(self, key: Any, name: str) -> None: ...


def write_registry(values: Sequence[RegistryValue], registry: Registry) -> list[str]:
    """Write ``values`` under ``HKEY_CURRENT_USER``; returns what was written."""
    for item in values:
        with registry.CreateKeyEx(registry.HKEY_CURRENT_USER, item.key, 0,
                                  registry.KEY_SET_VALUE) as key:
            registry.SetValueEx(key, item.name, 0, registry.REG_SZ, item.value)
    return [f"wrote HKEY_CURRENT_USER\\{v.key} {v.name or '(default)'} = {v.value}"
            for v in values]


def erase_registry(registry: Registry) -> list[str]:
    """Remove what :func:`write_registry` wrote for moas-gui (and nothing of others')."""
    def delete_tree(path: str) -> bool:
        try:
            with registry.OpenKey(registry.HKEY_CURRENT_USER, path, 0,
                                  registry.KEY_ALL_ACCESS) as key:
                while True:
                    try:
                        child = registry.EnumKey(key, 0)
                    except OSError:
                        break
                    delete_tree(f"{path}\\{child}")
            registry.DeleteKey(registry.HKEY_CURRENT_USER, path)
            return True
        except FileNotFoundError:
            return False

    done = []
    if delete_tree(f"Software\\Classes\\{PROG_ID}"):
        done.append(f"removed HKEY_CURRENT_USER\\Software\\Classes\\{PROG_ID}")
    try:
        with registry.OpenKey(registry.HKEY_CURRENT_USER, "Software\\Classes\\.moas", 0,
                              registry.KEY_ALL_ACCESS) as key:
            if registry.QueryValueEx(key, "")[0] == PROG_ID:
                registry.DeleteValue(key, "")
                done.append("removed the .moas file association")
        with registry.OpenKey(registry.HKEY_CURRENT_USER,
                              "Software\\Classes\\.moas\\OpenWithProgids", 0,
                              registry.KEY_SET_VALUE) as key:
            registry.DeleteValue(key, PROG_ID)
    except FileNotFoundError:
        pass
    return done or ["nothing to remove: the file association was not installed"]


def _install_windows(values: Sequence[RegistryValue]) -> list[str]:  # pragma: no cover
    if sys.platform != "win32":
        raise OSError("the Windows registry exists only on Windows")
    import ctypes
    import winreg

    done = write_registry(values, winreg)  # type: ignore[arg-type, unused-ignore]
    ctypes.windll.shell32.SHChangeNotify(0x08000000, 0, None, None)  # SHCNE_ASSOCCHANGED
    return done


def _uninstall_windows() -> list[str]:  # pragma: no cover
    if sys.platform != "win32":
        raise OSError("the Windows registry exists only on Windows")
    import ctypes
    import winreg

    done = erase_registry(winreg)  # type: ignore[arg-type, unused-ignore]
    ctypes.windll.shell32.SHChangeNotify(0x08000000, 0, None, None)
    return done


# -- macOS ---------------------------------------------------------------------------------


def macos_instructions(command: Sequence[str]) -> list[str]:
    shell = " ".join(_posix_quote(part) for part in command)
    return [
        ("macOS: double-clicking a file needs an application bundle, which this command does "
        "not make. To make one:"),
        "  1. open Automator, choose New Document > Application;",
        "  2. add 'Run Shell Script', set 'Pass input' to 'as arguments', and write:",
        f"       {shell} \"$@\" >/dev/null 2>&1 &",
        "  3. save it as 'MOAS Server' in Applications;",
        ("  4. in Finder, select a .moas file, File > Get Info, 'Open with': MOAS Server, "
        "then 'Change All...'."),
    ]


def _posix_quote(text: str) -> str:
    return text if text and all(c.isalnum() or c in "/._-+:=@" for c in text) \
        else "'" + text.replace("'", "'\\''") + "'"


# -- the two calls -------------------------------------------------------------------------


def install_desktop(*, system: str | None = None, command: Sequence[str] | None = None,
                    run: Runner = run_tool,
                    which: Callable[[str], str | None] = shutil.which) -> list[str]:
    """Register ``.moas`` files and a menu entry for this user; return what was done."""
    system = system or platform.system()
    if system == "Windows":
        win_command = list(command) if command else windows_command(
            PureWindowsPath(sys.executable), lambda p: Path(p).exists(),
            frozen=bool(getattr(sys, "frozen", False)))
        return _install_windows(windows_registry_values(win_command,
                                                        PureWindowsPath(ICON_DIR)))
    command = list(command) if command else server_command()
    if system == "Darwin":
        return macos_instructions(command)
    return install_linux(command, data_home(), run, which)


def uninstall_desktop(*, system: str | None = None, run: Runner = run_tool,
                      which: Callable[[str], str | None] = shutil.which) -> list[str]:
    """Undo :func:`install_desktop`; return what was done."""
    system = system or platform.system()
    if system == "Windows":
        return _uninstall_windows()
    if system == "Darwin":
        return ["macOS: move the 'MOAS Server' application you made with Automator to the Trash."]
    return uninstall_linux(data_home(), config_home(), run, which)


__all__ = [
    "DESKTOP_FILE",
    "MIME_PACKAGE",
    "MIME_TYPE",
    "PROG_ID",
    "Registry",
    "RegistryValue",
    "desktop_entry",
    "erase_registry",
    "exec_quote",
    "install_desktop",
    "linux_files",
    "macos_instructions",
    "mime_package",
    "server_command",
    "uninstall_desktop",
    "windows_command",
    "windows_registry_values",
    "write_registry",
]
