"""The one seam for outside hands, in the server window and in the builder of
``moas-server --edit``: off unless the environment names a hook.

When ``MOAS_GUI_CONTROL_HOOK`` names an importable module, :func:`start_if_asked`
imports it and awaits its ``start(window)``, which returns something with an
``async close()`` the window awaits when it quits.  The journey tests name
``moas_gui.testing.control_hook`` (a person's clicks over a Unix socket);
the product itself names nothing, imports nothing from ``moas_gui.testing``
and, with the variable unset (every normal launch), does nothing at all.
"""

from __future__ import annotations

import importlib
import os
from typing import Any, Protocol, cast

ENVIRONMENT = "MOAS_GUI_CONTROL_HOOK"


class Hook(Protocol):
    """What a hook's ``start(window)`` returns."""

    async def close(self) -> None: ...


async def start_if_asked(window: Any) -> Hook | None:
    """Start the hook the environment names, if it names one."""
    name = os.environ.get(ENVIRONMENT, "").strip()
    if not name:
        return None
    try:
        module = importlib.import_module(name)
    except ImportError as exc:
        raise ImportError(f"{ENVIRONMENT}={name!r}: cannot import the hook: {exc}") from exc
    start = getattr(module, "start", None)
    if not callable(start):
        raise TypeError(f"{ENVIRONMENT}={name!r}: the module has no start(window)")
    return cast(Hook, await start(window))


__all__ = ["ENVIRONMENT", "Hook", "start_if_asked"]
