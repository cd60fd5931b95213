"""The process's limit of open files, which bounds how many clients it can serve.

Every client connection holds a file handle.  Many desktops start programs
with a soft limit of 1,024 handles although the hard limit allows far more;
:func:`raise_open_file_limit` lifts the soft limit as far as the system lets
an ordinary user, once, at start.  Windows has no such limit to raise (and no
:mod:`resource` module): there both functions do nothing.
"""

from __future__ import annotations

import logging
import sys
from typing import Final

log = logging.getLogger(__name__)

WANTED: Final = 65_536
"""Handles asked for at start: far more than any station needs, and not unlimited."""


def open_file_limit() -> int | None:
    """The soft limit of open files now, or ``None`` where there is none to read."""
    if sys.platform == "win32":
        return None
    import resource

    soft, _hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    return None if soft == resource.RLIM_INFINITY else int(soft)


def raise_open_file_limit(wanted: int = WANTED) -> int | None:
    """Raises the soft limit of open files towards ``wanted`` (never above the
    hard limit, never lowers it); returns the soft limit afterwards (``None``
    where there is no limit)."""
    if sys.platform == "win32":
        return None
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return None
    target = wanted if hard == resource.RLIM_INFINITY else min(wanted, hard)
    if target <= soft:
        return int(soft)
    # macOS refuses more than OPEN_MAX (10,240) whatever the hard limit says
    for attempt in (target, min(target, 10_240)):
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (attempt, hard))
        except (ValueError, OSError):
            continue
        log.debug("Open file limit raised from %d to %d", soft, attempt)
        return attempt
    log.info("Could not raise the open file limit (%d); clients are capped to fit in it", soft)
    return int(soft)


def fitting_client_limit(max_clients: int) -> int:
    """``max_clients``, or half the open-file limit when that is fewer (the
    other half is for the switches, rotators, logs and the program itself)."""
    files = open_file_limit()
    if files is None or max_clients <= files // 2:
        return max_clients
    limit = max(1, files // 2)
    log.warning("At most %d clients at once (not %d): this process may open only %d files",
                limit, max_clients, files)
    return limit


__all__ = ["WANTED", "fitting_client_limit", "open_file_limit", "raise_open_file_limit"]
