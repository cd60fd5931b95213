"""Writing a file so that a crash, ``kill -9`` or a full disk never leaves it half
written: the new content goes to a temporary file beside it, is flushed to the disk,
and is renamed over the old one.  A reader sees the old file or the new one, whole.
On Windows the rename is tried again for a moment while another program (a virus
scanner, the search indexer) holds the file.

Every file the server writes goes through :func:`write_atomic` (the saved state, Save
Switch Data, the desktop registration's files); Qt's ``QSettings`` (recent files, the
window's place) does the same by itself (``QSaveFile``).
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Final


def temporary_name(path: Path) -> Path:
    """Where :func:`write_atomic` puts ``path``'s new content first (hidden, per process)."""
    return path.with_name(f".{path.name}.{os.getpid()}.tmp")


def write_atomic(path: Path, data: bytes) -> None:
    """Replace ``path`` by ``data``: a temporary file, flushed to disk, renamed over it.
    The directory must exist.  An existing file's permissions are kept."""
    temporary = temporary_name(path)
    try:
        with open(temporary, "wb") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        with contextlib.suppress(OSError):
            os.chmod(temporary, os.stat(path).st_mode & 0o7777)
        replace_patiently(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            temporary.unlink()
        raise
    if sys.platform != "win32":
        # the rename itself reaches the disk only with the directory
        with contextlib.suppress(OSError):
            fd = os.open(path.parent, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)


REFUSALS_PASS = sys.platform == "win32"
"""Whether a refused rename is worth trying again: on Windows a virus scanner, the search
indexer or a backup program may hold the file for a moment, and the rename fails with
``PermissionError`` until it lets go.  Elsewhere a refusal is final."""
RETRY_PAUSES_S: Final = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5)
"""The pauses between tries (about 1.2 s in all), then the last refusal is raised."""


def replace_patiently(source: Path, target: Path,
                      sleep: Callable[[float], None] = time.sleep) -> None:
    """``os.replace(source, target)``, tried again after a short pause while Windows
    refuses it (see :data:`REFUSALS_PASS`)."""
    pauses = iter(RETRY_PAUSES_S if REFUSALS_PASS else ())
    while True:
        try:
            os.replace(source, target)
            return
        except PermissionError:
            pause = next(pauses, None)
            if pause is None:
                raise
            sleep(pause)


def write_text_atomic(path: Path, text: str) -> None:
    """:func:`write_atomic` for text, in UTF-8."""
    write_atomic(path, text.encode("utf-8"))


__all__ = ["replace_patiently", "temporary_name", "write_atomic", "write_text_atomic"]
