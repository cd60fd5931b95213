"""The allowed direction of imports between the packages of moas_gui (docs/architecture.md).

Every ``import`` and ``from ... import`` of every module is read with :mod:`ast`
(those inside functions too), so a cycle cannot hide behind a late import.
"""

from __future__ import annotations

import functools
import json
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest
from import_reader import imported_names, module_name

PACKAGE = Path(__file__).resolve().parents[2] / "moas_gui"

ALLOWED: dict[str, set[str]] = {
    "errors": set(),
    "addresses": set(),
    "aio": set(),
    "status": set(),
    "files": set(),
    "places": set(),
    "clock": set(),
    "retry": set(),
    "log_repeats": set(),
    "line_framer": set(),
    "log_limit": set(),
    "edge": {"clock", "errors", "log_limit"},
    "loop_watch": {"edge", "log_limit"},
    "operators": {"errors", "files", "places"},
    "tls": {"errors", "files", "places"},
    "antenna_log": {"aio", "clock", "config", "engine", "errors", "files", "places"},
    "serial": {"errors"},
    "config": {"errors"},
    "engine": {"config", "errors"},
    "state_store": {"engine", "errors", "files", "places"},
    "plan": {"config", "engine", "errors"},
    "builder": {"config", "engine", "errors", "files", "places", "plan"},
    "hw": {"addresses", "aio", "clock", "config", "edge", "engine", "errors", "files",
           "line_framer", "retry", "serial"},
    "net": {"aio", "antenna_log", "config", "edge", "errors", "hw", "line_framer", "log_limit",
            "operators", "tls"},
    "rights": {"config", "engine", "net"},
    "rotator_program": {"clock", "edge", "errors", "hw", "log_limit", "retry", "serial"},
    "engine_backend": {"engine", "errors", "hw", "net", "rights", "status"},
    "source_intake": {"engine", "sources"},
    "running": {"addresses", "antenna_log", "clock", "config", "edge", "engine", "errors", "files", "hw",
                "net", "operators", "source_intake", "sources", "state_store", "tls"},
    "opening": {"config", "state_store"},
    "antenna_feed": {"antenna_log", "engine", "hw", "running"},
    "switch_events": {"antenna_feed", "engine", "hw", "running", "source_intake"},
    "server_view": {"addresses", "antenna_feed", "antenna_log", "config", "engine", "hw", "loop_watch",
                    "running", "sources", "status"},
    "app": {"addresses", "antenna_feed", "antenna_log", "clock", "config", "engine", "engine_backend", "errors",
            "files", "hw", "loop_watch", "net", "opening", "rights", "running", "server_view", "source_intake",
            "sources", "state_store", "status", "switch_events", "tls"},
    "client": {"addresses", "clock", "errors", "files", "line_framer", "places", "retry",
               "tls"},
    "sources": {"addresses", "aio", "antenna_log", "client", "clock", "config", "engine", "errors", "hw",
                "line_framer", "log_limit", "retry", "serial"},
    "single_instance": {"edge", "errors"},
    "desktop": {"files"},
    "service": {"files"},
    "ui": {"addresses", "aio", "antenna_log", "app", "builder", "client", "hw", "log_repeats", "operators", "plan", "sources",
           "status"},
    "cli": {"antenna_log", "app", "builder", "client", "config", "hw", "net", "rotator_program", "single_instance", "ui",
            "desktop", "errors", "status", "engine", "addresses", "aio", "files", "clock",
            "retry", "sources", "log_repeats", "places", "service", "plan", "edge",
            "operators", "tls"},
    "testing": {"aio", "clock", "edge", "hw", "net", "ui"},
}
"""Which packages (or top-level modules) of moas_gui each one may import."""

NEVER: dict[str, set[str]] = {
    "sources": {"net", "edge"},
}
"""Arrows that must stay absent whatever :data:`ALLOWED` says one day: the frequency
sources are clients of loggers and radios, not listeners of the client protocol (the
limiter of repeated log lines they share with the listeners is ``moas_gui.log_limit``)."""

