"""Reading what a module imports, for the rule tests (``test_rule_imports.py``,
``test_rule_testing_package.py``): every ``import`` and ``from ... import`` with
:mod:`ast`, those inside functions too, and ``import_module``/``__import__`` given a
literal name."""

from __future__ import annotations

import ast
from pathlib import Path

DYNAMIC = {"import_module", "__import__"}


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
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
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
