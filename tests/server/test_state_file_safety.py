"""The saved state is read safely: a regular file of bounded size only; anything else
(a FIFO, a device, a link leading outside the state directory, a huge file) is ignored
with one warning saying what it is, and the server starts clean."""

from __future__ import annotations

import logging
import os
import sys
from pathlib import Path

import pytest

from moas_gui.state_store import (
    MAX_STATE_BYTES,
    SavedState,
    StateError,
    encode,
    load,
    read_state_file,
)

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="FIFOs and /dev are POSIX")


def _one_warning(caplog: pytest.LogCaptureFixture, *words: str) -> str:
    lines = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(lines) == 1, lines
    assert "\n" not in lines[0]
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


def test_a_fifo_is_refused_without_waiting_for_a_writer(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "station.state.json"
    os.mkfifo(path)
    with caplog.at_level(logging.WARNING):
        assert load(path, "x") is None  # returns at all: opening did not wait
    _one_warning(caplog, str(path), "FIFO", "starting without it")


def test_a_link_to_a_device_outside_the_directory_is_refused(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    path = tmp_path / "station.state.json"
    path.symlink_to("/dev/zero")
    with caplog.at_level(logging.WARNING):
        assert load(path, "x") is None
    _one_warning(caplog, "link to /dev/zero", "outside the state directory")


def test_a_link_to_a_regular_file_elsewhere_is_refused(tmp_path: Path) -> None:
    elsewhere = tmp_path / "other"
    elsewhere.mkdir()
    (elsewhere / "secret").write_text("{}")
    home = tmp_path / "state"
    home.mkdir()
    (home / "s.state.json").symlink_to(elsewhere / "secret")
    with pytest.raises(StateError, match="outside the state directory"):
        read_state_file(home / "s.state.json")


def test_a_link_within_the_directory_is_followed(tmp_path: Path) -> None:
    (tmp_path / "real.json").write_bytes(b'{"a": 1}')
    (tmp_path / "s.state.json").symlink_to(tmp_path / "real.json")
    assert read_state_file(tmp_path / "s.state.json") == b'{"a": 1}'


def test_a_link_to_dev_null_is_refused(tmp_path: Path) -> None:
    os.symlink("/dev/null", tmp_path / "null")
    with pytest.raises(StateError, match="outside the state directory"):
        read_state_file(tmp_path / "null")


def test_a_huge_file_is_not_read(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = tmp_path / "station.state.json"
    with path.open("wb") as f:
        f.truncate(300 << 20)  # sparse: costs no disk
    with caplog.at_level(logging.WARNING):
        assert load(path, "x") is None
    _one_warning(caplog, "314,572,800 bytes", f"{MAX_STATE_BYTES:,}")


def test_a_directory_is_refused(tmp_path: Path) -> None:
    (tmp_path / "s.state.json").mkdir()
    with pytest.raises(StateError):
        read_state_file(tmp_path / "s.state.json")


def test_no_file_is_no_state_and_no_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING):
        assert load(tmp_path / "none.state.json", "x") is None
    assert not caplog.records


def test_a_good_file_still_loads(tmp_path: Path) -> None:
    saved = SavedState("f" * 64, {}, {})
    path = tmp_path / "s.state.json"
    path.write_bytes(encode(saved))
    loaded = load(path, "f" * 64)
    assert loaded is not None and loaded.fingerprint == "f" * 64
