"""Everything the engine looks up, computed once per configuration.

The per-frequency-change path must not scan the configuration, so every
question it asks is answered here by a dict or a short tuple: which antennas a
radio can use and through which relays in which range, conflicts and fast
pairs (made symmetric), alternate paths, components, systems, ports.

Alternate paths (5.8): antennas that list each other in ``Alternate`` are one
*path group*; its *canonical* member (the one listed in a system, else the
lowest ID) names the physical antenna on buttons and in components.

Radios come in three kinds: the configured radios (MAIN), their sub receivers
(SUB, ``SubReceiver``) and their alternate receivers (ALT, ``AltReceiver``: a
radio number whose selected antenna becomes the main radio's alternate receive
antenna).  SUB and ALT radios only receive.
"""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum

from moas_gui.config.model import Antenna, Config, Function, Radio, RadioRef, StationRelays, Switch

from .ranges import INF, RangeRelays, Segment, bound, merge_segments, range_relays_at
from .systems import Link, SystemIndex, build_system_index


class RadioKind(str, Enum):
    """What a configured radio is: a main radio, the sub receiver of one, or the other path
    (Alternate) of one."""

    MAIN = "main"
    SUB = "sub"
    ALT = "alt"


@dataclass(frozen=True, slots=True)
class IndexedRadio:
    """A radio as the engine looks it up: its kind, the radios it goes with, its
    switch ports, and the paths and frequency segments of the antennas it can use."""

    ref: RadioRef
    kind: RadioKind
    radio: Radio
    main: RadioRef | None
    """For SUB and ALT radios: the radio they belong to."""
    sub: RadioRef | None
    alt: RadioRef | None
    ports: tuple[tuple[int, int], ...]
    """(switch id, port 1-6) pairs of this radio's own T/R and inhibit lines."""
    paths: Mapping[int, tuple[RangeRelays, ...]]
    segments: Mapping[int, tuple[Segment, ...]]
    bands: tuple[Segment, ...]
    """Every segment of every usable antenna, narrowest first."""
    antennas: tuple[int, ...]
    """Antennas this radio has relays for, by ID."""
    points: tuple[float, ...] = ()
    """Every range boundary, sorted: between two of them the covering antennas do not change."""
    _covering: dict[tuple[int, bool], tuple[int, ...]] = field(default_factory=dict,
                                                                 compare=False, repr=False)

    def covering(self, khz: float | None) -> tuple[int, ...]:
        """Antennas (by ID) with a range holding ``khz`` for this radio; cached per interval."""
        if khz is None:
            key = (-1, True)
        else:
            i = bisect_left(self.points, khz)
            key = (i, i < len(self.points) and self.points[i] == khz)
        found = self._covering.get(key)
        if found is None:
            found = tuple(a for a in self.antennas if range_relays_at(self.paths[a], khz) is not None)
            self._covering[key] = found
        return found

    @property
    def receive_only(self) -> bool:
        return self.kind is not RadioKind.MAIN

    def path(self, antenna: int, khz: float | None) -> RangeRelays | None:
        return range_relays_at(self.paths.get(antenna, ()), khz)

    def covers(self, antenna: int, khz: float | None) -> bool:
        return range_relays_at(self.paths.get(antenna, ()), khz) is not None

    def band(self, khz: float | None) -> Segment | None:
        if khz is None:
            return None
        for seg in self.bands:
            if seg[0] <= khz <= seg[1]:
                return seg
        return None

    def segment(self, antenna: int, khz: float | None) -> Segment | None:
        if khz is None:
            return None
        for seg in self.segments.get(antenna, ()):
            if seg[0] <= khz <= seg[1]:
                return seg
        return None

    def used_segment(self, antenna: int, khz: float | None) -> Segment | None:
        """The segment of ``antenna`` a radio at ``khz`` was using: the one holding ``khz``,
        else the nearest one (the radio tuned beyond its edge, appendix F step 2)."""
        if khz is None:
            return None
        found = self.segment(antenna, khz)
        if found is not None:
            return found
        best: Segment | None = None
        best_d = float("inf")
        for seg in self.segments.get(antenna, ()):
            d = max(seg[0] - khz, khz - seg[1], 0.0)
            if d < best_d:
                best, best_d = seg, d
        return best


