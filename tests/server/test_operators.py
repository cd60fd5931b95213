"""The operators file: tokens shown once and kept only as salted hashes, names and radios
checked, a damaged file said plainly; and where it lives."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from moas_gui.operators import OperatorBook, OperatorError, Role, parse_radios, split_token
from moas_gui.places import config_dir


def test_a_token_is_checked_against_its_hash_and_nothing_else_passes(tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "ops.json")
    first, token = book.add("alice", Role.ADMIN)
    second, other = book.add("bob", Role.VIEW, frozenset({(1, 2)}))
    assert book.check(token) == first and book.check(other) == second
    key, secret = split_token(token) or ("", "")
    assert book.check(f"moas1.{key}.{secret[:-1]}A" if secret[-1] != "A" else token[:-1] + "B") \
        is None
    for wrong in ("", "moas1", "moas1..x", "moas2." + token[6:], token + " extra", "x" * 5000):
        assert book.check(wrong) is None
    stored = json.loads((tmp_path / "ops.json").read_text())["operators"]
    assert secret not in json.dumps(stored)
    assert stored[0]["salt"] != stored[1]["salt"] and len(stored[0]["hash"]) == 64
    assert book.operators()[1].radios_text() == "1/2"


def test_names_and_radios_are_checked_with_a_sentence(tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "ops.json")
    for name in ("", " lead", "a" * 41, "new\nline", "tab\there"):
        with pytest.raises(OperatorError, match="not an operator name"):
            book.add(name, Role.VIEW)
    assert parse_radios("1/1, 2/3") == frozenset({(1, 1), (2, 3)})
    with pytest.raises(OperatorError, match="STATION/RADIO"):
        parse_radios("1/1,2")
    with pytest.raises(OperatorError, match="no operator"):
        book.remove("nobody")


def test_a_damaged_file_is_named_and_lets_no_token_in(tmp_path: Path) -> None:
    path = tmp_path / "ops.json"
    book = OperatorBook(path)
    _op, token = book.add("alice", Role.ADMIN)
    path.write_text('{"operators": [{"name": "alice"', encoding="utf-8")
    with pytest.raises(OperatorError, match=str(path)):
        book.operators()
    assert book.check(token) is None


def test_the_file_lives_in_the_configuration_directory(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    assert config_dir() == tmp_path / "moas-gui"
    assert OperatorBook().path == tmp_path / "moas-gui" / "operators.json"
