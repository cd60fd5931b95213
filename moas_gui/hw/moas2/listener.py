"""What a switch link tells the server: one collaborator, :class:`SwitchListener`.

The server's own listener (``running.py``) overrides what it wants to hear; every
method here does nothing.  :class:`Told` is the link's side: it calls the listener
safely (a failing call is logged with its traceback and the link carries on) and
tells :meth:`SwitchListener.seen` only what changed.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping

from ...engine.switchstate import SwitchState
from .actions import LinkStatus, Slots

log = logging.getLogger(__name__.rsplit(".", 1)[0] + ".link")


class SwitchListener:
    """What a switch link says as it happens (each a no-op unless overridden)."""

    def status(self, status: LinkStatus) -> None:
        """The link's status changed."""

    def transmitting(self, station: int, on: bool) -> None:
        """The box says ``station`` began (True) or ended (False) transmitting."""

    def box_error(self, text: str) -> None:
        """The box refused a command (``text`` names it)."""

    def adopt(self, stations: Mapping[int, Slots],
              transmitting: frozenset[int]) -> SwitchState | None:
        """A survey found these stations' antennas winning over the saved state (slots
        by station; ``transmitting``: those keyed then): the engine takes them, all at
        once, and this returns its wanted state then, which the box is reconciled to
        (None: the state the link was last given)."""
        return None

    def seen(self, station: int, slots: Slots) -> None:
        """The antennas the box reports in use for ``station`` changed: what it
        confirmed, as it landed (the antenna log's "in force")."""


class Told:
    """The link's side of its listener: safe calls, and ``seen`` told only anew."""

    __slots__ = ("_seen", "listener", "where")

    def __init__(self, listener: SwitchListener, where: str) -> None:
        self.listener = listener
        self.where = where
        self._seen: tuple[Slots, ...] | None = None
        """What ``seen`` was last told (None: nothing yet)."""

    def call(self, method: Callable[..., object], *args: object) -> object:
        """Call the listener; a failing call is logged, the link carries on (None)."""
        try:
            return method(*args)
        except Exception:  # whatever the server's code raises, the link carries on
            log.exception("%s: the listener's %s callback failed", self.where,
                          getattr(method, "__name__", method))
            return None

    def seen(self, seen: tuple[Slots, ...] | None) -> None:
        """``seen`` for each station whose antennas in use the box reports anew."""
        if seen == self._seen:
            return
        before, self._seen = self._seen, seen
        for station, slots in enumerate(seen or (), start=1):
            if before is None or before[station - 1] != slots:
                self.call(self.listener.seen, station, slots)


__all__ = ["SwitchListener", "Told"]
