"""What one engine operation changed, for the switch links and the clients.

Every operation of :class:`~moas_gui.engine.Engine` returns a :class:`Changes`.
A window or a network session looks at it and redraws or sends only what it
names; the switch links apply the new :class:`SwitchState` of each switch listed.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from moas_gui.config.model import RadioRef

from .switchstate import SwitchState

_EMPTY: Mapping[int, SwitchState] = MappingProxyType({})


@dataclass(frozen=True, slots=True)
class Changes:
    """The outcome of one operation.

    ``radios``: radios whose view (frequency, antennas, transmit or inhibit state,
    note) changed.  ``switches``: the complete new wanted state of every switch
    whose wanted state changed.  ``layouts``: True when any layout's buttons may
    show something different now.  ``log``: sentences for the operator's log at
    Info level.  ``details``: sentences for the log at Debug level (the antennas each
    decision passed over, and why).
    """

    radios: frozenset[RadioRef] = frozenset()
    switches: Mapping[int, SwitchState] = field(default_factory=lambda: _EMPTY)
    layouts: bool = False
    log: tuple[str, ...] = ()
    details: tuple[str, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.radios or self.switches or self.layouts or self.log)

    def merge(self, later: Changes) -> Changes:
        """These changes followed by ``later`` (later switch states win)."""
        switches = dict(self.switches)
        switches.update(later.switches)
        return Changes(
            self.radios | later.radios,
            MappingProxyType(switches),
            self.layouts or later.layouts,
            self.log + later.log,
            self.details + later.details,
        )


def make_changes(
    radios: Iterable[RadioRef] = (),
    switches: Mapping[int, SwitchState] | None = None,
    layouts: bool = False,
    log: Iterable[str] = (),
) -> Changes:
    """A :class:`Changes` from plain values (the mapping is frozen)."""
    return Changes(
        frozenset(radios),
        MappingProxyType(dict(switches)) if switches else _EMPTY,
        layouts,
        tuple(log),
    )


NO_CHANGES = Changes()

__all__ = ["NO_CHANGES", "Changes", "make_changes"]