def _most_specific(entries: tuple[StationRelays, ...], station: int, radio: int,
                   exact_radio: bool = False) -> StationRelays | None:
    best: StationRelays | None = None
    best_score = -1
    for e in entries:
        if not e.applies_to(station, radio):
            continue
        if exact_radio and e.radio != radio:
            continue
        score = (e.station is not None) + (e.radio is not None)
        if score > best_score:
            best, best_score = e, score
    return best


def _paths_for(antenna: Antenna, station: int, radio: int, fallback_radio: int | None
               ) -> tuple[RangeRelays, ...]:
    out: list[RangeRelays] = []
    for cr in antenna.control:
        entry = None
        if fallback_radio is not None:
            entry = _most_specific(cr.stations, station, radio, exact_radio=True)
            if entry is None:
                entry = _most_specific(cr.stations, station, fallback_radio)
        else:
            entry = _most_specific(cr.stations, station, radio)
        if entry is None:
            continue
        relays = frozenset(entry.relays)
        out.append(RangeRelays(
            bound(cr.range.lower, -INF), bound(cr.range.upper, INF), relays,
            frozenset(entry.rx_relays) if entry.rx_relays is not None else relays,
            frozenset(entry.persistent_relays), entry.radio_rx_antenna,
        ))
    out.sort(key=lambda p: (p.lower, p.upper))
    return tuple(out)


def _symmetric(antennas: tuple[Antenna, ...], attr: str) -> dict[int, frozenset[int]]:
    ids = {a.id for a in antennas}
    sets: dict[int, set[int]] = {a.id: set() for a in antennas}
    for a in antennas:
        for b in getattr(a, attr):
            if b in ids:
                sets[a.id].add(b)
                sets[b].add(a.id)
    return {k: frozenset(v) for k, v in sets.items()}


