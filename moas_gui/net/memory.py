"""Giving freed memory back to the operating system.

After hundreds of clients leave (or are cut off), Python has freed what they
held, but the C library may keep the pages for later; on a station computer
that runs for days, the server should shrink back.  :func:`give_back_memory`
asks glibc to return what it can (``malloc_trim``); elsewhere it does nothing.
"""

from __future__ import annotations

import functools
import logging
import sys
from collections.abc import Callable

log = logging.getLogger(__name__)


@functools.cache
def _find_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, looked up on the first call (a server no crowd of clients
    ever leaves does not load ctypes nor look for the C library)."""
    if not sys.platform.startswith("linux"):
        return None
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        trim: Callable[[int], int] = libc.malloc_trim
    except (OSError, AttributeError):  # not glibc (musl has no malloc_trim)
        return None
    return trim


def give_back_memory() -> bool:
    """Returns freed heap memory to the system where the C library can; says whether it could."""
    trim = _find_trim()
    if trim is None:
        return False
    trim(0)
    return True


__all__ = ["give_back_memory"]
