"""A newcomer finds everything: the README names every page of docs/ and every option of
``moas-server``, and the manual's contents (docs/README.md, Help > Manual's first page)
name every page."""

from __future__ import annotations

import re
from pathlib import Path

from moas_gui.cli.server import _parser

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def pages() -> set[str]:
    return {p.name for p in DOCS.glob("*.md") if p.name != "README.md"}


def linked(text: str, prefix: str = "") -> set[str]:
    return set(re.findall(r"\]\(" + re.escape(prefix) + r"([a-z0-9-]+\.md)", text))


def options() -> set[str]:
    found: set[str] = set()
    for action in _parser()._actions:
        found.update(s for s in action.option_strings if s.startswith("--") and s != "--help")
    return found


def test_the_readme_links_every_page_of_the_docs() -> None:
    missing = pages() - linked((ROOT / "README.md").read_text(encoding="utf-8"), "docs/")
    assert not missing, f"README.md's documentation list leaves out {sorted(missing)}"


def test_the_manuals_contents_list_every_page() -> None:
    missing = pages() - linked((DOCS / "README.md").read_text(encoding="utf-8"))
    assert not missing, f"docs/README.md (Help > Manual's contents) leaves out {sorted(missing)}"


def test_the_readme_names_every_option_of_the_server() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    named = set(re.findall(r"(--[a-z0-9][a-z0-9-]*)", readme))
    assert "--tls" in options() and len(options()) > 40, "the parser was read"
    missing = options() - named
    assert not missing, f"README.md's options leave out {sorted(missing)}"
