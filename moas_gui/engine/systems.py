"""Antenna systems (5.3, 5.16, 6.5): what a button press selects.

A radio's selection is always one configured antenna.  Its *components* are
the single antennas it is made of (its ``InUse`` list, or itself), named by
their canonical path (see :mod:`.index`).  A press works on components:

* an additive member toggles its components in or out;
* an exclusive (or shared) member replaces everything its system holds; pressed
  again while selected, it takes its system out if that system is additive in
  its parent (the Multi-Multi 20 Europe stack rule), otherwise nothing changes;
* walking up the tree, an additive link keeps the parent's other parts and an
  exclusive link drops them; anything outside the top system is dropped;
* a double-click (``exclusive=True``) selects the pressed antenna's components
  alone.

The engine then looks up the antenna whose components are exactly the result.
An empty result means the press would leave nothing selected: it is ignored.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum

from moas_gui.config.model import System


class Link(str, Enum):
    ADDITIVE = "additive"
    EXCLUSIVE = "exclusive"
    SHARED = "shared"


@dataclass(frozen=True, slots=True)
class Membership:
    """The system an antenna or a system is listed in, and how (its link)."""

    system: int
    link: Link


@dataclass(frozen=True, slots=True)
class SystemIndex:
    """Where each antenna and system sits in the station's systems."""

    antenna_parent: Mapping[int, Membership]
    """Canonical antenna id -> the system it is listed in."""
    system_parent: Mapping[int, Membership]
    leaves: Mapping[int, frozenset[int]]
    """System id -> every component its members are made of."""
    top: Mapping[int, int]
    """Canonical antenna id -> the outermost system holding it."""
    shared_capable: frozenset[int]
    """Systems with shared antennas (the Share function's subject)."""
    has_plain_members: Mapping[int, bool]
    """For shared-capable systems: whether they also have additive/exclusive members."""
    initial_shared: Mapping[int, bool]

    def parent(self, antenna: int) -> Membership | None:
        return self.antenna_parent.get(antenna)

    def shared_system(self, antenna: int) -> tuple[int, bool] | None:
        """(system, is a shared member) when ``antenna`` sits directly in a shared-capable system."""
        m = self.antenna_parent.get(antenna)
        if m is None or m.system not in self.shared_capable:
            return None
        return m.system, m.link is Link.SHARED

    def usable(self, antenna: int, shared: Mapping[int, bool]) -> bool:
        """Whether the system's sharing mode lets ``antenna`` be used now (6.6.5).

        In shared mode only the shared members of a system can be used; out of it
        only the others, unless the system has nothing but shared members.
        """
        found = self.shared_system(antenna)
        if found is None:
            return True
        system, is_shared = found
        on = shared.get(system, False)
        if is_shared:
            return on or not self.has_plain_members[system]
        return not on


def build_system_index(
    systems: tuple[System, ...],
    canon: Mapping[int, int],
    comps: Mapping[int, frozenset[int]],
) -> SystemIndex:
    antenna_parent, system_parent = _parents(systems, canon)
    leaves = _leaves(systems, comps)
    top = {a: _outermost(system_parent, m.system) for a, m in antenna_parent.items()}
    shared_capable = frozenset(s.id for s in systems if s.shared_antennas)
    return SystemIndex(
        antenna_parent=antenna_parent,
        system_parent=system_parent,
        leaves=leaves,
        top=top,
        shared_capable=shared_capable,
        has_plain_members={s.id: bool(s.additive_antennas or s.exclusive_antennas
                                      or s.additive_systems or s.exclusive_systems)
                           for s in systems if s.id in shared_capable},
        initial_shared={s.id: s.shared for s in systems if s.id in shared_capable},
    )


