"""The Windows file association, as far as it can be tried away from Windows: the values
are written to and erased from a registry that keeps them in a dict (the same calls as
``winreg``), and the command Explorer would run for a double-clicked file is split by
Windows' rules, read by ``moas-server``'s own parser and handed over to a running server
through the Windows transport (TCP on 127.0.0.1 with a token), real sockets."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path, PureWindowsPath
from typing import Any

import pytest
from helpers import until

from moas_gui import desktop
from moas_gui.cli.server import _parser
from moas_gui.desktop import PROG_ID, erase_registry, windows_registry_values, write_registry
from moas_gui.single_instance import claim, offer


class FakeRegistry:
    """``winreg``'s calls used by the association, over ``{key path: {name: value}}``."""

    HKEY_CURRENT_USER = 0x80000001
    KEY_SET_VALUE = 2
    KEY_ALL_ACCESS = 0xF003F
    REG_SZ = 1

    def __init__(self) -> None:
        self.keys: dict[str, dict[str, str]] = {}

    class Handle:
        def __init__(self, path: str) -> None:
            self.path = path

        def __enter__(self) -> FakeRegistry.Handle:
            return self

        def __exit__(self, *exc: object) -> None:
            pass

    def _norm(self, root: int, path: str) -> str:
        assert root == self.HKEY_CURRENT_USER, "only the current user's keys are touched"
        return path.casefold()

    def CreateKeyEx(self, root: int, path: str, reserved: int = 0,
                    access: int = 0) -> Handle:
        assert access == self.KEY_SET_VALUE
        parts = path.split("\\")
        for end in range(1, len(parts) + 1):  # as Windows does: the parents too
            self.keys.setdefault(self._norm(root, "\\".join(parts[:end])), {})
        return self.Handle(self._norm(root, path))

    def OpenKey(self, root: int, path: str, reserved: int = 0,
                access: int = 0) -> Handle:
        key = self._norm(root, path)
        if key not in self.keys:
            raise FileNotFoundError(2, "The system cannot find the file specified")
        return self.Handle(key)

    def SetValueEx(self, handle: Handle, name: str, reserved: int, kind: int,
                   value: str) -> None:
        assert kind == self.REG_SZ and isinstance(value, str)
        self.keys[handle.path][name] = value

    def QueryValueEx(self, handle: Handle, name: str) -> tuple[str, int]:
        try:
            return self.keys[handle.path][name], self.REG_SZ
        except KeyError:
            raise FileNotFoundError(2, "no such value") from None

    def EnumKey(self, handle: Handle, index: int) -> str:
        children = sorted(k[len(handle.path) + 1:] for k in self.keys
                          if k.startswith(handle.path + "\\") and
                          "\\" not in k[len(handle.path) + 1:])
        if index >= len(children):
            raise OSError(259, "No more data is available")
        return children[index]

    def DeleteKey(self, root: int, path: str) -> None:
        key = self._norm(root, path)
        assert not any(k.startswith(key + "\\") for k in self.keys), "a key with subkeys"
        del self.keys[key]

    def DeleteValue(self, handle: Handle, name: str) -> None:
        try:
            del self.keys[handle.path][name]
        except KeyError:
            raise FileNotFoundError(2, "no such value") from None

    def value(self, path: str, name: str = "") -> str:
        return self.keys[path.casefold()][name]


