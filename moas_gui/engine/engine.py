"""The engine: antenna selection and every rule of the manual, with no I/O.

Feed it what happens (a radio's frequency, a T/R change of a switch port, a
button press, a function, a direction) and it answers with a
:class:`~.changes.Changes`: radios whose view changed, the complete wanted
state of each switch that changed, and sentences for the log.  Time is passed
in (``now``, seconds on any monotonic clock); when omitted the last time seen
is used.  A request that cannot be met raises an :class:`~.errors.EngineError`
and leaves the engine exactly as it was.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from types import MappingProxyType

from moas_gui.config.model import Config, RadioRef

from .changes import NO_CHANGES, Changes
from .derive import alternates, inhibit_reason
from .errors import BadRequest, EngineError, NotFound, NotRunning
from .functions import extra_relays, function, is_on, refresh_relays, run, status
from .guards import interlock_guard, same_band_guard
from .index import ConfigIndex, RadioKind
from .layouts import layout_view
from .manual import select_antenna, select_direction
from .outputs import Inputs, PortAntennas, build, inhibit_pairs, radio_relays, slot_needs
from .ranges import nearest_range_relays
from .relative import relative as relative_select
from .relative import relative_list
from .rules import permitted, related, unpermitted
from .selection import recheck, select_by_frequency
from .slots import SETTLE_MARGIN_S, SlotClasses, SlotMap, allocate, initial_map, receive_seen
from .state import RadioState, State
from .switchstate import NO_ANTENNA, StationAntennas, SwitchState
from .systems import is_selected
from .views import AVAILABLE, SELECTED, UNAVAILABLE, AntennaView, LayoutView, RadioView
from .why import SWITCH, Why
from .work import Work, radio_name


class Engine:
    """One configuration's antenna switching brain (see the module docstring)."""

    def __init__(self, config: Config, now: float = 0.0) -> None:
        ix = ConfigIndex(config)
        self._ix = ix
        self._classes = SlotClasses(ix)
        st = State()
        st.now = now
        for ref in ix.order:
            st.radios[ref] = RadioState()
        st.shared = dict(ix.systems.initial_shared)
        for ref in ix.mains:
            cfg = ix.radios[ref].radio
            st.busses[ref] = frozenset(cfg.inhibit_buss)
            st.alt_active[ref] = frozenset(cfg.alt_active) if cfg.alt_active else None
            for other in cfg.partner[:1]:
                if other in ix.radios and other != ref and ref not in st.partners \
                        and other not in st.partners:
                    st.partners[ref] = other
                    st.partners[other] = ref
        self._state = st
        self._maps: dict[int, SlotMap] = {switch_id: initial_map(self._classes, switch_id)
                                              for switch_id in ix.switch_ids}
        self._switch_states: dict[int, SwitchState] = {}
        self._owners: dict[int, dict[int, RadioRef | None]] = {}
        self._views: dict[RadioRef, RadioView] = {}
        self._port_cache: dict[RadioRef, tuple[object, PortAntennas]] = {}
        self._ports: dict[RadioRef, PortAntennas] = {}
        self._station_cache: dict[tuple[object, ...], StationAntennas] = {}
        self._commit(Work(ix, st), force=True)

    def clone(self) -> Engine:
        """An independent engine in exactly this engine's state: a fresh copy of a new
        engine costs far less than building one (the configuration's read-only index is
        shared).  The station plan runs every scenario on such a copy."""
        c = Engine.__new__(Engine)
        c._ix = self._ix
        c._classes = self._classes
        c._state = self._state.clone()
        c._maps = dict(self._maps)
        c._switch_states = dict(self._switch_states)
        c._owners = {k: dict(v) for k, v in self._owners.items()}
        c._views = dict(self._views)
        c._port_cache = dict(self._port_cache)
        c._ports = dict(self._ports)
        c._station_cache = dict(self._station_cache)
        return c

    # -- reading ---------------------------------------------------------------------------
    @property
    def config(self) -> Config:
        return self._ix.config

    @property
    def running(self) -> bool:
        return self._state.running

    def switch_states(self) -> dict[int, SwitchState]:
        """The complete wanted state of every switch now."""
        return dict(self._switch_states)

    def radio_view(self, station: int, radio: int) -> RadioView:
        return self._views[self._radio(station, radio)]

    def radios(self) -> tuple[RadioView, ...]:
        return tuple(self._views[r] for r in sorted(self._views))

    def antenna_views(self) -> tuple[AntennaView, ...]:
        out = []
        for a in self._ix.ids:
            ant = self._ix.antennas[a]
            out.append(AntennaView(a, ant.label, ant.title, ant.rotator, ant.offset))
        return tuple(out)

    def slot_of(self, switch_id: int, antenna: int, station: int, radio: int,
                as_partner_alt: bool | None = None) -> int | None:
        """The switch slot standing for ``antenna`` on that radio's ports (None: none now).

        A radio listening on its partner's receive antenna as its alternate (5.13), or on an
        antenna radios may share (``SharedTX`` and its conflicts, shared-capable systems), does
        so through a slot of its own: with ``as_partner_alt`` None that slot is answered while
        it is in use (and the radio does not hold the antenna itself), with False always the
        radio's ordinary slot (the one it transmits or receives through), with True always
        the alternate slot.
        """
        if antenna not in self._ix.antennas or switch_id not in self._maps:
            return None
        ref = RadioRef(station, radio)
        if as_partner_alt is None:
            pa = self._ports.get(ref)
            if pa is not None and pa.alt == antenna and antenna not in (pa.tx, pa.rx):
                key = self._classes.alt_key(antenna, ref, pa.alt_partner)
            else:
                key = self._classes.key(antenna, ref)
        else:
            key = self._classes.key(antenna, ref, as_partner_alt)
        return self._maps[switch_id].key_slot.get(key)

    def may_share(self, a: RadioRef, antenna_a: int, b: RadioRef, antenna_b: int) -> bool:
        """Whether radios ``a`` and ``b`` may hold these conflicting antennas together now
        (a shared system in shared mode, or shared transmit antennas between interlocked
        radios; a radio and its own sub or alternate receiver)."""
        return related(self._ix, a, b) or permitted(self._ix, self._state, a, b, antenna_a,
                                                     antenna_b)

    def function_status(self, station: int, radio: int, function_id: int) -> tuple[bool, str]:
        """Whether a function can run now for this radio, and why not."""
        ref = self._radio(station, radio)
        f = function(self._ix, function_id)
        verdict = status(self._ix, self._state, ref, f)
        return verdict.available, verdict.reason

    def system_shared(self, system_id: int) -> bool:
        """Whether a shared-capable system is in shared mode now (5.10, the Share function)."""
        return self._state.shared.get(system_id, False)

    def function_on(self, function_id: int) -> bool:
        """Whether a toggling function (Share, Relay, Inhibit, Extra, Partner, AltActive) is on."""
        return is_on(self._ix, self._state, function(self._ix, function_id))

    def layout(self, station: int, radio: int, rows: int, columns: int) -> LayoutView:
        """The configured layout closest to ``rows`` x ``columns``, with button states (5.16)."""
        ref = self._radio(station, radio)
        for name, value in (("rows", rows), ("columns", columns)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise BadRequest(f"{name} must be a whole number of at least 1 (not {value!r})")
        ix, st = self._ix, self._state
        rs = st.radios[ref]

        def antenna_state(a: int) -> tuple[str, str]:
            canon = ix.canon[a]
            for held in (rs.tx, rs.rx):
                if held is not None and is_selected(ix.systems, ix.comps, ix.comps[held], canon):
                    return SELECTED, ""
            refusal = self._refusal(lambda w: select_antenna(w, ref, a, "both", False))
            return (UNAVAILABLE, refusal) if refusal else (AVAILABLE, "")

        def function_state(fid: int) -> tuple[str, str]:
            f = ix.functions[fid]
            if is_on(ix, st, f):
                return SELECTED, ""
            verdict = status(ix, st, ref, f)
            if verdict.available:
                return AVAILABLE, ""
            return UNAVAILABLE, f"{f.label} is not available: {verdict.reason}"

        return layout_view(ix, ref, rs.khz, rows, columns, antenna_state, function_state)

    def electrical_heading(self, rotator_id: int) -> float | None:
        """The offset of the antenna of an electrical rotator in use, if any."""
        ix, st = self._ix, self._state
        for ref in ix.order:
            rs = st.radios[ref]
            for a in (rs.tx, rs.rx):
                if a is not None and ix.antennas[a].rotator == rotator_id:
                    return float(ix.antennas[a].offset)
        return None

    # -- operations ------------------------------------------------------------------------
    def set_frequency(self, station: int, radio: int, khz: float, tx_khz: float | None = None,
                      now: float | None = None) -> Changes:
        """A logger reported this radio's frequency (kHz); selection per appendix F."""
        ref = self._radio(station, radio)
        khz = _frequency("khz", khz)
        tx = None if tx_khz is None else _frequency("tx_khz", tx_khz)
        info = self._ix.radios[ref]
        if info.kind is RadioKind.ALT:
            raise BadRequest(f"{radio_name(ref)} is the alternate receiver of {info.main} and "
                             "follows its frequency")

        def op(w: Work) -> None:
            self._frequency(w, ref, khz, None if tx == khz else tx)
        return self._run(op, now, need_running=False)

    def hold(self, station: int, radio: int, by: str | None,
             now: float | None = None, since: float | None = None) -> Changes:
        """Hold the radio's antennas against its frequency changes (``by`` says who holds
        them, e.g. "AetherSDR at 192.168.1.20"), or release them (``by`` None): a held
        radio's frequency is kept but chooses no antennas; presses still do.  Releasing
        selects for the frequency it has now.  ``since``: when the hold began, in seconds
        since the epoch, shown to people (kept when the same holder holds again)."""
        ref = self._radio(station, radio)
        if by is not None and (not isinstance(by, str) or not by.strip()):
            raise BadRequest(f"who holds the antennas must be said (not {by!r})")

        def op(w: Work) -> None:
            st = w.st
            if by is not None:
                if st.held.get(ref) != by:
                    st.held[ref] = by
                    st.held_since.pop(ref, None)
                    w.log.append(f"{radio_name(ref)}: antennas held by {by}")
                if since is not None:
                    st.held_since.setdefault(ref, since)
                return
            st.held_since.pop(ref, None)
            if st.held.pop(ref, None) is None:
                return
            w.log.append(f"{radio_name(ref)}: antennas released, they follow the frequency")
            if st.radios[ref].khz is not None:
                w.takeover = True
                w.reported = ref
                select_by_frequency(w, ref, None)  # chosen afresh, as for a new frequency
        return self._run(op, now, need_running=False)

    def radio_on_port(self, switch_id: int, port: int) -> tuple[int, int] | None:
        """``(station, radio)`` of the radio whose switch port this is (the configured
        ports, or each station's own port by default); None for a port of no radio."""
        ref = self._ix.port_radio.get((switch_id, port))
        return None if ref is None else (ref.station, ref.radio)

    def set_transmitting(self, switch_id: int, port: int, transmitting: bool,
                         now: float | None = None) -> Changes:
        """A switch port's T/R line changed (the switch's ``<`` / ``>`` events)."""
        ix = self._ix
        if switch_id not in ix.switches:
            raise NotFound(f"There is no switch {switch_id} in the configuration")
        if not 1 <= port <= 6:
            raise BadRequest(f"port must be 1-6 (not {port})")

        def op(w: Work) -> None:
            st = w.st
            st.ports_tr[(switch_id, port)] = bool(transmitting)
            if not transmitting:
                self._maps[switch_id] = receive_seen(self._maps[switch_id], port)
            ref = ix.port_radio.get((switch_id, port))
            if ref is None:
                return
            info = ix.radios[ref]
            was = st.radios[ref].transmitting
            now_tx = any(st.ports_tr.get(p, False) for p in info.ports)
            if info.kind is not RadioKind.MAIN:
                now_tx = False
            if was == now_tx:
                return
            st.radios[ref] = st.radios[ref].with_(transmitting=now_tx)
            if now_tx:
                freq = st.radios[ref].tx_freq
                latched = set(st.latched)
                for tr in info.radio.relays:
                    if freq is not None and tr.range.contains(freq):
                        latched |= tr.set
                        latched -= tr.reset
                st.latched = frozenset(latched)
        return self._run(op, now, need_running=False)

    def select(self, station: int, radio: int, antenna: int, target: str = "both",
               exclusive: bool = False, now: float | None = None) -> Changes:
        """A button press: additive toggles, exclusive selects alone (``exclusive`` = double-click)."""
        ref = self._radio(station, radio)
        return self._run(lambda w: select_antenna(w, ref, antenna, target, exclusive), now)

    def run_function(self, station: int, radio: int, function_id: int,
                     now: float | None = None) -> Changes:
        ref = self._radio(station, radio)
        f = function(self._ix, function_id)
        return self._run(lambda w: run(w, ref, f), now)

    def relative(self, station: int, radio: int, step: int | None = None,
                 index: int | None = None, now: float | None = None) -> Changes:
        """Appendix G: the next (+1) or previous (-1) relative antenna, or the one at ``index``."""
        ref = self._radio(station, radio)
        return self._run(lambda w: relative_select(w, ref, step, index), now)

    def select_direction(self, rotator_id: int, heading: float,
                         now: float | None = None) -> Changes:
        """An electrical rotator turned: the antenna whose offset is closest (5.15)."""
        if self._ix.config.rotator(rotator_id) is None:
            raise NotFound(f"There is no rotator {rotator_id}")
        if isinstance(heading, bool) or not isinstance(heading, (int, float)) \
                or not math.isfinite(heading):
            raise BadRequest(f"heading must be a number of degrees (not {heading!r})")
        return self._run(lambda w: select_direction(w, rotator_id, float(heading)), now)

    def keep_switch_antennas(self, switch_id: int, held: Mapping[int, tuple[int, int]],
                             now: float | None = None) -> Changes:
        """What switch ``switch_id`` holds for its ports wins over the saved state.

        A restart (or a reconnection) found the box holding other antennas for some ports
        than the state this engine was restored from: the state could not be saved, or
        the box was driven from elsewhere.  ``held`` gives, per port, the transmit and
        receive slots the box holds.  The box is the truth, above all for a station
        that transmits on it, so the radio on each port takes the antennas its slots
        stand for, as they are; its next frequency is decided afresh by the rules.

        Every port is taken in the one operation, its slots read against the one slot
        map the box was loaded with: taken one port at a time, appendix F's restart rule
        would run between two ports and could give a radio an antenna the box holds for
        a port not taken yet (the box would then refuse the engine's state).  A port
        with no radio, or a slot that stands for no antenna of that radio, is left to
        the engine (the switch link then sends the engine's own choice, which the box
        applies under its hot-switch rules)."""
        ix = self._ix
        if switch_id not in self._maps:
            return NO_CHANGES
        slot_key = self._maps[switch_id].slot_key

        def antenna(ref: RadioRef, slot: int) -> tuple[bool, int | None]:
            """Whether ``slot`` stands for an antenna of ``ref`` (or none), and which."""
            if slot == NO_ANTENNA:
                return True, None
            key = slot_key.get(slot)
            for a in ix.antennas:
                if key is not None and self._classes.key(a, ref) == key:
                    return True, a
            return False, None

        taken: list[tuple[int, RadioRef, int | None, int | None]] = []
        for port, (tx_slot, rx_slot) in sorted(held.items()):
            ref = ix.port_radio.get((switch_id, port))
            if ref is None:
                continue
            (tx_known, tx), (rx_known, rx) = antenna(ref, tx_slot), antenna(ref, rx_slot)
            if not (tx_known and rx_known):
                continue
            rs = self._state.radios[ref]
            if (rs.tx, rs.rx) != (tx, rx):
                taken.append((port, ref, tx, rx))
        if not taken:
            return NO_CHANGES

        def op(w: Work) -> None:
            for port, ref, tx, rx in taken:
                w.st.radios[ref] = w.st.radios[ref].with_(tx=tx, rx=rx, note="")
                w.st.why[ref] = Why(SWITCH, f"switch {switch_id} held these antennas for "
                                            f"port {port} after a restart (newer than the "
                                            "saved state)")
                w.log.append(f"{radio_name(ref)}: kept the antennas switch {switch_id} "
                             f"holds for port {port} (newer than the saved state)")
            _yield_to_the_box(w, {ref for _, ref, _, _ in taken}, switch_id)
        return self._run(op, now, need_running=False)

    def stop(self) -> Changes:
        """Stop Switches: every switch inactive, all relays off (3.4.5)."""
        def op(w: Work) -> None:
            if w.st.running:
                w.st.running = False
                w.log.append("Switches stopped: all relays off")
        return self._run(op, None, need_running=False)

    def start(self) -> Changes:
        """Start Switches: the switches hold the current antennas again."""
        def op(w: Work) -> None:
            if not w.st.running:
                w.st.running = True
                w.log.append("Switches started")
        return self._run(op, None, need_running=False)

    def reset(self) -> Changes:
        """Reset Switches: every switch's complete state, to be loaded again (3.4.3)."""
        return Changes(switches=MappingProxyType(dict(self._switch_states)),
                       log=("Switches reset: loading the current antennas again",))

    # -- internals -------------------------------------------------------------------------
    def _radio(self, station: int, radio: int) -> RadioRef:
        for name, value in (("station", station), ("radio", radio)):
            if isinstance(value, bool) or not isinstance(value, int):
                raise BadRequest(f"{name} must be a whole number (not {value!r})")
        ref = RadioRef(station, radio)
        if ref not in self._ix.radios:
            raise NotFound(f"There is no {ref} in the configuration")
        return ref

    def _frequency(self, w: Work, ref: RadioRef, khz: float, tx: float | None) -> None:
        ix, st = w.ix, w.st
        info = ix.radios[ref]
        old = st.radios[ref].khz
        st.radios[ref] = st.radios[ref].with_(khz=khz, tx_khz=tx)
        if ref in st.held:
            return  # an operator holds its antennas (hold): the frequency chooses none
        w.takeover = True
        w.reported = ref
        select_by_frequency(w, ref, old)
        if info.kind is not RadioKind.MAIN:
            return
        for extra in (info.sub, info.alt):
            if extra is None or extra not in ix.radios:
                continue
            einfo = ix.radios[extra]
            follows = einfo.kind is RadioKind.ALT or ix.sub_flag(extra, "use_main_freq")
            if follows:
                eold = st.radios[extra].khz
                st.radios[extra] = st.radios[extra].with_(khz=khz)
                select_by_frequency(w, extra, eold)

    def _refusal(self, op: Callable[[Work], None]) -> str:
        """What ``op`` would be refused with now ("" when it would work), tried on a copy."""
        w = Work(self._ix, self._state.clone())
        try:
            op(w)
        except EngineError as exc:  # the rules' refusal, in words for the operator
            return str(exc) or f"{type(exc).__name__} (the engine gave no reason)"
        except Exception as exc:  # noqa: BLE001 - a fault must not take the layout down
            return f"the server could not tell: {type(exc).__name__} ({exc})"
        return ""

    def _run(self, op: Callable[[Work], None], now: float | None,
             need_running: bool = True) -> Changes:
        if need_running and not self._state.running:
            raise NotRunning("The switches are stopped; start them first")
        st = self._state.clone()
        if now is not None:
            st.now = max(st.now, float(now))
        w = Work(self._ix, st)
        saved_maps = dict(self._maps)
        try:
            op(w)
            if need_running:
                same_band_guard(w)
            recheck(w)
            if self._ix.any_shared_tx:
                interlock_guard(w, need_running)
            refresh_relays(self._ix, st, w)
            return self._commit(w)
        except Exception:
            self._maps = saved_maps
            raise

    def _commit(self, w: Work, force: bool = False) -> Changes:
        ix, st = self._ix, w.st
        alt_reasons: dict[RadioRef, str] = {}
        alts = alternates(ix, st, alt_reasons)
        ports = self._port_antennas(st, alts, extra_relays(ix, st))
        maps = self._allocate_slots(st, ports)
        transmitting = frozenset(ref for ref in ix.mains if st.radios[ref].transmitting)
        inputs = Inputs(ports, alts, {ref: inhibit_reason(ix, st, ref) for ref in ix.mains},
                        inhibit_pairs(ix, st), transmitting)
        built = build(ix, st, self._classes, maps, inputs, self._switch_states, self._owners,
                      self._station_cache)
        views = {ref: self._view(st, ref, inputs, alt_reasons.get(ref, ""))
                 for ref in ix.order}
        changed_radios = {ref for ref, v in views.items() if self._views.get(ref) != v}
        changed_switches = {sw: s for sw, s in built.states.items()
                            if force or self._switch_states.get(sw) is not s}
        layouts = bool(changed_radios) or force or _layout_inputs_changed(self._state, st)
        self._state = st
        self._ports = ports
        self._maps = maps
        self._switch_states = built.states
        self._owners = built.station0_owner
        self._views = views
        if not (changed_radios or changed_switches or layouts or w.log):
            return NO_CHANGES
        return Changes(frozenset(changed_radios), MappingProxyType(changed_switches), layouts,
                       tuple(w.log), tuple(w.details))

    def _port_antennas(self, st: State,
                       alts: Mapping[RadioRef, tuple[int | None, frozenset[RadioRef]]],
                       extras: Mapping[RadioRef, frozenset[int]]
                       ) -> dict[RadioRef, PortAntennas]:
        """What every radio but the alternate receivers puts on its ports; a radio whose
        inputs did not change (and has no sub receiver) keeps the answer found before."""
        ix = self._ix
        ports = {}
        for ref in ix.order:
            if ix.radios[ref].kind is RadioKind.ALT:
                continue
            partner = st.partners.get(ref)
            key = (st.radios[ref], alts.get(ref), extras.get(ref), partner,
                   st.radios[partner].rx if partner in st.radios else None)
            cached = self._port_cache.get(ref)
            if cached is not None and cached[0] == key and not ix.radios[ref].sub:
                ports[ref] = cached[1]
            else:
                ports[ref] = radio_relays(ix, st, ref, alts.get(ref), extras)
                self._port_cache[ref] = (key, ports[ref])
        return ports

    def _allocate_slots(self, st: State, ports: Mapping[RadioRef, PortAntennas]
                        ) -> dict[int, SlotMap]:
        """Each switch's antenna slots for what its ports need now (:func:`allocate`, told
        which ports transmit and how long the switch takes to settle)."""
        ix = self._ix
        needed = slot_needs(ix, self._classes, ports)
        maps = {}
        for sw in ix.switch_ids:
            busy, unknown = self._busy(st, sw)
            switch = ix.switches[sw]
            settle = SETTLE_MARGIN_S + (switch.inhibit_time + switch.interrupt_mode_delay) / 1000
            maps[sw] = allocate(self._classes, self._maps[sw], needed[sw], st.now, busy, unknown,
                                settle)
        return maps

    def _busy(self, st: State, switch: int) -> tuple[frozenset[int], bool]:
        indicate = self._ix.switches[switch].indicate_tr
        busy = set()
        unknown = False
        for port in range(1, 7):
            tr = st.ports_tr.get((switch, port))
            if tr is None and not indicate:
                busy.add(port)
                unknown = True
            elif tr:
                busy.add(port)
        return frozenset(busy), unknown

    def _view(self, st: State, ref: RadioRef, inputs: Inputs, alt_why: str) -> RadioView:
        ix = self._ix
        rs = st.radios[ref]
        info = ix.radios[ref]
        main = info.kind is RadioKind.MAIN
        reason = inputs.reasons.get(ref, "") if main else ""
        note = reason or rs.note
        inhibited = bool(reason)
        if main and not inhibited and inputs.transmitting:
            for t in inputs.transmitting:
                if (t, ref) in inputs.inhibit_pairs:
                    inhibited = True
                    note = note or f"inhibited while {t} transmits"
                    break
        alt = inputs.alts.get(ref, (None, frozenset()))[0] if main else None
        listed = relative_list(ix, ref, rs.khz)
        path = nearest_range_relays(info.paths.get(rs.rx, ()), rs.khz) \
            if rs.rx is not None and ix.radio_rx_inputs else None
        view = RadioView(ref.station, ref.radio, rs.khz, rs.tx_freq if main else None,
                         rs.tx, rs.rx, alt, rs.transmitting, inhibited, note,
                         None if listed is None else listed[1].ids,
                         path is not None and path.radio_rx_antenna, st.why.get(ref),
                         st.held.get(ref), st.held_since.get(ref), alt_why if main else "")
        old = self._views.get(ref)
        return old if old == view else view


def _yield_to_the_box(w: Work, taken: set[RadioRef], switch_id: int) -> None:
    """A radio the saved state has on an antenna that conflicts with one a radio took
    from the box loses it and is selected again: the box holds the taken one, and the
    engine never wants two radios on conflicting antennas (the box would refuse it)."""
    for a, b, _x, _y in unpermitted(w.ix, w.st):
        if (a in taken) == (b in taken):
            continue  # both from the box (it let them be), or neither
        loser = b if a in taken else a
        if w.set_pair(loser, None, None, f"switch {switch_id} holds its antenna for "
                      "another radio", Why(SWITCH, f"switch {switch_id} held its antenna "
                                                   "for another radio after a restart")):
            w.pending.append(loser)


def _layout_inputs_changed(old: State, st: State) -> bool:
    """Whether anything the button layouts show besides the radios changed: shared
    systems, inhibit busses, partners, AltActive, relay and extra states, stored
    antennas."""
    return (old.shared != st.shared or old.busses != st.busses or old.partners != st.partners
            or old.alt_active != st.alt_active or old.relay_on != st.relay_on
            or old.extra_on != st.extra_on or old.stored != st.stored)


def _frequency(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or value <= 0:
        raise BadRequest(f"{name} must be a positive number of kHz (not {value!r})")
    return float(value)


__all__ = ["Engine"]