NET_MAY_USE_FROM_HW = {"moas_gui.hw.rotators.base", "moas_gui.hw.rotators.headings"}
"""The rotctld listener speaks of rotators; nothing else of hw/ is the client side's business."""

PURE = {"builder", "config", "engine"}
FORBIDDEN_IN_PURE = {"PySide6", "qasync", "asyncio", "serial", "socket", "selectors",
                     "threading", "subprocess"}
"""The engine and the configuration model do no I/O and know no event loop; the builder's
model (moas_gui.builder) reads and writes its file but loads no Qt and runs no loop."""


def _modules() -> dict[str, tuple[str, Path]]:
    found = {}
    for path in PACKAGE.rglob("*.py"):
        found[module_name(path, PACKAGE)] = (path.relative_to(PACKAGE).parts[0].removesuffix(".py"),
                                              path)
    return found


def _imports(name: str, path: Path) -> set[str]:
    return imported_names(path, name)


@functools.cache
def modules() -> dict[str, tuple[str, Path]]:
    """Every module of the package, read once, when a test first asks (not at collection)."""
    return _modules()


@functools.cache
def imports() -> dict[str, set[str]]:
    return {name: _imports(name, path) for name, (_, path) in modules().items()}


@functools.cache
def _edges() -> dict[str, set[str]]:
    edges: dict[str, set[str]] = defaultdict(set)
    for name, (top, _) in modules().items():
        for imported in imports()[name]:
            parts = imported.split(".")
            if parts[0] == "moas_gui" and len(parts) > 1 and parts[1] != top \
                    and f"moas_gui.{parts[1]}" in modules() | _packages():
                edges[top].add(parts[1])
    return edges


def _packages() -> dict[str, tuple[str, Path]]:
    return {f"moas_gui.{p.name}": (p.name, p) for p in PACKAGE.iterdir() if p.is_dir()}


def test_every_package_of_moas_gui_has_a_rule() -> None:
    tops = {top for top, _ in modules().values()} - {"__init__", "manual", "resources", "examples"}
    assert tops <= set(ALLOWED), f"add a rule for {sorted(tops - set(ALLOWED))}"


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_each_package_imports_only_what_it_may(package: str) -> None:
    extra = _edges().get(package, set()) - ALLOWED[package]
    assert not extra, f"moas_gui.{package} imports {sorted(extra)}, which it may not"


@pytest.mark.parametrize("package", sorted(NEVER))
def test_the_arrows_that_must_stay_absent_are(package: str) -> None:
    assert not NEVER[package] & ALLOWED[package], f"ALLOWED lets {package} import {NEVER[package]}"
    present = _edges().get(package, set()) & NEVER[package]
    assert not present, f"moas_gui.{package} imports {sorted(present)}"


def test_the_packages_import_each_other_without_a_cycle() -> None:
    edges = _edges()
    done: set[str] = set()

    def visit(node: str, trail: tuple[str, ...]) -> None:
        assert node not in trail, "import cycle: " + " -> ".join((*trail, node))
        if node in done:
            return
        for nxt in sorted(edges.get(node, ())):
            visit(nxt, (*trail, node))
        done.add(node)

    for node in sorted(edges):
        visit(node, ())


def test_hw_imports_nothing_from_net_and_net_only_rotator_types_from_hw() -> None:
    for name, (top, _) in modules().items():
        if top == "hw":
            assert not {i for i in imports()[name] if i.startswith("moas_gui.net")}, name
        if top == "net":
            used = {i for i in imports()[name] if i.startswith("moas_gui.hw")}
            taken = {i for i in used if i in modules()}
            assert taken <= NET_MAY_USE_FROM_HW, f"{name} uses {sorted(taken)}"


