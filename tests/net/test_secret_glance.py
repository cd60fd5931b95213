"""The operators file's watch: while the file is unchanged, a glance (one ``stat``) from
a timer every WATCH_EVERY seconds and no task waiting between glances (a quiet server
pays one loop turn a glance); a change is still read and the removed operator's
sessions ended."""

from __future__ import annotations

import asyncio
from pathlib import Path

import pytest
from helpers import until

from moas_gui.net.secrets import WATCH_EVERY, SecretGuard
from moas_gui.operators import OperatorBook, Role


def looks_under_way() -> list[asyncio.Task[object]]:
    return [task for task in asyncio.all_tasks()
            if "SecretGuard._watching" in repr(task.get_coro())]


@pytest.mark.asyncio
async def test_an_unchanged_file_is_glanced_at_and_a_removal_still_ends_sessions(
        tmp_path: Path) -> None:
    book = OperatorBook(tmp_path / "operators.json")
    book.add("otto", Role.OPERATE)
    book.add("anna", Role.OPERATE)
    guard = SecretGuard(book)
    ended: list[str] = []

    def end(name: str) -> int:
        ended.append(name)
        return 1

    guard.listen(end)
    try:
        await until(lambda: guard.watched, what="the watcher's first read")
        await asyncio.sleep(3 * WATCH_EVERY)
        assert looks_under_way() == [], "between glances of an unchanged file no task waits"
        OperatorBook(book.path).remove("otto")  # as another process would edit it
        await until(lambda: ended == ["otto"], timeout=30, what="the removal noticed")
        await asyncio.sleep(2 * WATCH_EVERY)
        assert ended == ["otto"] and looks_under_way() == []
    finally:
        guard.close()
