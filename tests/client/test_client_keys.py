"""What the desktop client keeps per server: the token in a keyring (here keyrings.alt's
file keyring, a real backend), or, where no keyring runs, a file only its user may read."""

from __future__ import annotations

import stat
import sys
from collections.abc import Iterator
from pathlib import Path

import keyring
import pytest
from keyrings.alt.file import PlaintextKeyring

from moas_gui.client.keys import KNOWN_FILE, TOKENS_FILE, ClientKeys


@pytest.fixture
def file_keyring(tmp_path: Path) -> Iterator[PlaintextKeyring]:
    ring = PlaintextKeyring()
    ring.file_path = str(tmp_path / "ring" / "keyring_pass.cfg")
    before = keyring.get_keyring()
    keyring.set_keyring(ring)
    yield ring
    keyring.set_keyring(before)


def test_the_token_goes_to_the_keyring_and_nowhere_else(
        tmp_path: Path, file_keyring: PlaintextKeyring) -> None:
    keys = ClientKeys(tmp_path / "cfg", use_keyring=True)
    assert keys.set_token("10.0.0.5:12059", "moas1.0a0b0c0d.secret-part") == "the system keyring"
    assert file_keyring.get_password("moas-gui", "token:10.0.0.5:12059") == \
        "moas1.0a0b0c0d.secret-part"
    assert ClientKeys(tmp_path / "cfg", use_keyring=True).token("10.0.0.5:12059") == \
        "moas1.0a0b0c0d.secret-part"
    assert not (tmp_path / "cfg" / TOKENS_FILE).exists()
    assert keys.token("10.0.0.6:12059") is None


def test_without_a_keyring_the_token_is_in_a_file_only_its_user_reads(tmp_path: Path) -> None:
    keys = ClientKeys(tmp_path / "cfg", use_keyring=False)
    where = keys.set_token("station:12059", "moas1.01020304.abc")
    path = tmp_path / "cfg" / TOKENS_FILE
    assert where == str(path)
    assert ClientKeys(tmp_path / "cfg", use_keyring=False).token("station:12059") == \
        "moas1.01020304.abc"
    if sys.platform != "win32":
        assert stat.S_IMODE(path.stat().st_mode) == 0o600


def test_a_pinned_fingerprint_is_kept_per_server(tmp_path: Path) -> None:
    keys = ClientKeys(tmp_path, use_keyring=False)
    keys.set_pin("a:1", "AB:CD")
    keys.set_pin("b:2", "EF:01")
    again = ClientKeys(tmp_path, use_keyring=False)
    assert (again.pin("a:1"), again.pin("b:2"), again.pin("c:3")) == ("AB:CD", "EF:01", None)
    assert (tmp_path / KNOWN_FILE).is_file()


def test_the_command_line_pins_a_fingerprint_or_trusts_the_first_one_it_sees(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import argparse

    from moas_gui.cli.client import connection_security

    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    monkeypatch.setattr("moas_gui.client.keys._keyring_usable", lambda: False)

    def args(**given: object) -> argparse.Namespace:
        return argparse.Namespace(**{"token": None, "tls": False, "pin": None, **given})

    first = connection_security("10.0.0.5", 12059, args(tls=True, token="moas1.01020304.x"))
    trust = first["trust"]
    assert first["token"] == "moas1.01020304.x" and callable(trust)
    assert trust("AB:" * 31 + "CD") is True  # trusted on first use, and kept
    again = connection_security("10.0.0.5", 12059, args(tls=True))
    assert again["pin"] == "AB:" * 31 + "CD" and "trust" not in again
    assert again["token"] == "moas1.01020304.x"  # given once
    pinned = connection_security("10.0.0.5", 12059, args(tls=True, pin="ef" * 32))
    assert pinned["pin"] == ":".join(["EF"] * 32)
    with pytest.raises(ValueError, match="64 hex digits"):
        connection_security("10.0.0.5", 12059, args(tls=True, pin="12:34"))
    with pytest.raises(ValueError, match="goes with --tls"):
        connection_security("10.0.0.5", 12059, args(pin="ef" * 32))


def test_a_plaintext_file_keyring_is_not_taken_for_the_system_keyring(
        file_keyring: PlaintextKeyring) -> None:
    from moas_gui.client.keys import _keyring_usable

    assert keyring.get_keyring() is file_keyring
    assert _keyring_usable() is False
