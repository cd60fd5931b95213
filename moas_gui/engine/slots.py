"""Switch antenna slots: which of a switch's 63 antenna numbers stands for what.

The switch knows antennas only as numbers 0-62 (63 is "no antenna") and
checks conflicts and fast transitions between those numbers from its tables.
The configuration may name far more antennas (Multi-Multi 20 has 86), so the
server owns the mapping, per switch (ERRATA).  The rules:

* A *slot key* is an antenna *class* and an *owner*.  Antennas whose conflict
  row, fast row and shared system are identical form one class: to the switch
  they are one antenna with different relays, which is exactly how the
  firmware treats a 4-square's directions.  Antennas that two radios may
  legitimately share (``SharedTX``, members of a shared system, and every
  antenna when partners or sub receivers with their own port exist) are keyed
  per owning radio, so a waived conflict between two sharing radios never
  loosens the table for a third.
* A radio listening on its partner's receive antenna as its alternate (5.13)
  does so through a slot of its own (the key's third part), whose conflict
  with the partner's slot is the one waived: the radio's ordinary slot for that
  antenna keeps every conflict, so the table never lets it take the antenna
  for transmit or receive while the partner holds it.
* So does an alternate on an antenna radios may share (``SharedTX``, one that
  conflicts with a ``SharedTX`` antenna, a shared-capable system's member):
  the waiver that lets two interlocked radios hold a shared transmit antenna
  is between their ordinary slots, and never covers the alternate's slot, so
  the box refuses a receiver on an antenna another radio transmits on.  An
  alternate slot is waived only against another radio's receive-only use of
  the antenna with the sharing rules' permission, and the partner's receive
  slot under 5.13.
* When every key a switch could need fits in 63 slots, the mapping is fixed
  when the engine starts and the tables never change (apart from waivers).
* Otherwise slots are given to keys when they come into use.  A slot given up
  keeps its key and its table rows until it is *settled*: every port of that
  switch that was transmitting (or whose T/R state is unknown) when it was
  given up has since been seen receiving, and the switch's own inhibit and
  interrupt delays have passed.  Only a settled slot is given a new key, least
  recently used first.  So the switch never holds, or has pending, an antenna
  whose slot's table rows describe a different antenna.  A switch that never
  reports T/R is assumed settled after :data:`UNKNOWN_TR_SETTLE_S`.
* Table rows for a slot always come from the configuration; the switch link
  must send table changes before the antenna commands of the same state.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from moas_gui.config.model import RadioRef

from .errors import Unavailable
from .index import ConfigIndex, RadioKind
from .switchstate import NO_ANTENNA

SlotKey = tuple[int, RadioRef | None, bool]
"""(antenna class, owning radio or None, held as the partner's receive antenna)."""

SLOTS = 63
SETTLE_MARGIN_S = 0.5
UNKNOWN_TR_SETTLE_S = 30.0


class SlotClasses:
    """Antenna classes and per-radio keying for one configuration."""

    def __init__(self, ix: ConfigIndex) -> None:
        self.ix = ix
        shared_system_number = {s: n + 1 for n, s in enumerate(sorted(ix.systems.shared_capable))}
        self.system_number: dict[int, int] = {}
        needs_owner_everywhere = any(
            info.kind is RadioKind.SUB and info.ports for info in ix.radios.values()
        ) or any(info.radio.partner for info in ix.radios.values()) or any(
            f.name == "Partner" for f in ix.functions.values())
        self.per_radio: dict[int, bool] = {}
        classes: dict[tuple[object, ...], int] = {}
        self.klass: dict[int, int] = {}
        self.members: dict[int, list[int]] = {}
        for a in ix.ids:
            found = ix.systems.shared_system(ix.canon[a])
            system = found[0] if found else None
            if system is not None:
                self.system_number[a] = shared_system_number[system]
            own = bool(needs_owner_everywhere or ix.antennas[a].shared_tx or system is not None)
            self.per_radio[a] = own
            key: tuple[object, ...] = ((a,) if own else
                                       (ix.conflicts[a], ix.fast[a], ix.antennas[a].rx_only))
            k = classes.setdefault(key, len(classes))
            self.klass[a] = k
            self.members.setdefault(k, []).append(a)
        self.rep: dict[int, int] = {k: v[0] for k, v in self.members.items()}
        self.own_alt: dict[int, bool] = _own_alternates(ix, self.per_radio, self.system_number)
        """Antennas two radios may hold together with permission (a ``SharedTX`` antenna or
        one conflicting with it, a shared-capable system's member): as an alternate they
        have a slot of their own, so a waiver for the radio's own use never covers it."""
        self.any_owned = any(self.per_radio.values())
        """Whether any antenna is keyed per radio (only then can a conflict be waived)."""
        self.partners: dict[RadioRef, frozenset[RadioRef]] = _possible_partners(ix)
        """Every radio that may ever be partnered, with the radios it may be partnered with."""

    def key(self, antenna: int, owner: RadioRef, as_partner_alt: bool = False) -> SlotKey:
        if not self.per_radio[antenna]:
            return (self.klass[antenna], None, False)
        return (self.klass[antenna], owner, as_partner_alt)

    def alt_key(self, antenna: int, owner: RadioRef, partner_alt: bool = False) -> SlotKey:
        """The key of ``owner``'s alternate ``antenna``: the alternate slot (the key's third
        part) when it is the partner's receive antenna (5.13) or an antenna radios may share
        (:attr:`own_alt`), else the radio's ordinary slot."""
        return self.key(antenna, owner, partner_alt or self.own_alt[antenna])

    def conflict(self, k1: SlotKey, k2: SlotKey) -> bool:
        return self.ix.conflict(self.rep[k1[0]], self.rep[k2[0]])

    def fast(self, k1: SlotKey, k2: SlotKey) -> bool:
        return self.ix.is_fast(self.rep[k1[0]], self.rep[k2[0]])

    def fast_with_none(self, k: SlotKey) -> bool:
        """Whether a change between this key and "no antenna" may be fast.

        Closing a receive-only antenna's relays while transmitting on nothing
        is harmless; otherwise it is as fast as the antenna is with itself.
        """
        a = self.rep[k[0]]
        return self.ix.antennas[a].rx_only or self.ix.is_fast(a, a)

    def possible_keys(self, switch: int) -> list[SlotKey]:
        """Every key the ports of ``switch`` could ever need, in a stable order."""
        ix = self.ix
        keys: dict[SlotKey, None] = {}
        for ref in ix.order:
            info = ix.radios[ref]
            if not any(p[0] == switch for p in info.ports):
                continue
            antennas = set(info.antennas)
            if info.kind is RadioKind.MAIN:
                for extra in (info.sub, info.alt):
                    if extra is not None and extra in ix.radios and not ix.radios[extra].ports:
                        antennas |= set(ix.radios[extra].antennas)
                for rule in info.radio.alternate:
                    if rule.antenna is not None and rule.antenna in ix.antennas:
                        antennas.add(rule.antenna)
            for a in sorted(antennas):
                keys.setdefault(self.key(a, ref), None)
            for a in sorted(self._alternates(ref)):
                if self.own_alt[a]:
                    keys.setdefault(self.key(a, ref, True), None)
            for other in sorted(self.partners.get(ref, ())):
                oinfo = ix.radios.get(other)
                if oinfo is None:
                    continue
                for a in sorted(set(info.antennas) & set(oinfo.antennas)):
                    if self.per_radio[a] and not ix.antennas[a].tx_only:
                        keys.setdefault(self.key(a, ref, True), None)
        return sorted(keys, key=_order(self))


    def _alternates(self, ref: RadioRef) -> set[int]:
        """Antennas that can be ``ref``'s alternate other than its partner's (those come
        with the partner keys): its ``Alternate`` rules' and its alternate receiver's."""
        ix = self.ix
        info = ix.radios[ref]
        if info.kind is not RadioKind.MAIN:
            return set()
        out = {rule.antenna for rule in info.radio.alternate
               if rule.antenna is not None and rule.antenna in ix.antennas}
        if info.alt is not None and info.alt in ix.radios:
            out |= set(ix.radios[info.alt].antennas)
        return {a for a in out if not ix.antennas[a].tx_only}


def _own_alternates(ix: ConfigIndex, per_radio: Mapping[int, bool],
                    system_number: Mapping[int, int]) -> dict[int, bool]:
    """Per antenna: whether as an alternate it has a slot of its own (keyed per radio, and a
    shared-capable system's member or conflicting with a ``SharedTX`` antenna)."""
    shared_tx = [b for b in ix.ids if ix.antennas[b].shared_tx]
    return {a: per_radio[a] and (a in system_number or any(ix.conflict(a, b) for b in shared_tx))
            for a in ix.ids}


def _order(classes: SlotClasses) -> Callable[[SlotKey], tuple[int, RadioRef, bool]]:
    """Keys in a stable order: by class, then owner, the ordinary key before the alternate."""
    def key(k: SlotKey) -> tuple[int, RadioRef, bool]:
        return (classes.rep[k[0]], k[1] or RadioRef(0, 0), k[2])
    return key


def _possible_partners(ix: ConfigIndex) -> dict[RadioRef, frozenset[RadioRef]]:
    """Radios that may be partners (5.13): the ``Partner`` lists and the Partner functions."""
    pairs: dict[RadioRef, set[RadioRef]] = {}

    def add(a: RadioRef, b: RadioRef) -> None:
        if a != b and a in ix.radios and b in ix.radios:
            pairs.setdefault(a, set()).add(b)
            pairs.setdefault(b, set()).add(a)

    for info in ix.radios.values():
        for other in info.radio.partner:
            add(info.ref, other)
    for f in ix.functions.values():
        p = f.int_params
        if f.name == "Partner" and len(p) >= 4:
            add(RadioRef(p[0], p[1]), RadioRef(p[2], p[3]))
    return {k: frozenset(v) for k, v in pairs.items()}


@dataclass(frozen=True, slots=True)
class Release:
    time: float
    busy: frozenset[int]
    """Ports that were transmitting (or unknown) when the slot was given up."""
    unknown: bool = False


def _pair(a: int, b: int) -> tuple[int, int]:
    return (a, b) if a <= b else (b, a)


@dataclass(frozen=True, slots=True)
class SlotMap:
    """The slot mapping of one switch at one moment (replaced, never edited)."""

    switch: int
    static: bool
    key_slot: Mapping[SlotKey, int]
    slot_key: Mapping[int, SlotKey]
    in_use: frozenset[SlotKey] = frozenset()
    released: Mapping[int, Release] = field(default_factory=dict)
    conflicts: frozenset[tuple[int, int]] = frozenset()
    fast: frozenset[tuple[int, int]] = frozenset()
    systems: tuple[tuple[int, int], ...] = ()

    def slot(self, key: SlotKey | None) -> int:
        return NO_ANTENNA if key is None else self.key_slot[key]


def _tables(classes: SlotClasses, slot_key: Mapping[int, SlotKey]
            ) -> tuple[frozenset[tuple[int, int]], frozenset[tuple[int, int]],
                       tuple[tuple[int, int], ...]]:
    conflicts: set[tuple[int, int]] = set()
    fast: set[tuple[int, int]] = set()
    items = sorted(slot_key.items())
    for i, (s1, k1) in enumerate(items):
        for s2, k2 in items[i:]:
            if classes.conflict(k1, k2):
                conflicts.add(_pair(s1, s2))
            if classes.fast(k1, k2):
                fast.add(_pair(s1, s2))
        if classes.fast_with_none(k1):
            fast.add((s1, NO_ANTENNA))
    systems = tuple(sorted(
        (s, classes.system_number[classes.rep[k[0]]]) for s, k in slot_key.items()
        if classes.rep[k[0]] in classes.system_number))
    return frozenset(conflicts), frozenset(fast), systems


def initial_map(classes: SlotClasses, switch: int) -> SlotMap:
    keys = classes.possible_keys(switch)
    if len(keys) <= SLOTS:
        key_slot = {k: i for i, k in enumerate(keys)}
        slot_key = {i: k for k, i in key_slot.items()}
        c, f, s = _tables(classes, slot_key)
        return SlotMap(switch, True, key_slot, slot_key, conflicts=c, fast=f, systems=s)
    c, f, s = _tables(classes, {})
    return SlotMap(switch, False, {}, {}, conflicts=c, fast=f, systems=s)


def allocate(classes: SlotClasses, old: SlotMap, needed: Iterable[SlotKey], now: float,
             busy_ports: frozenset[int], unknown: bool, settle_s: float) -> SlotMap:
    """The mapping after this switch's ports need exactly ``needed``.

    ``busy_ports`` are the ports transmitting now (or of unknown state, then
    ``unknown`` is True).  Raises :class:`Unavailable` when no settled slot is
    left for a key that needs one.
    """
    want = frozenset(needed)
    if old.static:
        return old if want == old.in_use else _replace_use(old, want)
    if want == old.in_use:
        return old
    key_slot = dict(old.key_slot)
    slot_key = dict(old.slot_key)
    released = dict(old.released)
    for k in old.in_use - want:
        released[key_slot[k]] = Release(now, busy_ports, unknown)
    for k in want:
        if k in key_slot:
            released.pop(key_slot[k], None)
    changed: list[int] = []
    for k in sorted(want - key_slot.keys(), key=_order(classes)):
        slot = next((s for s in range(SLOTS) if s not in slot_key), None)
        if slot is None:
            ready = [(rel.time, s) for s, rel in released.items()
                     if _settled(rel, now, settle_s)]
            if not ready:
                raise Unavailable(
                    f"Switch {old.switch} has no free antenna slot right now: all 63 hold "
                    "antennas in use or just given up by a transmitting station; try again "
                    "after the transmission")
            _, slot = min(ready)
            del key_slot[slot_key[slot]]
            del released[slot]
        key_slot[k] = slot
        slot_key[slot] = k
        changed.append(slot)
    conflicts, fast, systems = old.conflicts, old.fast, old.systems
    if changed:
        conflicts, fast, systems = _retable(classes, old, slot_key, changed)
    return SlotMap(old.switch, False, key_slot, slot_key, want, released, conflicts, fast,
                   systems)


def _replace_use(old: SlotMap, want: frozenset[SlotKey]) -> SlotMap:
    return SlotMap(old.switch, old.static, old.key_slot, old.slot_key, want, old.released,
                   old.conflicts, old.fast, old.systems)


def _settled(rel: Release, now: float, settle_s: float) -> bool:
    if now < rel.time + settle_s:
        return False
    if not rel.busy:
        return True
    return rel.unknown and now >= rel.time + UNKNOWN_TR_SETTLE_S


def _retable(classes: SlotClasses, old: SlotMap, slot_key: Mapping[int, SlotKey],
             changed: list[int]) -> tuple[frozenset[tuple[int, int]],
                                          frozenset[tuple[int, int]], tuple[tuple[int, int], ...]]:
    touched = set(changed)
    conflicts = {p for p in old.conflicts if p[0] not in touched and p[1] not in touched}
    fast = {p for p in old.fast if p[0] not in touched and p[1] not in touched}
    for s1 in changed:
        k1 = slot_key[s1]
        for s2, k2 in slot_key.items():
            if classes.conflict(k1, k2):
                conflicts.add(_pair(s1, s2))
            if classes.fast(k1, k2):
                fast.add(_pair(s1, s2))
        if classes.fast_with_none(k1):
            fast.add((s1, NO_ANTENNA))
    systems = tuple(sorted(
        (s, classes.system_number[classes.rep[k[0]]]) for s, k in slot_key.items()
        if classes.rep[k[0]] in classes.system_number))
    return frozenset(conflicts), frozenset(fast), systems


def receive_seen(old: SlotMap, port: int) -> SlotMap:
    """A port of this switch reported receive: it no longer holds any released slot."""
    if not any(port in rel.busy for rel in old.released.values()):
        return old
    released = {s: Release(rel.time, rel.busy - {port}, rel.unknown) if port in rel.busy else rel
                for s, rel in old.released.items()}
    return SlotMap(old.switch, old.static, old.key_slot, old.slot_key, old.in_use, released,
                   old.conflicts, old.fast, old.systems)


__all__ = [
    "SETTLE_MARGIN_S",
    "SLOTS",
    "UNKNOWN_TR_SETTLE_S",
    "Release",
    "SlotClasses",
    "SlotKey",
    "SlotMap",
    "allocate",
    "initial_map",
    "receive_seen",
]
