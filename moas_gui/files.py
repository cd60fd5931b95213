"""Writing a file so that a crash, ``kill -9`` or a full disk never leaves it half
written: the new content goes to a temporary file beside it, is flushed to the disk,
and is renamed over the old one.  A reader sees the old file or the new one, whole.

Every file the server writes goes through :func:`write_atomic` (the saved state, Save
Switch Data, the desktop registration's files); Qt's ``QSettings`` (recent files, the
window's place) does the same by itself (``QSaveFile``).
"""

from __future__ import annotations

import contextlib
import os
import sys
from pathlib import Path


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
        os.replace(temporary, path)
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


def write_text_atomic(path: Path, text: str) -> None:
    """:func:`write_atomic` for text, in UTF-8."""
    write_atomic(path, text.encode("utf-8"))


__all__ = ["temporary_name", "write_atomic", "write_text_atomic"]
