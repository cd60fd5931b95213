"""From the engine's state to what every switch must hold (:class:`SwitchState`).

Per switch port of a radio: the transmit, receive and alternate antennas as
slots with the relays of this switch, persistent relays when the other
antenna belongs to another group (5.7), a sub receiver without a port of its
own riding on its main radio's receive relays (and transmit relays with
``PersistSubReceiver``), and the extra relays closed while transmitting.
Relays on a switch where the radio has no port go to that switch's station 0
(no hot-switch protection there: the manual's chapter 8 advice).

Station 0 relays that belong to a transmitting radio (its Relay functions,
its relays on a switch without its port), and the extra relays of a
transmitting port, keep their previous value until that radio receives: the
engine never changes a transmitting radio's RF path behind the switch's back.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from moas_gui.config.model import RadioRef
from moas_gui.config.relays import local_relay, local_relays, relay_exists, switch_of_relay

from .functions import relay_contributions
from .index import ConfigIndex, IndexedRadio, RadioKind
from .ranges import RangeRelays, nearest_range_relays, range_relays_at
from .rules import inhibits, permitted, related
from .slots import SlotClasses, SlotKey, SlotMap
from .state import RadioState, State
from .switchstate import NO_ANTENNA, STATIONS, StationAntennas, SwitchState


@dataclass(frozen=True, slots=True)
class PortAntennas:
    """What one radio puts on its ports: antennas and global relay numbers."""

    tx: int | None
    tx_relays: frozenset[int]
    rx: int | None
    rx_relays: frozenset[int]
    alt: int | None
    alt_relays: frozenset[int]
    extra: frozenset[int]
    alt_partner: bool = False
    """The alternate is the partner's receive antenna (5.13): it has a slot of its own."""


def _path(paths: tuple[RangeRelays, ...], khz: float | None) -> RangeRelays | None:
    return range_relays_at(paths, khz) or nearest_range_relays(paths, khz)


def _group(ix: ConfigIndex, antenna: int) -> object:
    canon = ix.canon[antenna]
    return ix.systems.top.get(canon, ("antenna", canon))


def radio_relays(ix: ConfigIndex, st: State, ref: RadioRef,
                 alt: tuple[int | None, frozenset[RadioRef]] | None,
                 extras: Mapping[RadioRef, frozenset[int]]) -> PortAntennas:
    info = ix.radios[ref]
    rs = st.radios[ref]
    tx_relays, rx_relays = _own_relays(ix, info, rs)
    if info.kind is RadioKind.SUB and info.ports:
        if not ix.sub_flag(ref, "persist_sub_receiver"):
            return PortAntennas(None, frozenset(), rs.rx, rx_relays, None, frozenset(),
                                frozenset())
        return PortAntennas(rs.rx, rx_relays, rs.rx, rx_relays, None, frozenset(), frozenset())
    rx_antenna = rs.rx
    riding = _riding_sub_receiver(ix, st, info)
    if riding is not None:
        sub_rx, sub_relays, persist = riding
        if rx_antenna is None:
            # the main radio receives on nothing: the port's receive antenna is the
            # sub receiver's, so its relays are not dropped with the empty slot
            rx_antenna = sub_rx
        rx_relays = rx_relays | sub_relays
        if persist:
            tx_relays = tx_relays | sub_relays
    alt_antenna, alt_relays = _alternate_relays(ix, st, info, rs,
                                                alt[0] if alt else None)
    partner = st.partners.get(ref)
    # 5.13's partner receive antenna: only when the partner receives and transmits on
    # different antennas (on its one antenna it transmits there: never a listener's)
    alt_partner = (alt_antenna is not None and partner is not None and partner in st.radios
                   and st.radios[partner].rx == alt_antenna
                   and st.radios[partner].tx != alt_antenna)
    return PortAntennas(rs.tx, tx_relays, rx_antenna, rx_relays, alt_antenna, alt_relays,
                        extras.get(ref, frozenset()), alt_partner)


def _own_relays(ix: ConfigIndex, info: IndexedRadio, rs: RadioState
                ) -> tuple[frozenset[int], frozenset[int]]:
    """The relays of a radio's own transmit and receive paths at its frequencies (the
    transmit path at the split frequency when there is one); when the two antennas are
    in different groups each side also holds the other's persistent relays (5.7)."""
    tx_path = rx_path = None
    if rs.tx is not None:
        paths = info.paths.get(rs.tx, ())
        tx_path = range_relays_at(paths, rs.tx_freq) or _path(paths, rs.khz)
    if rs.rx is not None:
        rx_path = _path(info.paths.get(rs.rx, ()), rs.khz)
    tx_relays = tx_path.relays if tx_path else frozenset()
    rx_relays = rx_path.rx_relays if rx_path else frozenset()
    if (rs.tx is not None and rs.rx is not None and tx_path and rx_path
            and _group(ix, rs.tx) != _group(ix, rs.rx)):
        tx_relays = tx_relays | rx_path.persistent
        rx_relays = rx_relays | tx_path.persistent
    return tx_relays, rx_relays


