"""Every listener of the program admits through the edge's one door
(``moas_gui/edge/gate.py``): no module opens a stream server that would hand its
connections to a callback of its own.

asyncio's ``start_server`` and ``start_unix_server`` take a callback and admit
everyone; they are left to the stand-ins of ``moas_gui/testing`` (test peers, never
part of the server).  ``create_server`` and ``create_unix_server`` take a protocol
factory: outside the edge they are given a door (a module that calls them imports the
gate).  TCP listeners of the program otherwise go through ``edge/listener.py``."""

from __future__ import annotations

import ast
from pathlib import Path

from import_reader import nodes

PACKAGE = Path(__file__).resolve().parents[2] / "moas_gui"

CALLBACK_SERVERS = {"start_server", "start_unix_server"}
FACTORY_SERVERS = {"create_server", "create_unix_server"}


def door_breaches(root: Path) -> list[str]:
    """``file: call`` for every stream server opened around the door under ``root``."""
    found: list[str] = []
    for path in sorted(root.rglob("*.py")):
        where = path.relative_to(root).as_posix()
        if where.startswith(("testing/", "edge/")):
            continue
        walked = nodes(path)
        imports_gate = any(isinstance(node, ast.ImportFrom) and node.module is not None
                           and node.module.endswith("edge.gate") for node in walked)
        for node in walked:
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
                continue
            name = node.func.attr
            if name in CALLBACK_SERVERS or (name in FACTORY_SERVERS and not imports_gate):
                found.append(f"{where}: {name}")
    return found


def test_every_stream_server_of_the_program_opens_through_the_door() -> None:
    assert door_breaches(PACKAGE) == []


def test_the_rule_finds_a_server_opened_around_the_door(tmp_path: Path) -> None:
    """A deliberately broken copy: a callback server, and a factory one with no gate."""
    (tmp_path / "net").mkdir()
    (tmp_path / "net" / "side.py").write_text(
        "import asyncio\nasync def f(cb):\n    await asyncio.start_server(cb, 'h', 1)\n")
    (tmp_path / "other.py").write_text(
        "async def g(loop, p):\n    await loop.create_unix_server(p, path='x')\n")
    (tmp_path / "fine.py").write_text(
        "from moas_gui.edge.gate import gate_factory\n"
        "async def h(loop, d):\n    await loop.create_unix_server(d, path='x')\n")
    (tmp_path / "testing").mkdir()
    (tmp_path / "testing" / "peer.py").write_text(
        "import asyncio\nasync def f(cb):\n    await asyncio.start_server(cb, 'h', 1)\n")
    assert door_breaches(tmp_path) == ["net/side.py: start_server",
                                       "other.py: create_unix_server"]
