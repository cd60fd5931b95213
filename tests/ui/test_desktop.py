"""Desktop integration: the files written on Linux, the registry values for Windows, macOS advice."""

from __future__ import annotations

import shlex
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path, PureWindowsPath

import pytest

from moas_gui import desktop
from moas_gui.desktop import (
    RegistryValue,
    data_home,
    desktop_entry,
    exec_quote,
    install_desktop,
    server_command,
    uninstall_desktop,
    windows_command,
    windows_registry_values,
)

ICONS = Path(desktop.__file__).parent / "resources" / "icons"


class FakeTools:
    """Stands in for the freedesktop tools: records every command, answers as told."""

    def __init__(self, installed: Sequence[str] = (), fail: dict[str, str] | None = None) -> None:
        self.installed = set(installed)
        self.fail = fail or {}
        self.commands: list[list[str]] = []

    def which(self, tool: str) -> str | None:
        return f"/usr/bin/{tool}" if tool in self.installed else None

    def run(self, command: Sequence[str]) -> subprocess.CompletedProcess[str]:
        self.commands.append(list(command))
        tool = Path(command[0]).name
        if tool in self.fail:
            return subprocess.CompletedProcess(list(command), 2, "", f"warning\n{self.fail[tool]}\n")
        return subprocess.CompletedProcess(list(command), 0, "", "")


@pytest.fixture
def xdg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    data = tmp_path / "data"
    monkeypatch.setenv("XDG_DATA_HOME", str(data))
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    return data


def entry_keys(text: str) -> dict[str, str]:
    lines = text.splitlines()
    assert lines[0] == "[Desktop Entry]"
    return dict(line.split("=", 1) for line in lines[1:] if line)


def test_linux_install_writes_menu_entry_file_type_and_icons(xdg: Path) -> None:
    tools = FakeTools()
    report = install_desktop(system="Linux", command=["/opt/moas gui/bin/moas-server"],
                             run=tools.run, which=tools.which)
    keys = entry_keys((xdg / "applications" / "moas-server.desktop").read_text())
    assert keys["Exec"] == '"/opt/moas gui/bin/moas-server" %f'
    assert keys["Type"] == "Application" and keys["Icon"] == "moas-server"
    assert keys["MimeType"] == "application/x-moas;" and keys["Terminal"] == "false"

    mime = ET.parse(xdg / "mime" / "packages" / "moas-gui.xml").getroot()
    ns = "{http://www.freedesktop.org/standards/shared-mime-info}"
    kind = mime.find(f"{ns}mime-type")
    assert kind is not None and kind.get("type") == "application/x-moas"
    glob = kind.find(f"{ns}glob")
    assert glob is not None and glob.get("pattern") == "*.moas"
    assert int(glob.get("weight", "50")) > 50, "must outweigh the *.json glob (weight 50)"

    hicolor = xdg / "icons" / "hicolor"
    for size in (16, 22, 24, 32, 48, 64, 128, 256):
        assert (hicolor / f"{size}x{size}" / "apps" / "moas-server.png").read_bytes() == \
            (ICONS / f"moas-normal-{size}.png").read_bytes()
        assert (hicolor / f"{size}x{size}" / "mimetypes" / "application-x-moas.png").read_bytes() \
            == (ICONS / f"application-x-moas-{size}.png").read_bytes()
    assert (hicolor / "scalable" / "apps" / "moas-server.svg").exists()
    assert (hicolor / "scalable" / "mimetypes" / "application-x-moas.svg").exists()

    assert tools.commands == []
    assert any("update-mime-database is not installed" in line for line in report)
    assert any("xdg-mime is not installed" in line for line in report)
    assert any(str(xdg / "applications" / "moas-server.desktop") in line for line in report)