def _riding_sub_receiver(ix: ConfigIndex, st: State, info: IndexedRadio
                         ) -> tuple[int, frozenset[int], bool] | None:
    """A main radio's sub receiver without a port of its own rides on the main radio's
    port: its receive antenna, that antenna's receive relays, and whether they are held
    while transmitting too (``PersistSubReceiver``).  None when there is nothing to add."""
    sub = info.sub
    if sub is None or sub not in ix.radios or ix.radios[sub].ports:
        return None
    ss = st.radios[sub]
    if ss.rx is None:
        return None
    p = _path(ix.radios[sub].paths.get(ss.rx, ()), ss.khz)
    if p is None:
        return None
    return ss.rx, p.rx_relays, ix.sub_flag(sub, "persist_sub_receiver")


def _alternate_relays(ix: ConfigIndex, st: State, info: IndexedRadio, rs: RadioState,
                      alt_antenna: int | None) -> tuple[int | None, frozenset[int]]:
    """The alternate antenna and its receive relays at the radio's frequency, through the
    alternate receiver's paths when that receiver listens on it (5.9); no alternate when
    the antenna has no path there."""
    if alt_antenna is None:
        return None, frozenset()
    source = info
    if info.alt is not None and info.alt in ix.radios and \
            st.radios[info.alt].rx == alt_antenna:
        source = ix.radios[info.alt]
    p = _path(source.paths.get(alt_antenna, ()), rs.khz)
    if p is None:
        return None, frozenset()
    return alt_antenna, p.rx_relays


@dataclass(slots=True)
class Built:
    """What building the outputs gives: each switch's state, and who owns each of its
    station 0 relays."""

    states: dict[int, SwitchState]
    station0_owner: dict[int, dict[int, RadioRef | None]]
    """Per switch: each station 0 relay and the radio it belongs to (None: nobody)."""


def slot_needs(ix: ConfigIndex, classes: SlotClasses, ports: Mapping[RadioRef, PortAntennas]
               ) -> dict[int, set[SlotKey]]:
    needed: dict[int, set[SlotKey]] = {switch_id: set() for switch_id in ix.switch_ids}
    for ref, pa in ports.items():
        info = ix.radios[ref]
        for switch_id, _port in info.ports:
            for a in (pa.tx, pa.rx):
                if a is not None:
                    needed[switch_id].add(classes.key(a, ref))
            if pa.alt is not None:
                needed[switch_id].add(classes.alt_key(pa.alt, ref, pa.alt_partner))
    return needed


_LOCAL: dict[tuple[frozenset[int], int], frozenset[int]] = {}


def _local_cached(relays: frozenset[int], switch: int) -> frozenset[int]:
    key = (relays, switch)
    found = _LOCAL.get(key)
    if found is None:
        if len(_LOCAL) > 65536:
            _LOCAL.clear()
        found = _LOCAL[key] = local_relays(relays, switch)
    return found


@dataclass(frozen=True, slots=True)
class Inputs:
    """What every switch's state is built from, computed once per operation."""

    ports: Mapping[RadioRef, PortAntennas]
    alts: Mapping[RadioRef, tuple[int | None, frozenset[RadioRef]]]
    reasons: Mapping[RadioRef, str]
    """Why the server inhibits each main radio (empty: it does not)."""
    inhibit_pairs: frozenset[tuple[RadioRef, RadioRef]]
    """(transmitter, inhibited) pairs of radio-to-radio inhibits now."""
    transmitting: frozenset[RadioRef]


def inhibit_pairs(ix: ConfigIndex, st: State) -> frozenset[tuple[RadioRef, RadioRef]]:
    return frozenset((t, r) for t in ix.mains for r in ix.mains
                     if t != r and inhibits(ix, st, t, r))


