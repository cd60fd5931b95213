"""One builder window per file: a window claims its file, and a second window (of this
program or another) that wants the same file is told which window has it.

A claim is a small file in the user's state directory (``builder-claims/``) named after
the station file's full path, holding the claiming process, its window's name and when.
A claim whose process has ended is stale and taken over, so a crash never locks a file.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from moas_gui.errors import MoasError
from moas_gui.files import write_atomic
from moas_gui.places import state_dir


@dataclass(frozen=True, slots=True)
class Claim:
    path: str
    pid: int
    window: str
    since: float

    def describe(self) -> str:
        when = time.strftime("%H:%M", time.localtime(self.since))
        here = "this program" if self.pid == os.getpid() else f"process {self.pid}"
        return f'the builder window "{self.window}" ({here}, since {when})'


class FileClaimed(MoasError):
    """The file is open in another builder window (``claim`` says which)."""

    def __init__(self, claim: Claim) -> None:
        self.claim = claim
        super().__init__(f"{claim.path} is already open in {claim.describe()}; "
                         "edit it there, or close that window first")


_HELD: dict[str, str] = {}
"""The claims of this process: the claim file's name to the window's name."""


def claims_dir() -> Path:
    return state_dir() / "builder-claims"


def _claim_file(path: Path) -> Path:
    key = hashlib.sha256(str(path.resolve()).encode("utf-8")).hexdigest()[:32]
    return claims_dir() / f"{key}.json"


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (never a signal on Windows, where ``os.kill`` ends it)."""
    if pid == os.getpid():
        return True
    if sys.platform == "win32":
        return _alive_on_windows(pid)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # there is such a process (another user's, or a system that will not say)
    return True


def _alive_on_windows(pid: int) -> bool:
    import ctypes

    kernel = ctypes.windll.kernel32  # type: ignore[attr-defined,unused-ignore]
    handle = kernel.OpenProcess(0x1000, False, pid)  # PROCESS_QUERY_LIMITED_INFORMATION
    if not handle:
        return bool(kernel.GetLastError() == 5)  # access denied: it runs, as another user
    try:
        code = ctypes.c_ulong()
        return bool(kernel.GetExitCodeProcess(handle, ctypes.byref(code))) and code.value == 259
    finally:
        kernel.CloseHandle(handle)  # (259: STILL_ACTIVE)


def holder(path: Path) -> Claim | None:
    """Who has ``path`` open, if anyone does still."""
    claim_file = _claim_file(path)
    try:
        data = json.loads(claim_file.read_text(encoding="utf-8"))
        claim = Claim(str(data["path"]), int(data["pid"]), str(data["window"]), float(data["since"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if claim.pid == os.getpid() and claim_file.name not in _HELD:
        return None  # a claim of this process's past (a pid used again)
    return claim if _alive(claim.pid) else None


def claim(path: Path, window: str) -> Claim:
    """Claim ``path`` for ``window``; :class:`FileClaimed` when another window has it."""
    held = holder(path)
    if held is not None:
        raise FileClaimed(held)
    mine = Claim(str(path.resolve()), os.getpid(), window, time.time())
    claim_file = _claim_file(path)
    claim_file.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(claim_file, json.dumps({"path": mine.path, "pid": mine.pid, "window": window,
                                         "since": mine.since}).encode("utf-8"))
    _HELD[claim_file.name] = window
    return mine


def release(path: Path) -> None:
    """Give ``path`` up (nothing when this process does not hold it)."""
    claim_file = _claim_file(path)
    if _HELD.pop(claim_file.name, None) is not None:
        with contextlib.suppress(OSError):
            claim_file.unlink()


__all__ = ["Claim", "FileClaimed", "claim", "claims_dir", "holder", "release"]
