"""The engine's selections as plain data, and back: what a restart needs to come
back to the same decisions (see ``docs/server.md``, "After a restart").

:func:`export_selections` gives a JSON-ready dict of what the operator and the
loggers chose: each radio's frequencies and antennas, the antennas remembered
per band, functions switched on, latched relays, stored antennas, whether the
switches run, and which switch slot stands for which antenna.  Live inputs are
left out (who transmits now, the clock): the switches report T/R again.

:func:`restore_selections` puts such a dict into a freshly made engine of the
same configuration and returns the :class:`~.changes.Changes` of the complete
state, like the engine's first decision.  Anything that does not fit the
configuration raises :class:`SnapshotError` and leaves the engine untouched.
Pure: no I/O, no clock.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from moas_gui.config.model import RadioRef
from moas_gui.errors import MoasError

from .changes import Changes
from .engine import Engine
from .slots import Release, SlotKey, SlotMap, _tables
from .state import RadioState, State
from .why import Why
from .work import Work

FORMAT = 1
"""Bumped whenever the layout below changes; another number is not restored."""


class SnapshotError(MoasError, ValueError):
    """A snapshot that does not fit this engine's configuration (the message says where)."""


# -- export ----------------------------------------------------------------------------------

def _ref(ref: RadioRef) -> list[int]:
    return [ref.station, ref.radio]


def _key(key: SlotKey) -> list[Any]:
    klass, owner, as_partner_alt = key
    out: list[Any] = [klass, None if owner is None else _ref(owner)]
    if as_partner_alt:
        out.append(True)
    return out


def export_selections(engine: Engine) -> dict[str, Any]:
    """What the engine holds, as JSON-ready data (see the module docstring)."""
    st: State = engine._state
    radios = []
    for ref, rs in sorted(st.radios.items()):
        radios.append({
            "radio": _ref(ref), "khz": rs.khz, "tx_khz": rs.tx_khz, "tx": rs.tx, "rx": rs.rx,
            "note": rs.note, "rel_pos": rs.rel_pos,
            "rel_key": None if rs.rel_key is None else list(rs.rel_key),
            "why": None if ref not in st.why else st.why[ref].to_dict(),
        })
    history = [{"radio": _ref(ref), "bands": [[seg[0], seg[1], pair[0], pair[1]]
                                              for seg, pair in sorted(bands.items())]}
               for ref, bands in sorted(st.history.items())]
    maps = {}
    for switch, m in sorted(engine._maps.items()):
        if m.static:
            continue  # fixed by the configuration
        maps[str(switch)] = {
            "slots": [[slot, *_key(key)] for slot, key in sorted(m.slot_key.items())],
            "released": [[slot, sorted(rel.busy), rel.unknown, max(0.0, st.now - rel.time)]
                         for slot, rel in sorted(m.released.items())],
        }
    return {
        "format": FORMAT,
        "radios": radios,
        "history": history,
        "shared": [[system, on] for system, on in sorted(st.shared.items())],
        "busses": [[*_ref(ref), sorted(b)] for ref, b in sorted(st.busses.items())],
        "partners": [[*_ref(a), *_ref(b)] for a, b in sorted(st.partners.items())],
        "alt_active": [[*_ref(ref), None if v is None else sorted(_ref(r) for r in v)]
                       for ref, v in sorted(st.alt_active.items())],
        "relay_on": sorted(st.relay_on),
        "relay_auto_off": sorted(st.relay_auto_off),
        "extra_on": sorted(st.extra_on),
        "latched": sorted(st.latched),
        "stored": [[*_ref(ref), tx, rx] for ref, (tx, rx) in sorted(st.stored.items())],
        "running": st.running,
        "maps": maps,
    }


# -- restore ---------------------------------------------------------------------------------