def _parents(systems: tuple[System, ...], canon: Mapping[int, int]
             ) -> tuple[dict[int, Membership], dict[int, Membership]]:
    """The system each antenna and each system belongs to, and how (additive, exclusive,
    shared); the first system naming one keeps it.  A system inside a shared system is
    one of its exclusive members; a system naming itself or an unknown one is ignored."""
    antenna_parent: dict[int, Membership] = {}
    system_parent: dict[int, Membership] = {}
    known = {s.id for s in systems}
    for s in systems:
        for link, ids in ((Link.ADDITIVE, s.additive_antennas),
                          (Link.EXCLUSIVE, s.exclusive_antennas),
                          (Link.SHARED, s.shared_antennas)):
            for a in ids:
                if a in canon:
                    antenna_parent.setdefault(canon[a], Membership(s.id, link))
        for link, ids in ((Link.ADDITIVE, s.additive_systems),
                          (Link.EXCLUSIVE, s.exclusive_systems),
                          (Link.EXCLUSIVE, s.shared_systems)):
            for sub in ids:
                if sub in known and sub != s.id:
                    system_parent.setdefault(sub, Membership(s.id, link))
    return antenna_parent, system_parent


def _leaves(systems: tuple[System, ...], comps: Mapping[int, frozenset[int]]
            ) -> dict[int, frozenset[int]]:
    """Per system, the single antennas (components) of all its members, through the
    systems inside it (a loop of systems is followed once)."""
    by_id = {s.id: s for s in systems}
    leaves: dict[int, frozenset[int]] = {}

    def collect(sid: int, seen: frozenset[int]) -> frozenset[int]:
        if sid in leaves:
            return leaves[sid]
        s = by_id[sid]
        out: set[int] = set()
        for a in s.member_antennas:
            if a in comps:
                out |= comps[a]
        for sub in s.member_systems:
            if sub in by_id and sub not in seen:
                out |= collect(sub, seen | {sub})
        leaves[sid] = frozenset(out)
        return leaves[sid]

    for s in systems:
        collect(s.id, frozenset({s.id}))
    return leaves


def _outermost(system_parent: Mapping[int, Membership], sid: int) -> int:
    """The outermost system holding system ``sid`` (itself when none does)."""
    seen = {sid}
    while sid in system_parent and system_parent[sid].system not in seen:
        sid = system_parent[sid].system
        seen.add(sid)
    return sid


def _has_additive_ancestor(sx: SystemIndex, system: int) -> bool:
    seen = {system}
    while system in sx.system_parent:
        m = sx.system_parent[system]
        if m.link is Link.ADDITIVE:
            return True
        system = m.system
        if system in seen:
            return False
        seen.add(system)
    return False


def press(
    sx: SystemIndex,
    comps: Mapping[int, frozenset[int]],
    current: frozenset[int],
    pressed: int,
    exclusive: bool,
) -> frozenset[int]:
    """The components selected after pressing canonical antenna ``pressed``.

    ``current`` holds the components selected now (empty for none).  The result
    may be empty: the press would leave nothing selected.
    """
    own = comps[pressed]
    membership = sx.antenna_parent.get(pressed)
    if exclusive or membership is None:
        return own
    system = membership.system
    part = current & sx.leaves.get(system, frozenset())
    if membership.link is Link.ADDITIVE:
        new_part = part - own if own <= current else part | own
    elif part == own and _has_additive_ancestor(sx, system):
        new_part = frozenset()
    else:
        new_part = own
    node = system
    seen = {node}
    while node in sx.system_parent:
        up = sx.system_parent[node]
        if up.link is Link.ADDITIVE:
            keep = (current & sx.leaves.get(up.system, frozenset())) - sx.leaves.get(node, frozenset())
            new_part = keep | new_part
        node = up.system
        if node in seen:
            break
        seen.add(node)
    return new_part


def is_selected(
    sx: SystemIndex,
    comps: Mapping[int, frozenset[int]],
    current: frozenset[int],
    button: int,
) -> bool:
    """Whether canonical antenna ``button`` shows as selected for components ``current``."""
    own = comps[button]
    if not current:
        return False
    membership = sx.antenna_parent.get(button)
    if membership is None:
        return current == own
    if membership.link is Link.ADDITIVE:
        return own <= current
    return current & sx.leaves.get(membership.system, frozenset()) == own


__all__ = ["Link", "Membership", "SystemIndex", "build_system_index", "is_selected", "press"]
