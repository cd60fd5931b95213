"""The product never imports ``moas_gui.testing`` (the fakes and test hooks).

Every module of moas_gui outside ``moas_gui/testing/`` is read with :mod:`ast`:
its ``import`` and ``from ... import`` statements (relative ones resolved, those
inside functions too) and any ``importlib.import_module(...)`` or
``__import__(...)`` given a literal name.  None may reach ``moas_gui.testing``.
A second check imports the programs' entry modules in a fresh interpreter and
looks at what was loaded.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from import_reader import imported_names, module_name

PACKAGE = Path(__file__).resolve().parents[2] / "moas_gui"
TESTING = "moas_gui.testing"


def reaches_testing(names: set[str]) -> list[str]:
    return sorted(n for n in names if n == TESTING or n.startswith(TESTING + "."))


def offenders(root: Path = PACKAGE) -> dict[str, list[str]]:
    """Modules outside ``<root>/testing`` that import the testing package, and what."""
    out: dict[str, list[str]] = {}
    for path in sorted(root.rglob("*.py")):
        if path.relative_to(root).parts[0] == "testing":
            continue
        name = module_name(path, root)
        hits = reaches_testing(imported_names(path, name))
        if hits:
            out[name] = hits
    return out


def test_no_module_outside_the_testing_package_imports_it() -> None:
    found = offenders()
    assert not found, "the product imports moas_gui.testing: " + "; ".join(
        f"{module} imports {', '.join(names)}" for module, names in found.items())


def test_the_testing_package_holds_the_fakes() -> None:
    """The rule guards something: the fakes are there, and nowhere else in the product."""
    names = {p.stem for p in (PACKAGE / "testing").glob("*.py")}
    assert {"fake_backend", "fake_server", "fake_station", "fake_moas_rotator", "genius_server",
            "faulty_controller", "control_hook"} <= names
    for old in ("net/fake_backend.py", "net/fake_server.py", "net/fake_station.py",
                "hw/rotators/fake_moas_rotator.py", "hw/rotators/genius_emulator.py",
                "hw/rotators/controllers/faulty.py"):
        assert not (PACKAGE / old).exists(), f"moas_gui/{old} is back in the product"


@pytest.mark.parametrize("source", [
    "from moas_gui.testing.fake_backend import FakeBackend\n",
    "import moas_gui.testing.fake_server\n",
    "from moas_gui import testing\n",
    "from ..testing import fake_station\n",
    "def later():\n    from ...testing.genius_server import GeniusServer\n",
    "import importlib\nhook = importlib.import_module('moas_gui.testing.control_hook')\n",
    "mod = __import__('moas_gui.testing')\n",
])
def test_the_rule_fails_on_every_way_of_importing_it(tmp_path: Path, source: str) -> None:
    """A copy of the package's shape with one offending module: the rule names it."""
    root = tmp_path / "moas_gui"
    (root / "testing").mkdir(parents=True)
    (root / "testing" / "__init__.py").write_text("")
    (root / "testing" / "fake_backend.py").write_text("from moas_gui.net import backend\n")
    (root / "net" / "sub").mkdir(parents=True)
    (root / "net" / "__init__.py").write_text("from .backend import ClientBackend\n")
    (root / "net" / "backend.py").write_text("import json\n")
    offender = root / "net" / "sub" / "bad.py" if source.startswith("def later") \
        else root / "net" / "bad.py"
    offender.write_text(source)
    found = offenders(root)
    assert list(found) == [module_name(offender, root)]
    assert all(n.startswith(TESTING) for n in found[module_name(offender, root)])


def test_a_mention_in_words_is_not_an_import(tmp_path: Path) -> None:
    root = tmp_path / "moas_gui"
    root.mkdir()
    (root / "doc.py").write_text('"""Client authors: see moas_gui.testing.fake_server."""\n'
                                 'HELP = "python -m moas_gui.testing.fake_server"\n')
    assert offenders(root) == {}


def test_starting_the_programs_loads_nothing_of_the_testing_package() -> None:
    """The entry modules of every program, and the packages that held the fakes before,
    imported in a fresh interpreter, leave ``moas_gui.testing`` unloaded."""
    entries = ["moas_gui.cli.server", "moas_gui.cli.client", "moas_gui.cli.emulator",
               "moas_gui.cli.rotator", "moas_gui.net", "moas_gui.hw.rotators",
               "moas_gui.hw.rotators.controllers", "moas_gui.ui.control_hook"]
    probe = ("import importlib, sys\n"
             f"for name in {entries!r}:\n"
             "    importlib.import_module(name)\n"
             "print(sorted(m for m in sys.modules if m.startswith('moas_gui.testing')))\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]", f"loaded: {done.stdout.strip()}"