def test_linux_install_runs_the_freedesktop_tools_that_are_present(xdg: Path) -> None:
    tools = FakeTools(installed=["update-mime-database", "update-desktop-database", "xdg-mime"])
    report = install_desktop(system="Linux", command=["/usr/bin/moas-server"],
                             run=tools.run, which=tools.which)
    assert tools.commands == [
        ["/usr/bin/update-mime-database", str(xdg / "mime")],
        ["/usr/bin/update-desktop-database", str(xdg / "applications")],
        ["/usr/bin/xdg-mime", "default", "moas-server.desktop", "application/x-moas"],
    ]
    assert "ran xdg-mime default moas-server.desktop application/x-moas" in report


def test_a_failing_tool_is_reported_and_the_files_stay(xdg: Path) -> None:
    tools = FakeTools(installed=["update-mime-database"],
                      fail={"update-mime-database": "cannot write cache"})
    report = install_desktop(system="Linux", command=["/usr/bin/moas-server"],
                             run=tools.run, which=tools.which)
    assert "update-mime-database failed (exit 2): cannot write cache" in report
    assert (xdg / "applications" / "moas-server.desktop").exists()


def test_the_real_mime_database_learns_the_moas_type(xdg: Path) -> None:
    real = desktop.shutil.which("update-mime-database")
    report = install_desktop(system="Linux", command=["/usr/bin/moas-server"],
                             which=lambda tool: real if tool == "update-mime-database" else None)
    if real is None:
        assert any("update-mime-database is not installed" in line for line in report)
        return
    assert f"ran update-mime-database {xdg / 'mime'}" in report, report
    globs = (xdg / "mime" / "globs2").read_text()
    assert "application/x-moas:*.moas" in globs


def test_uninstall_removes_the_files_and_only_our_association(xdg: Path, tmp_path: Path) -> None:
    tools = FakeTools()
    install_desktop(system="Linux", command=["/usr/bin/moas-server"], run=tools.run,
                    which=tools.which)
    mimeapps = tmp_path / "config" / "mimeapps.list"
    mimeapps.parent.mkdir(parents=True)
    mimeapps.write_text("[Default Applications]\napplication/x-moas=moas-server.desktop;\n"
                        "text/plain=gedit.desktop;\n[Added Associations]\n"
                        "application/x-moas=code.desktop;moas-server.desktop;\n")
    report = uninstall_desktop(system="Linux", run=tools.run, which=tools.which)
    assert not (xdg / "applications" / "moas-server.desktop").exists()
    assert not (xdg / "mime" / "packages" / "moas-gui.xml").exists()
    assert not list((xdg / "icons").rglob("*.png"))
    assert mimeapps.read_text() == ("[Default Applications]\ntext/plain=gedit.desktop;\n"
                                    "[Added Associations]\napplication/x-moas=code.desktop;\n")
    assert any("removed the .moas association" in line for line in report)
    again = uninstall_desktop(system="Linux", run=tools.run, which=tools.which)
    assert "nothing to remove" in again[-1]


def test_macos_gets_instructions_and_nothing_is_written(xdg: Path) -> None:
    report = install_desktop(system="Darwin", command=["/Users/op/venv/bin/moas-server"])
    assert any("Automator" in line for line in report)
    assert any("/Users/op/venv/bin/moas-server \"$@\"" in line for line in report)
    assert not xdg.exists()


def test_without_a_command_the_installed_server_is_named_by_its_absolute_path(xdg: Path) -> None:
    install_desktop(system="Linux", run=FakeTools().run, which=FakeTools().which)
    exec_line = entry_keys((xdg / "applications" / "moas-server.desktop").read_text())["Exec"]
    words = shlex.split(exec_line)
    assert words[-1] == "%f"
    assert Path(words[0]).is_absolute() and Path(words[0]).exists()
    assert words[:-1] == server_command()


def test_xdg_data_home_is_honoured_only_when_absolute() -> None:
    assert data_home({"XDG_DATA_HOME": "/srv/data"}) == Path("/srv/data")
    assert data_home({"XDG_DATA_HOME": "relative/data"}) == Path.home() / ".local" / "share"
    assert data_home({}) == Path.home() / ".local" / "share"