def build(ix: ConfigIndex, st: State, classes: SlotClasses, maps: Mapping[int, SlotMap],
          inputs: Inputs, previous: Mapping[int, SwitchState],
          previous_owner: Mapping[int, Mapping[int, RadioRef | None]],
          cache: dict[tuple[object, ...], StationAntennas]) -> Built:
    """Every switch's wanted state (``maps`` must already hold every slot key needed)."""
    ports = inputs.ports
    transmitting = inputs.transmitting
    inhibited = {ref for ref, why in inputs.reasons.items() if why
                 and (ref in transmitting or not ix.radios[ref].radio.inhibit_only_on_transmit)}
    contributions = _station0_wanted(ix, st, ports, transmitting)
    if len(cache) > 4096:
        cache.clear()
    states: dict[int, SwitchState] = {}
    for switch_id in ix.switch_ids:
        m = maps[switch_id]
        prev = previous.get(switch_id)
        stations, inh, port_of = _port_stations(ix, classes, m, ports, transmitting, inhibited,
                                                switch_id, prev, cache)
        inhibit_others, use_alt = _radio_pairs(inputs, port_of)
        waived = (_waivers(ix, st, classes, m, ports, port_of) if classes.any_owned
                  else frozenset())
        owners = _station0(contributions[switch_id], previous_owner.get(switch_id, {}),
                           prev.station0 if prev else frozenset(), transmitting)
        interrupt, delay = ix.interrupt[switch_id]
        states[switch_id] = SwitchState(
            stations=tuple(stations),
            station0=frozenset(owners),
            conflicts=m.conflicts - waived if waived else m.conflicts,
            fast=m.fast,
            systems=m.systems,
            inhibited=frozenset(inh),
            inhibit_others=tuple(frozenset(s) for s in inhibit_others),
            use_alternate=tuple(frozenset(s) for s in use_alt),
            interrupt=interrupt,
            receive_delay=(0, 0, 0, 0, 0, 0),
            inhibit_time=ix.switches[switch_id].inhibit_time,
            interrupt_delay=delay,
            active=st.running,
        )
        if prev is not None and prev == states[switch_id]:
            states[switch_id] = prev
        contributions[switch_id] = owners
    return Built(states, contributions)


def _station0_wanted(ix: ConfigIndex, st: State, ports: Mapping[RadioRef, PortAntennas],
                     transmitting: frozenset[RadioRef]) -> dict[int, dict[int, RadioRef | None]]:
    """Per switch, the station 0 relays wanted now and the radio each belongs to: the
    latched relays (nobody's), the Relay functions' relays, and a radio's relays on a
    switch where it has no port (its extra relays too while it transmits).  The first
    owner named keeps a relay."""
    contributions: dict[int, dict[int, RadioRef | None]] = {switch_id: {} for switch_id in ix.switch_ids}

    def add0(relays: frozenset[int], owner: RadioRef | None) -> None:
        for r in relays:
            switch_id = switch_of_relay(r)
            if switch_id in contributions and relay_exists(r):
                contributions[switch_id].setdefault(local_relay(r), owner)

    add0(st.latched, None)
    for relay, owner in relay_contributions(ix, st):
        add0(frozenset({relay}), owner)
    for ref, pa in ports.items():
        own = ix.radio_switches[ref]
        if own == ix.all_switches:
            continue
        off_port = (pa.tx_relays if pa.tx is not None else pa.rx_relays) | (
            pa.extra if ref in transmitting else frozenset())
        add0(frozenset(r for r in off_port if switch_of_relay(r) not in own), ref)
    return contributions


def _port_stations(ix: ConfigIndex, classes: SlotClasses, m: SlotMap,
                   ports: Mapping[RadioRef, PortAntennas], transmitting: frozenset[RadioRef],
                   inhibited: set[RadioRef], switch_id: int, prev: SwitchState | None,
                   cache: dict[tuple[object, ...], StationAntennas]
                   ) -> tuple[list[StationAntennas], set[int], dict[RadioRef, list[int]]]:
    """One switch's six stations: each port of a radio holds that radio's antennas as
    slots with this switch's relays; a transmitting radio's extra relays keep their
    previous value.  Also the ports the server inhibits and each radio's ports here."""
    stations = [_IDLE] * 6
    inh: set[int] = set()
    port_of: dict[RadioRef, list[int]] = {}
    for ref in ix.switch_radios[switch_id]:
        pa = ports.get(ref)
        if pa is None:
            continue
        for port in ix.switch_ports[(ref, switch_id)]:
            port_of.setdefault(ref, []).append(port)
            if ref in transmitting and prev is not None:
                extra = prev.station(port).extra
            else:
                extra = _local_cached(pa.extra, switch_id)
            key = (switch_id, ref, pa, extra, id(m.key_slot))
            station = cache.get(key)
            if station is None:
                station = cache[key] = _station(classes, m, ref, pa, extra, switch_id)
            stations[port - 1] = station
            if ref in inhibited:
                inh.add(port)
    return stations, inh, port_of


def _station(classes: SlotClasses, m: SlotMap, ref: RadioRef, pa: PortAntennas,
             extra: frozenset[int], switch_id: int) -> StationAntennas:
    """One port's station: each antenna the radio uses as its slot with the antenna's
    relays on this switch; an unused one is no antenna and no relays."""
    return StationAntennas(
        m.slot(classes.key(pa.tx, ref)) if pa.tx is not None else NO_ANTENNA,
        _local_cached(pa.tx_relays, switch_id) if pa.tx is not None else frozenset(),
        m.slot(classes.key(pa.rx, ref)) if pa.rx is not None else NO_ANTENNA,
        _local_cached(pa.rx_relays, switch_id) if pa.rx is not None else frozenset(),
        m.slot(classes.alt_key(pa.alt, ref, pa.alt_partner))
        if pa.alt is not None else NO_ANTENNA,
        _local_cached(pa.alt_relays, switch_id) if pa.alt is not None else frozenset(),
        extra,
    )


