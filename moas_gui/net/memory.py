"""Giving freed memory back to the operating system.

After hundreds of clients leave (or are cut off), Python has freed what they
held, but the C library may keep the pages for later; on a station computer
that runs for days, the server should shrink back.  :func:`give_back_memory`
asks glibc to return what it can (``malloc_trim``); elsewhere it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
import sys
from collections.abc import Callable

log = logging.getLogger(__name__)


def _find_trim() -> Callable[[int], int] | None:
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim: Callable[[int], int] = libc.malloc_trim
    except (OSError, AttributeError):  # not glibc (musl has no malloc_trim)
        return None
    return trim


_TRIM = _find_trim()


def give_back_memory() -> bool:
    """Returns freed heap memory to the system where the C library can; says whether it could."""
    if _TRIM is None:
        return False
    _TRIM(0)
    return True


__all__ = ["give_back_memory"]