@pytest.mark.parametrize("package", sorted(PURE))
def test_the_engine_and_the_configuration_import_no_qt_loop_serial_or_socket(
        package: str) -> None:
    for name, (top, _) in modules().items():
        if top == package:
            roots = {i.split(".")[0] for i in imports()[name]}
            assert not roots & FORBIDDEN_IN_PURE, f"{name} imports {sorted(roots & FORBIDDEN_IN_PURE)}"


def test_the_rules_see_late_imports_too(tmp_path: Path) -> None:
    """A function-level import counts like any other (an import cycle cannot hide there)."""
    module = tmp_path / "late.py"
    module.write_text("def f():\n    from moas_gui.net import server\n    import asyncio\n")
    assert {"moas_gui.net", "moas_gui.net.server", "asyncio"} <= _imports("moas_gui.hw.late",
                                                                           module)


SANS_IO = ["moas_gui.hw.moas2.messages", "moas_gui.hw.moas2.decoder", "moas_gui.hw.moas2.sync",
           "moas_gui.hw.moas2.resync", "moas_gui.hw.moas2.plan", "moas_gui.engine",
           "moas_gui.config"]
"""The codec's modules and the engine, which load no event loop and no serial port."""
LOOP_OR_PORT = ("asyncio", "serial", "PySide6", "socket")


@functools.cache
def loaded_after_each() -> dict[str, list[str]]:
    """What of :data:`LOOP_OR_PORT` one fresh interpreter holds after importing each of
    :data:`SANS_IO` in turn (one process for all of them, not one each: what the first
    *k* load together is all that the *k*-th loads alone, and more, so none of them
    found after the *k*-th means the *k*-th alone loads none)."""
    probe = ("import importlib, json, sys\n"
             "found = {}\n"
             f"for name in {SANS_IO!r}:\n"
             "    importlib.import_module(name)\n"
             f"    found[name] = sorted(m for m in {LOOP_OR_PORT!r} if m in sys.modules)\n"
             "print(json.dumps(found))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    found: dict[str, list[str]] = json.loads(done.stdout)
    return found


@pytest.mark.parametrize("module", SANS_IO)
def test_a_sans_io_codec_or_the_engine_loads_no_loop_and_no_serial_port(module: str) -> None:
    """Importing the codec (or the engine) loads neither asyncio nor pyserial: the switch
    package's ``__init__`` imports its link only when ``SwitchLink`` is asked for."""
    loaded = loaded_after_each()[module]
    assert loaded == [], f"{module} loads {loaded} (or one imported before it in the probe)"


def test_check_and_plan_load_no_event_loop() -> None:
    """``moas-server --check`` and ``--plan`` read a file and print: they load no asyncio
    (about a sixth of such a run's processor time, paid on every check before); the
    server's run imports it when it starts one."""
    example = PACKAGE.parent / "examples" / "small-station.moas"
    probe = ("import contextlib, io, sys\n"
             "from moas_gui.cli.server import main\n"
             "with contextlib.redirect_stdout(io.StringIO()):\n"
             f"    codes = [main(['--check', {str(example)!r}]), "
             f"main(['--plan', {str(example)!r}])]\n"
             "print(codes, 'asyncio' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[0, 0] False", done.stdout + done.stderr


def test_the_emulated_box_loads_no_engine_and_no_configuration() -> None:
    """``moas-emulator`` plays the box from the codec and the firmware model: the switch
    package hands out its planner (:mod:`moas_gui.hw.moas2.sync`, which reads the
    engine's switch state) only when asked, so an emulator process loads neither the
    engine nor the configuration (a third of its start-up before)."""
    probe = ("import sys, moas_gui.hw.moas2.emulator.box, moas_gui.hw.moas2.emulator.serve, "
             "moas_gui.hw.moas2.emulator.control, moas_gui.cli.emulator\n"
             "print(sorted(m for m in ('moas_gui.engine', 'moas_gui.config') "
             "if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]", done.stdout