def _radio_pairs(inputs: Inputs, port_of: Mapping[RadioRef, list[int]]
                 ) -> tuple[list[set[int]], list[set[int]]]:
    """Per station of one switch: the other stations its radio inhibits while it
    transmits (radio-to-radio inhibits), and those that move to their alternate antenna
    while it transmits."""
    inhibit_others: list[set[int]] = [set() for _ in STATIONS]
    use_alt: list[set[int]] = [set() for _ in STATIONS]
    for t, r in inputs.inhibit_pairs:
        if t in port_of and r in port_of:
            for tp in port_of[t]:
                inhibit_others[tp - 1].update(p for p in port_of[r] if p != tp)
    for r, r_ports in port_of.items():
        for t in inputs.alts.get(r, _NO_ALT)[1]:
            for tp in port_of.get(t, ()):
                use_alt[tp - 1].update(p for p in r_ports if p != tp)
    return inhibit_others, use_alt


_IDLE = StationAntennas()
_NO_ALT: tuple[int | None, frozenset[RadioRef]] = (None, frozenset())


def _station0(wanted: dict[int, RadioRef | None], prev_owner: Mapping[int, RadioRef | None],
              prev: frozenset[int], transmitting: frozenset[RadioRef]
              ) -> dict[int, RadioRef | None]:
    out: dict[int, RadioRef | None] = {}
    for relay, owner in wanted.items():
        if owner is None or owner not in transmitting or relay in prev:
            out[relay] = owner
    for relay in prev:
        owner = prev_owner.get(relay)
        if relay not in out and owner is not None and owner in transmitting:
            out[relay] = owner
    return out


def _waivers(ix: ConfigIndex, st: State, classes: SlotClasses, m: SlotMap,
             ports: Mapping[RadioRef, PortAntennas], port_of: Mapping[RadioRef, list[int]]
             ) -> frozenset[tuple[int, int]]:
    """Conflict pairs two radios here may hold together with the manual's permission."""
    refs = list(port_of)
    if len(refs) < 2:
        return frozenset()
    out: set[tuple[int, int]] = set()
    for i, a in enumerate(refs):
        pa = ports[a]
        for b in refs[i + 1:]:
            pb = ports[b]
            fam = related(ix, a, b)
            theirs = _antennas_used(pb)
            for x, x_is_alt in _antennas_used(pa):
                for y, y_is_alt in theirs:
                    if not ix.conflict(x, y):
                        continue
                    if fam or _conflict_allowed(ix, st, a, b, pa, pb, x, x_is_alt,
                                                y, y_is_alt):
                        s1 = m.slot(classes.alt_key(x, a, pa.alt_partner) if x_is_alt
                                    else classes.key(x, a))
                        s2 = m.slot(classes.alt_key(y, b, pb.alt_partner) if y_is_alt
                                    else classes.key(y, b))
                        out.add((s1, s2) if s1 <= s2 else (s2, s1))
    return frozenset(out)


def _antennas_used(pa: PortAntennas) -> tuple[tuple[int, bool], ...]:
    """The antennas a radio's ports use, each with whether it is the alternate."""
    return tuple((x, is_alt) for x, is_alt in ((pa.tx, False), (pa.rx, False), (pa.alt, True))
                 if x is not None)


def _conflict_allowed(ix: ConfigIndex, st: State, a: RadioRef, b: RadioRef,
                      pa: PortAntennas, pb: PortAntennas, x: int, x_is_alt: bool,
                      y: int, y_is_alt: bool) -> bool:
    """Whether two unrelated radios may hold the conflicting antennas ``x`` and ``y``:
    their own antennas when the manual permits it (shared transmit antennas, 5.12), one
    radio's alternate that is the very antenna its partner receives on (5.13), or an
    alternate and another radio's receive antenna (or alternate) the sharing rules permit
    together.  Never an alternate and another radio's transmit antenna: that is a
    receiver switched onto the antenna being transmitted on (5.9)."""
    if x_is_alt == y_is_alt:
        return permitted(ix, st, a, b, x, y)
    if y_is_alt:
        a, b, pa, pb, x, y = b, a, pb, pa, y, x
    if st.partners.get(a) == b and y == pb.rx and x == y and pb.rx != pb.tx:
        return True
    return y != pb.tx and permitted(ix, st, a, b, x, y)


__all__ = ["Built", "Inputs", "PortAntennas", "build", "inhibit_pairs", "radio_relays",
           "slot_needs"]