@pytest.mark.parametrize("argument, quoted", [
    ("/usr/bin/moas-server", "/usr/bin/moas-server"),
    ("/home/op/my venv/bin/moas-server", '"/home/op/my venv/bin/moas-server"'),
    ("/opt/$HOME/x", '"/opt/\\\\$HOME/x"'),
    ('/opt/a"b', '"/opt/a\\\\"b"'),
    ("/opt/back\\slash", '"/opt/back\\\\\\\\slash"'),
    ("/opt/100%", "/opt/100%%"),
])
def test_exec_arguments_are_quoted_as_the_desktop_entry_spec_asks(argument: str, quoted: str) -> None:
    assert exec_quote(argument) == quoted


def test_the_menu_entry_starts_python_when_there_is_no_script() -> None:
    keys = entry_keys(desktop_entry(["/usr/bin/python3", "-m", "moas_gui.cli.server"]))
    assert keys["Exec"] == "/usr/bin/python3 -m moas_gui.cli.server %f"


def test_windows_prefers_a_command_that_opens_no_console_window() -> None:
    python = PureWindowsPath(r"C:\Users\Op\moas\Scripts\python.exe")
    every = windows_command(python, lambda path: True)
    assert every == [r"C:\Users\Op\moas\Scripts\moas-server-gui.exe"]  # the gui-script
    pythonw = windows_command(python, lambda path: path.name == "pythonw.exe")
    assert pythonw == [r"C:\Users\Op\moas\Scripts\pythonw.exe", "-m", "moas_gui.cli.server"]
    script = windows_command(python, lambda path: path.name == "moas-server.exe")
    assert script == [r"C:\Users\Op\moas\Scripts\moas-server.exe"]
    bare = windows_command(python, lambda path: False)
    assert bare == [str(python), "-m", "moas_gui.cli.server"]
    frozen = windows_command(PureWindowsPath(r"C:\Program Files\moas-gui\moas-server.exe"),
                             lambda path: False, frozen=True)
    assert frozen == [r"C:\Program Files\moas-gui\moas-server-gui.exe"]


def test_windows_registry_values_associate_moas_files_with_the_server() -> None:
    values = windows_registry_values(
        [r"C:\Program Files\Python311\pythonw.exe", "-m", "moas_gui.cli.server"],
        PureWindowsPath(r"C:\Program Files\Python311\Lib\site-packages\moas_gui\resources\icons"))
    table = {(v.key, v.name): v.value for v in values}
    classes = "Software\\Classes"
    assert table[(f"{classes}\\.moas", "")] == "MOASGui.Configuration"
    assert table[(f"{classes}\\.moas\\OpenWithProgids", "MOASGui.Configuration")] == ""
    assert table[(f"{classes}\\MOASGui.Configuration\\shell\\open\\command", "")] == (
        r'"C:\Program Files\Python311\pythonw.exe" -m moas_gui.cli.server "%1"')
    assert table[(f"{classes}\\MOASGui.Configuration\\DefaultIcon", "")] == (
        r'"C:\Program Files\Python311\Lib\site-packages\moas_gui\resources\icons'
        r'\application-x-moas.ico",0')
    assert all(isinstance(v, RegistryValue) and v.key.startswith(classes) for v in values)
    assert len(table) == len(values), "no value is written twice"


def test_windows_script_command_is_quoted_with_its_file_argument() -> None:
    values = windows_registry_values([r"C:\moas\moas-server.exe"], PureWindowsPath(r"C:\moas"))
    command = [v.value for v in values if v.key.endswith("command")]
    assert command == [r'"C:\moas\moas-server.exe" "%1"']


def test_the_public_names_do_not_drift() -> None:
    assert sorted(desktop.__all__) == sorted([
        "DESKTOP_FILE", "MIME_PACKAGE", "MIME_TYPE", "PROG_ID", "Registry", "RegistryValue",
        "desktop_entry", "erase_registry", "write_registry", "exec_quote", "install_desktop", "linux_files", "macos_instructions", "mime_package",
        "server_command", "uninstall_desktop", "windows_command", "windows_registry_values"])
    assert sys.modules["moas_gui.desktop"] is desktop
