"""The server window's hook seam (moas_gui.ui.control_hook): off unless the environment
names a module, and then that module's ``start(window)``, whatever it is."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from moas_gui.ui.control_hook import ENVIRONMENT, start_if_asked

HOOK = '''
class Hook:
    def __init__(self, window):
        self.window = window
        self.closed = False

    async def close(self):
        self.closed = True


async def start(window):
    return Hook(window)
'''


@pytest.mark.asyncio
async def test_with_the_variable_unset_nothing_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENVIRONMENT, raising=False)
    assert await start_if_asked(object()) is None
    monkeypatch.setenv(ENVIRONMENT, "  ")
    assert await start_if_asked(object()) is None


@pytest.mark.asyncio
async def test_the_named_module_is_imported_and_started_with_the_window(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "seam_probe_hook.py").write_text(HOOK)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv(ENVIRONMENT, "seam_probe_hook")
    window = object()
    try:
        hook = await start_if_asked(window)
        assert hook is not None
        assert hook.window is window  # type: ignore[attr-defined]
        await hook.close()
        assert hook.closed  # type: ignore[attr-defined]
    finally:
        sys.modules.pop("seam_probe_hook", None)


@pytest.mark.asyncio
async def test_a_wrong_name_says_which_variable_and_what_is_wrong(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(ENVIRONMENT, "no_such_module_for_the_seam")
    with pytest.raises(ImportError, match=f"{ENVIRONMENT}='no_such_module_for_the_seam'"):
        await start_if_asked(object())
    (tmp_path / "seam_probe_startless.py").write_text("VALUE = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv(ENVIRONMENT, "seam_probe_startless")
    try:
        with pytest.raises(TypeError, match="no start"):
            await start_if_asked(object())
    finally:
        sys.modules.pop("seam_probe_startless", None)