class ConfigIndex:
    """Lookups for one configuration (built once; never changes)."""

    def __init__(self, config: Config) -> None:
        self.config = config
        self.antennas: dict[int, Antenna] = {a.id: a for a in config.antennas}
        self.ids: tuple[int, ...] = tuple(sorted(self.antennas))
        self.conflicts = _symmetric(config.antennas, "conflicts")
        self.fast = _symmetric(config.antennas, "fast")
        self._build_path_groups(config)
        self._physical_conflicts()
        self.systems: SystemIndex = build_system_index(config.systems, self.canon, self.comps)
        self.shared_members: frozenset[int] = frozenset(
            a for a in self.canon if (m := self.systems.parent(self.canon[a])) is not None
            and m.link is Link.SHARED)
        """Antennas that are shared members of a system (5.10), whatever its mode now."""
        self.switches: dict[int, Switch] = {s.id: s for s in config.switches}
        self.switch_ids: tuple[int, ...] = tuple(sorted(self.switches))
        self.functions: dict[int, Function] = {f.id: f for f in config.functions}
        self._build_radios(config)

    # -- antennas -------------------------------------------------------------------------
    def _build_path_groups(self, config: Config) -> None:
        parent = {a: a for a in self.antennas}

        def find(a: int) -> int:
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        for ant in config.antennas:
            for b in ant.alternate:
                if b in parent:
                    parent[find(ant.id)] = find(b)
        groups: dict[int, list[int]] = {}
        for aid in self.antennas:
            groups.setdefault(find(aid), []).append(aid)
        in_system: set[int] = set()
        for s in config.systems:
            in_system.update(s.member_antennas)
        self.canon: dict[int, int] = {}
        self.group: dict[int, tuple[int, ...]] = {}
        for members in groups.values():
            members.sort()
            listed = [m for m in members if m in in_system]
            head = listed[0] if listed else members[0]
            ordered = (head, *[m for m in members if m != head])
            for m in members:
                self.canon[m] = head
                self.group[m] = ordered
        self.comps: dict[int, frozenset[int]] = {}
        for ant in config.antennas:
            parts = ant.in_use or (ant.id,)
            self.comps[ant.id] = frozenset(self.canon[c] for c in parts if c in self.canon)
        combos: dict[frozenset[int], list[int]] = {}
        for aid in self.ids:
            combos.setdefault(self.comps[aid], []).append(aid)
        self.combos: dict[frozenset[int], tuple[int, ...]] = {
            k: tuple(sorted(v, key=lambda i: (self.canon[i] != i, i))) for k, v in combos.items()
        }

    def _physical_conflicts(self) -> None:
        """Two selections using one physical antenna conflict like the antenna with itself.

        5.8: "Since the two paths to the 15 meter antenna use different relays the MOAS
        server considers them to be different antennas"; they are still one antenna, so a
        path, another path of it, and a combination using it (``InUse``, 5.3) conflict when
        any path of it lists itself in ``Conflicts`` (one radio at a time).  An antenna that
        does not conflict with itself may be used by several radios through any path.
        """
        exclusive = {c for c, members in self.group.items() if c == members[0]
                     and any(m in self.conflicts[m] for m in members)}
        if not exclusive:
            return
        users: dict[int, list[int]] = {}
        for a in self.ids:
            for c in self.comps[a] & exclusive:
                users.setdefault(c, []).append(a)
        extra: dict[int, set[int]] = {}
        for found in users.values():
            for a in found:
                for b in found:
                    if b not in self.conflicts[a]:
                        extra.setdefault(a, set()).add(b)
        for a, more in extra.items():
            self.conflicts[a] = self.conflicts[a] | more

    def conflict(self, a: int, b: int) -> bool:
        return b in self.conflicts.get(a, ())

    def is_fast(self, a: int, b: int) -> bool:
        return b in self.fast.get(a, ())

    def can_transmit(self, a: int) -> bool:
        return not self.antennas[a].rx_only

    def can_receive(self, a: int) -> bool:
        return not self.antennas[a].tx_only

    def name(self, a: int | None) -> str:
        if a is None:
            return "none"
        ant = self.antennas.get(a)
        return f"Antenna {a}" if ant is None else f"{ant.title}"

    def describe(self, a: int) -> str:
        ant = self.antennas.get(a)
        if ant is None:
            return f"Antenna {a}"
        return f"Antenna {a} ({ant.label})"

    # -- radios ---------------------------------------------------------------------------
    def _build_radios(self, config: Config) -> None:
        infos = self._index_radios(config)
        self.radios: dict[RadioRef, IndexedRadio] = infos
        self.mains: tuple[RadioRef, ...] = tuple(sorted(r for r in infos
                                                        if infos[r].kind is RadioKind.MAIN))
        self.order: tuple[RadioRef, ...] = (
            self.mains
            + tuple(sorted(r for r in infos if infos[r].kind is RadioKind.SUB))
            + tuple(sorted(r for r in infos if infos[r].kind is RadioKind.ALT)))
        self._build_radio_ports(infos)
        self.all_switches = frozenset(self.switch_ids)
        self.any_shared_tx = any(a.shared_tx for a in self.antennas.values())
        """Whether conflicts may be permitted by an interlock (5.12), which can change."""
        self.radio_rx_inputs = any(p.radio_rx_antenna for info in infos.values()
                                   for paths in info.paths.values() for p in paths)
        """Whether any antenna is wired to a radio's RX-antenna input (6.4)."""
        self._build_interrupt_ports(infos)

    def _index_radios(self, config: Config) -> dict[RadioRef, IndexedRadio]:
        """Every radio the file names, as a main radio or as the sub or alternate receiver
        of one (6.10): a receiver named by a main radio's ``SubReceiver`` or
        ``AltReceiver`` is that radio's receiver, whether or not it has an entry of its
        own; one whose main radio is not indexed is left out."""
        single = self.switch_ids[0] if len(self.switch_ids) == 1 else None
        configured = {r.ref: r for r in config.radios}
        subs: dict[RadioRef, RadioRef] = {}
        alts: dict[RadioRef, RadioRef] = {}
        for r in config.radios:
            sub, alt = _receivers(r)
            if sub is not None:
                subs[sub] = r.ref
            if alt is not None:
                alts[alt] = r.ref
        infos: dict[RadioRef, IndexedRadio] = {}
        mains = [r for r in config.radios if r.ref not in subs and r.ref not in alts]
        for r in mains:
            sub, alt = _receivers(r)
            infos[r.ref] = self._radio_info(r, RadioKind.MAIN, None, sub, alt, single)
        for kind, receivers in ((RadioKind.SUB, subs), (RadioKind.ALT, alts)):
            for ref, main in sorted(receivers.items()):
                if main in infos and ref not in infos:
                    radio = configured.get(ref, Radio(ref.station, ref.radio))
                    infos[ref] = self._radio_info(radio, kind, main, None, None, single)
        return infos

    def _build_radio_ports(self, infos: dict[RadioRef, IndexedRadio]) -> None:
        """Which radio each switch port belongs to (the first in radio order), the radios
        on each switch, each radio's ports on a switch and the switches it is on."""
        self.port_radio: dict[tuple[int, int], RadioRef] = {}
        for ref in self.order:
            for sp in infos[ref].ports:
                self.port_radio.setdefault(sp, ref)
        self.switch_radios: dict[int, tuple[RadioRef, ...]] = {
            switch_id: tuple(ref for ref in self.order if any(p[0] == switch_id for p in infos[ref].ports))
            for switch_id in self.switch_ids
        }
        self.switch_ports: dict[tuple[RadioRef, int], tuple[int, ...]] = {
            (ref, switch_id): tuple(p for sw, p in infos[ref].ports if sw == switch_id)
            for switch_id in self.switch_ids for ref in self.switch_radios[switch_id]
        }
        self.radio_switches: dict[RadioRef, frozenset[int]] = {
            ref: frozenset(switch_id for switch_id, _p in infos[ref].ports) for ref in self.order
        }

    def _build_interrupt_ports(self, infos: dict[RadioRef, IndexedRadio]) -> None:
        """Interrupt mode per switch: the ports of its main radios marked ``Interrupt`` and
        the longest delay among the switch's own and those radios' (5.14)."""
        self.interrupt: dict[int, tuple[frozenset[int], int]] = {}
        for switch_id in self.switch_ids:
            ports: set[int] = set()
            delay = self.switches[switch_id].interrupt_mode_delay
            for ref in self.switch_radios[switch_id]:
                info = infos[ref]
                if info.kind is RadioKind.MAIN and info.radio.interrupt:
                    ports.update(self.switch_ports[(ref, switch_id)])
                    if info.radio.interrupt_mode_delay is not None:
                        delay = max(delay, info.radio.interrupt_mode_delay)
            self.interrupt[switch_id] = (frozenset(ports), delay)

    def _radio_info(self, radio: Radio, kind: RadioKind, main: RadioRef | None,
                    sub: RadioRef | None, alt: RadioRef | None, single: int | None
                    ) -> IndexedRadio:
        ports: list[tuple[int, int]] = []
        if kind is not RadioKind.ALT:
            for sp in radio.switches:
                switch_id = sp.switch or single
                if switch_id is not None and switch_id in self.switches and 1 <= sp.port <= 6:
                    ports.append((switch_id, sp.port))
        fallback = main.radio if kind is RadioKind.ALT and main is not None else None
        paths: dict[int, tuple[RangeRelays, ...]] = {}
        segments: dict[int, tuple[Segment, ...]] = {}
        for a in self.ids:
            p = _paths_for(self.antennas[a], radio.station, radio.radio, fallback)
            if p:
                paths[a] = p
                segments[a] = merge_segments((x.lower, x.upper) for x in p)
        bands = sorted({s for segs in segments.values() for s in segs},
                       key=lambda s: (s[1] - s[0], s[0]))
        points = sorted({v for ps in paths.values() for p in ps for v in (p.lower, p.upper)})
        return IndexedRadio(radio.ref, kind, radio, main, sub, alt, tuple(ports), paths, segments,
                         tuple(bands), tuple(sorted(paths)), tuple(points))

    def sub_flag(self, sub: RadioRef, name: str) -> bool:
        """``PersistSubReceiver`` or ``UseMainFreq`` (``name`` is the model's attribute) for
        the sub receiver ``sub``: 6.10's radio table lists them with ``SubReceiver`` on the
        main radio's entry; a file that puts them on the sub receiver's own entry is honoured
        too (``--check`` says where they belong)."""
        info = self.radios.get(sub)
        if info is None or info.kind is not RadioKind.SUB or info.main is None:
            return False
        main = self.radios[info.main].radio
        return bool(getattr(main, name) or getattr(info.radio, name))

    def radio_info(self, ref: RadioRef) -> IndexedRadio | None:
        return self.radios.get(ref)


def _receivers(radio: Radio) -> tuple[RadioRef | None, RadioRef | None]:
    """The sub and alternate receivers a radio's entry names (6.10); naming the radio
    itself names none."""
    sub = (RadioRef(radio.station, radio.sub_receiver)
           if radio.sub_receiver is not None and radio.sub_receiver != radio.radio else None)
    alt = (RadioRef(radio.station, radio.alt_receiver)
           if radio.alt_receiver is not None and radio.alt_receiver != radio.radio else None)
    return sub, alt


__all__ = ["ConfigIndex", "IndexedRadio", "RadioKind"]