class _Reader:
    """Strict reading of the plain data: every wrong type names where it is."""

    def __init__(self, engine: Engine) -> None:
        self.ix = engine._ix

    def fail(self, where: str, what: str) -> SnapshotError:
        return SnapshotError(f"{where}: {what}")

    def int_(self, value: object, where: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(where, f"expected a whole number, found {value!r:.40}")
        return value

    def opt_int(self, value: object, where: str) -> int | None:
        return None if value is None else self.int_(value, where)

    def float_(self, value: object, where: str, finite: bool = True) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or (finite and not math.isfinite(value)) or math.isnan(value):
            raise self.fail(where, f"expected a number, found {value!r:.40}")
        return float(value)

    def opt_khz(self, value: object, where: str) -> float | None:
        if value is None:
            return None
        khz = self.float_(value, where)
        if khz <= 0:
            raise self.fail(where, f"a frequency must be positive, found {khz}")
        return khz

    def list_(self, value: object, where: str, length: int | None = None) -> list[Any]:
        if not isinstance(value, list) or (length is not None and len(value) != length):
            size = "" if length is None else f" of {length}"
            raise self.fail(where, f"expected a list{size}, found {value!r:.40}")
        return value

    def ints(self, value: object, where: str) -> frozenset[int]:
        return frozenset(self.int_(v, where) for v in self.list_(value, where))

    def ref(self, value: object, where: str) -> RadioRef:
        station, radio = self.list_(value, where, 2)
        ref = RadioRef(self.int_(station, where), self.int_(radio, where))
        if ref not in self.ix.radios:
            raise self.fail(where, f"there is no {ref} in the configuration")
        return ref

    def antenna(self, value: object, where: str) -> int | None:
        a = self.opt_int(value, where)
        if a is not None and a not in self.ix.antennas:
            raise self.fail(where, f"there is no antenna {a} in the configuration")
        return a

    def key(self, klass: object, owner: object, where: str, classes: Mapping[int, Any],
            as_partner_alt: object = False) -> SlotKey:
        k = self.int_(klass, where)
        if k not in classes:
            raise self.fail(where, f"no antenna class {k}")
        if not isinstance(as_partner_alt, bool) or as_partner_alt and owner is None:
            raise self.fail(where, f"expected true for a partner's alternate slot, found "
                            f"{as_partner_alt!r:.20}")
        return (k, None if owner is None else self.ref(owner, where), as_partner_alt)


def _why(r: _Reader, value: object, where: str) -> Why:
    """A saved reason (the radio entry's ``why``)."""
    if not isinstance(value, dict) or not isinstance(value.get("rule"), str) \
            or not isinstance(value.get("text"), str):
        raise r.fail(where, "why is not an object with rule and text")
    passed = []
    for item in r.list_(value.get("passed_over", []), where):
        if not isinstance(item, dict) or not isinstance(item.get("reason"), str):
            raise r.fail(where, "why.passed_over holds something other than antenna reasons")
        passed.append((r.int_(item.get("antenna"), where), item["reason"]))
    return Why(value["rule"], value["text"], tuple(passed))


def _radios(r: _Reader, data: Mapping[str, Any], st: State) -> None:
    for entry in r.list_(data.get("radios"), "radios"):
        if not isinstance(entry, dict):
            raise r.fail("radios", f"expected an object, found {entry!r:.40}")
        ref = r.ref(entry.get("radio"), "radios")
        where = f"radios: {ref}"
        rel_key = entry.get("rel_key")
        note = entry.get("note", "")
        if not isinstance(note, str):
            raise r.fail(where, "note is not text")
        why = entry.get("why")
        if why is not None:
            st.why[ref] = _why(r, why, where)
        st.radios[ref] = RadioState(
            khz=r.opt_khz(entry.get("khz"), where), tx_khz=r.opt_khz(entry.get("tx_khz"), where),
            tx=r.antenna(entry.get("tx"), where), rx=r.antenna(entry.get("rx"), where),
            note=note, rel_pos=r.opt_int(entry.get("rel_pos"), where),
            rel_key=None if rel_key is None else tuple(
                r.int_(v, where) for v in r.list_(rel_key, where, 2)),  # type: ignore[arg-type]
        )
    for entry in r.list_(data.get("history"), "history"):
        if not isinstance(entry, dict):
            raise r.fail("history", f"expected an object, found {entry!r:.40}")
        ref = r.ref(entry.get("radio"), "history")
        bands = {}
        for band in r.list_(entry.get("bands"), f"history: {ref}"):
            low, high, tx, rx = r.list_(band, f"history: {ref}", 4)
            seg = (r.float_(low, "history", finite=False), r.float_(high, "history", finite=False))
            bands[seg] = (r.antenna(tx, f"history: {ref}"), r.antenna(rx, f"history: {ref}"))
        st.history[ref] = bands


def _settings(r: _Reader, data: Mapping[str, Any], st: State) -> None:
    shared = {}
    for pair in r.list_(data.get("shared"), "shared"):
        system, on = r.list_(pair, "shared", 2)
        if system not in st.shared or not isinstance(on, bool):
            raise r.fail("shared", f"no shared system {system!r:.20} (or not true/false)")
        shared[system] = on
    st.shared.update(shared)
    for entry in r.list_(data.get("busses"), "busses"):
        s, n, b = r.list_(entry, "busses", 3)
        st.busses[r.ref([s, n], "busses")] = r.ints(b, "busses")
    partners = {}
    for entry in r.list_(data.get("partners"), "partners"):
        s, n, s2, n2 = r.list_(entry, "partners", 4)
        partners[r.ref([s, n], "partners")] = r.ref([s2, n2], "partners")
    if any(partners.get(b) != a for a, b in partners.items()):
        raise r.fail("partners", "partners must be listed both ways")
    st.partners = partners
    for entry in r.list_(data.get("alt_active"), "alt_active"):
        s, n, v = r.list_(entry, "alt_active", 3)
        st.alt_active[r.ref([s, n], "alt_active")] = None if v is None else frozenset(
            r.ref(x, "alt_active") for x in r.list_(v, "alt_active"))
    for name in ("relay_on", "relay_auto_off", "extra_on"):
        ids = r.ints(data.get(name), name)
        unknown = ids - set(r.ix.functions)
        if unknown:
            raise r.fail(name, f"no function {min(unknown)} in the configuration")
        setattr(st, name, ids)
    st.latched = r.ints(data.get("latched"), "latched")
    stored = {}
    for entry in r.list_(data.get("stored"), "stored"):
        s, n, tx, rx = r.list_(entry, "stored", 4)
        stored[r.ref([s, n], "stored")] = (r.antenna(tx, "stored"), r.antenna(rx, "stored"))
    st.stored = stored
    running = data.get("running")
    if not isinstance(running, bool):
        raise r.fail("running", "expected true or false")
    st.running = running


def _maps(r: _Reader, engine: Engine, data: Mapping[str, Any], now: float) -> dict[int, SlotMap]:
    maps = dict(engine._maps)
    saved = data.get("maps")
    if not isinstance(saved, dict):
        raise r.fail("maps", "expected an object")
    classes = engine._classes
    for name, entry in saved.items():
        where = f"maps: switch {name}"
        switch = int(name) if isinstance(name, str) and name.isdigit() else -1
        if switch not in maps or maps[switch].static or not isinstance(entry, dict):
            raise r.fail(where, "no such switch with slots given out as needed")
        key_slot: dict[SlotKey, int] = {}
        slot_key: dict[int, SlotKey] = {}
        for item in r.list_(entry.get("slots"), where):
            fields = r.list_(item, where, 4 if isinstance(item, list) and len(item) == 4
                             else 3)
            slot, klass, owner = fields[:3]
            slot = r.int_(slot, where)
            key = r.key(klass, owner, where, classes.rep, *fields[3:])
            if not 0 <= slot < 63 or slot in slot_key or key in key_slot:
                raise r.fail(where, f"slot {slot} is out of range or given twice")
            key_slot[key], slot_key[slot] = slot, key
        released = {}
        for item in r.list_(entry.get("released"), where):
            slot, busy, unknown, age = r.list_(item, where, 4)
            if slot not in slot_key or not isinstance(unknown, bool):
                raise r.fail(where, f"released slot {slot!r:.20} holds nothing")
            # as long ago as when the state was saved: the time the server was down
            # does not count towards settling
            released[slot] = Release(now - max(0.0, r.float_(age, where)), r.ints(busy, where),
                                     unknown)
        conflicts, fast, systems = _tables(classes, slot_key)
        in_use = frozenset(k for s, k in slot_key.items() if s not in released)
        maps[switch] = SlotMap(switch, False, key_slot, slot_key, in_use, released, conflicts,
                               fast, systems)
    return maps


def restore_selections(engine: Engine, data: object) -> Changes:
    """Put ``data`` (from :func:`export_selections`) into ``engine``, freshly made from the
    same configuration; returns the complete state as changes.  Raises
    :class:`SnapshotError`, leaving the engine as it was, when ``data`` does not fit."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise SnapshotError("not a snapshot of this version")
    r = _Reader(engine)
    st = engine._state.clone()
    _radios(r, data, st)
    _settings(r, data, st)
    maps = _maps(r, engine, data, st.now)
    saved_maps = engine._maps
    engine._maps = maps
    try:
        return engine._commit(Work(engine._ix, st), force=True)
    except Exception as exc:
        engine._maps = saved_maps
        raise SnapshotError(f"the engine refused it: {exc}") from exc


__all__ = ["FORMAT", "SnapshotError", "export_selections", "restore_selections"]
