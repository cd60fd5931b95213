"""Reading the package's modules for the rule tests: :func:`syntax_tree` and
:func:`nodes` parse and walk each file once per test process, for every rule test that
reads the whole package (imports, class names and sizes, complexity, the one door, nested
loops ...: each read of all of it costs about a second); and what a module imports
(``test_rule_imports.py``, ``test_rule_testing_package.py``): every ``import`` and
``from ... import`` with :mod:`ast`, those inside functions too, and
``import_module``/``__import__`` given a literal name.

The trees of the whole package are about 570,000 objects, kept for the rest of the
process: they are frozen out of the cyclic collector (:func:`gc.freeze`, as
``tests/conftest.py`` does with what collection loaded), or every full collection after
them -- one after each Qt test of the same worker -- would walk them all again (about
0.2 s each: a Qt test file of 19 tests cost 4.8 s of processor time instead of 0.9)."""

from __future__ import annotations

import ast
import functools
import gc
from pathlib import Path

DYNAMIC = {"import_module", "__import__"}


@functools.cache
def _parsed(path: Path, stamp: tuple[int, int]) -> tuple[ast.Module, tuple[ast.AST, ...]]:
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    walked = tuple(ast.walk(tree))
    _keep_out_of_collections()
    return tree, walked


@functools.cache
def _garbage_collected_once() -> None:
    gc.collect()


def _keep_out_of_collections() -> None:
    """What is alive now (a tree just read among it) is left out of the cyclic collector's
    later collections; the garbage of what ran before is collected first, once, so that
    it is not kept with the trees (the trees make no garbage of their own)."""
    _garbage_collected_once()
    gc.freeze()


def _read(path: Path) -> tuple[ast.Module, tuple[ast.AST, ...]]:
    stat = path.stat()  # a file written again (a test's own copy) is read again
    return _parsed(path.resolve(), (stat.st_mtime_ns, stat.st_size))


def syntax_tree(path: Path) -> ast.Module:
    """The module at ``path`` parsed (once per process while the file is unchanged: the
    rule tests only read the trees, never change them)."""
    return _read(path)[0]


def nodes(path: Path) -> tuple[ast.AST, ...]:
    """Every node of :func:`syntax_tree` in ``ast.walk`` order (walked once, too)."""
    return _read(path)[1]


def module_name(path: Path, root: Path) -> str:
    """The dotted name of the module at ``path`` in the package folder ``root``."""
    parts = path.relative_to(root).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join((root.name, *parts))


def imported_names(path: Path, name: str) -> set[str]:
    """Every module name ``path`` (the module ``name``) imports or asks for by a literal,
    and each ``module.name`` a ``from`` import takes."""
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found: set[str] = set()
    for node in nodes(path):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Call) and node.args:
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else \
                func.id if isinstance(func, ast.Name) else ""
            first = node.args[0]
            if called in DYNAMIC and isinstance(first, ast.Constant) \
                    and isinstance(first.value, str):
                found.add(first.value)
    return found
