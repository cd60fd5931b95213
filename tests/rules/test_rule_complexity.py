"""A rule of the codebase: no function in ``moas_gui`` above cyclomatic complexity 20.

A function with more branches than that holds several rules of the manual at once; it is
cut into steps that each read as one rule, with its docstring (docs/engine.md).  The
score is radon's (every ``if``, loop, ``except``, boolean operator, comprehension and
``case`` adds one), read in process; a function defined inside another is held to the
same limit under its own name.  ``ruff check`` holds the same limit with mccabe (C901 in
pyproject.toml), which counts a little less (no boolean operators), so radon's is the
one that decides.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path

from import_reader import syntax_tree
from radon.complexity import cc_visit, cc_visit_ast
from radon.visitors import Function

ROOT = Path(__file__).resolve().parent.parent.parent
PACKAGE = ROOT / "moas_gui"
LIMIT = 20


def _functions(blocks: Iterable[object], outer: str = "") -> Iterator[tuple[str, Function]]:
    """Every function among ``blocks`` with its name, and those defined inside each."""
    for block in blocks:
        if isinstance(block, Function):
            name = outer + block.fullname
            yield name, block
            yield from _functions(block.closures, name + ".")


def too_complex(source: str | ast.Module, filename: str, limit: int = LIMIT) -> list[str]:
    """``file:line name (score)`` for every function, method or inner function of
    ``source`` (its text, or its parsed tree) whose complexity is above ``limit``."""
    blocks = cc_visit(source) if isinstance(source, str) else cc_visit_ast(source)
    return [f"{filename}:{block.lineno} {name} ({block.complexity})"
            for name, block in _functions(blocks) if block.complexity > limit]


def _branches(name: str, count: int, indent: str = "") -> str:
    """A function of complexity ``count + 1``: ``count`` ifs one after the other."""
    lines = [f"{indent}def {name}(x):"]
    for i in range(count):
        lines.append(f"{indent}    if x == {i}:")
        lines.append(f"{indent}        return {i}")
    lines.append(f"{indent}    return -1")
    return "\n".join(lines) + "\n"


def test_a_function_one_above_the_limit_is_named_with_its_score() -> None:
    first = _branches("at_the_limit", LIMIT - 1)
    source = first + _branches("one_too_many", LIMIT)
    line = first.count("\n") + 1
    assert too_complex(source, "generated.py") == [f"generated.py:{line} one_too_many (21)"]


def test_methods_and_closures_count_too() -> None:
    method = "class Holder:\n" + _branches("crowded", LIMIT, indent="    ")
    assert too_complex(method, "method.py") == ["method.py:2 Holder.crowded (21)"]
    # moving branches into an inner function does not hide them
    closure = ("def outer(x):\n" + _branches("inner", LIMIT, indent="    ")
               + "    return inner(x)\n")
    assert too_complex(closure, "closure.py") == ["closure.py:2 outer.inner (21)"]


def test_no_function_in_the_package_is_above_the_limit() -> None:
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        found += too_complex(syntax_tree(path), str(path.relative_to(ROOT)))
    assert not found, (f"{len(found)} functions are above complexity {LIMIT}: cut each into "
                       "steps that read as one rule each\n" + "\n".join(found))


def test_ruff_says_it_too_with_the_projects_settings(tmp_path: Path) -> None:
    sample = tmp_path / "sample.py"
    sample.write_text(_branches("at_the_limit", LIMIT - 1) + "\n\n"
                      + _branches("one_too_many", LIMIT), encoding="utf-8")
    result = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "concise",
         "--config", str(ROOT / "pyproject.toml"), str(sample)],
        capture_output=True, text=True, check=False)
    assert result.returncode == 1, result.stdout + result.stderr
    flagged = [line for line in result.stdout.splitlines() if "C901" in line]
    assert len(flagged) == 1, result.stdout
    assert "`one_too_many` is too complex (21 > 20)" in flagged[0]