def split_windows_command_line(line: str) -> list[str]:
    """Split a command line as ``CommandLineToArgvW`` (and the C runtime) do: the program
    name ends at the closing quote; then 2n backslashes before a quote are n backslashes
    and a quote that toggles quoting, 2n+1 are n and a literal quote."""
    words: list[str] = []
    i = 0
    if line.startswith('"'):
        end = line.index('"', 1)
        words.append(line[1:end])
        i = end + 1
    else:
        end = len(line) if " " not in line else line.index(" ")
        words.append(line[:end])
        i = end
    while i < len(line):
        while i < len(line) and line[i] in " \t":
            i += 1
        if i >= len(line):
            break
        word, quoted = [], False
        while i < len(line) and (quoted or line[i] not in " \t"):
            slashes = 0
            while i < len(line) and line[i] == "\\":
                slashes += 1
                i += 1
            if i < len(line) and line[i] == '"':
                word.append("\\" * (slashes // 2))
                if slashes % 2:
                    word.append('"')
                else:
                    quoted = not quoted
                i += 1
            else:
                word.append("\\" * slashes)
                if i < len(line) and (quoted or line[i] not in " \t"):
                    word.append(line[i])
                    i += 1
        words.append("".join(word))
    return words


def test_the_splitter_follows_windows_rules() -> None:
    assert split_windows_command_line(r'"C:\Program Files\x.exe" -m a "b c" d\\"e f"') == \
        [r"C:\Program Files\x.exe", "-m", "a", "b c", "d\\e f"]
    assert split_windows_command_line(r'x.exe a\\\"b') == ["x.exe", 'a\\"b']


GUI = r"C:\Users\Op Name\pipx\venvs\moas-gui\Scripts\moas-server-gui.exe"
PYTHONW = r"C:\Program Files\Python311\pythonw.exe"
ICONS = PureWindowsPath(r"C:\Users\Op Name\pipx\venvs\moas-gui\Lib\site-packages\moas_gui"
                        r"\resources\icons")


def test_the_association_is_written_and_erased_again() -> None:
    registry = FakeRegistry()
    registry.keys["software\\classes\\.txt"] = {"": "txtfile"}  # someone else's: kept
    done = write_registry(windows_registry_values([GUI], ICONS), registry)
    assert len(done) == len(windows_registry_values([GUI], ICONS))
    assert registry.value("Software\\Classes\\.moas") == PROG_ID
    command = registry.value(f"Software\\Classes\\{PROG_ID}\\shell\\open\\command")
    assert command == f'"{GUI}" "%1"'
    said = erase_registry(registry)
    assert said[0] == f"removed HKEY_CURRENT_USER\\Software\\Classes\\{PROG_ID}"
    assert "removed the .moas file association" in said
    assert not any(PROG_ID.casefold() in k for k in registry.keys)
    assert "" not in registry.keys["software\\classes\\.moas"]
    assert registry.keys["software\\classes\\.txt"] == {"": "txtfile"}
    assert erase_registry(registry) == [
        "nothing to remove: the file association was not installed"]


@pytest.mark.skipif(sys.platform == "win32", reason="would write this user's real registry")
def test_installing_on_another_system_says_the_registry_is_windows_only() -> None:
    with pytest.raises(OSError, match="only on Windows"):
        desktop.install_desktop(system="Windows", command=[GUI])


@pytest.mark.parametrize("command, skip", [([GUI], 0),
                                           ([PYTHONW, "-m", "moas_gui.cli.server"], 2)],
                         ids=["gui-script", "pythonw"])
@pytest.mark.asyncio
async def test_a_double_click_reaches_the_running_server(command: list[str], skip: int,
                                                         tmp_path: Path) -> None:
    """Explorer puts the file's path for %1 and runs the command; that launch finds a
    server running and hands the file over (Windows' transport: TCP and a token)."""
    folder = tmp_path / "Contest Files" / "CQ WW 2026 (M/S)".replace("/", "-")
    folder.mkdir(parents=True)
    clicked = folder / "station 1.moas"
    clicked.write_text("{}")
    registry = FakeRegistry()
    write_registry(windows_registry_values(command, ICONS), registry)
    line = registry.value(f"Software\\Classes\\{PROG_ID}\\shell\\open\\command")
    argv = split_windows_command_line(line.replace("%1", str(clicked)))
    assert argv[0] == command[0]
    args = _parser().parse_args(argv[1 + skip:])  # what moas-server reads
    assert args.file == str(clicked) and not args.headless

    directory = tmp_path / "instance"
    server = claim("test-server", directory=directory, transport="tcp")
    assert server is not None
    received: list[Any] = []
    try:
        await server.start(received.append)
        answer = await asyncio.to_thread(offer, "test-server", args.file, {"headless": False},
                                         directory=directory, transport="tcp")
        assert answer.taken
        await until(lambda: received)
        assert [Path(p) for p in received] == [clicked]
    finally:
        server.close()
