"""Small builders for engine tests: configurations in a few lines, and the examples."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from moas_gui.config import load_config
from moas_gui.config.model import (
    Antenna,
    Config,
    ControlRange,
    FrequencyRange,
    Function,
    Layout,
    Radio,
    RadioRef,
    StationRelays,
    Switch,
    SwitchPort,
    System,
)
from moas_gui.engine import Engine

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

BANDS = {
    160: (1800, 2000), 80: (3500, 4000), 40: (7000, 7300), 30: (10100, 10150),
    20: (14000, 14350), 17: (18068, 18168), 15: (21000, 21450), 12: (24890, 24990),
    10: (28000, 29700),
}

Relays = Mapping[tuple[int, int], Sequence[int]]


def antenna(ident: int, bands: Iterable[int | tuple[float | None, float | None]],
            relays: Relays, *, rx_relays: Relays | None = None,
            persistent: Relays | None = None, conflicts: Sequence[int] | None = None,
            fast: Sequence[int] = (), **flags: object) -> Antenna:
    """An antenna covering ``bands`` (band numbers or (lower, upper) kHz pairs) with the
    same relays per (station, radio) in every range.  It conflicts with itself by default."""
    control = []
    for band in bands:
        lo, hi = BANDS[band] if isinstance(band, int) else band
        stations = tuple(
            StationRelays(station=s, radio=r, relays=frozenset(rel),
                          rx_relays=(frozenset(rx_relays[(s, r)])
                                     if rx_relays and (s, r) in rx_relays else None),
                          persistent_relays=frozenset((persistent or {}).get((s, r), ())))
            for (s, r), rel in relays.items())
        control.append(ControlRange(FrequencyRange(lo, hi), stations))
    return Antenna(
        id=ident, short_name=str(flags.pop("short", f"A{ident}")),
        long_name=str(flags.pop("long", f"Antenna {ident}")),
        conflicts=tuple(conflicts) if conflicts is not None else (ident,),
        fast=tuple(fast), control=tuple(control), **flags)  # type: ignore[arg-type]


def radio(station: int, number: int, port: int, switch: int = 0, **kw: object) -> Radio:
    return Radio(station=station, radio=number, switches=(SwitchPort(switch, port),),
                 **kw)  # type: ignore[arg-type]


def ref(station: int, number: int) -> RadioRef:
    return RadioRef(station, number)


def config(antennas: Iterable[Antenna], radios: Iterable[Radio], *,
           systems: Iterable[System] = (), functions: Iterable[Function] = (),
           layouts: Iterable[Layout] = (), switches: Iterable[Switch] | None = None,
           **misc: object) -> Config:
    return Config(
        antennas=tuple(antennas), radios=tuple(radios), systems=tuple(systems),
        functions=tuple(functions), layouts=tuple(layouts),
        switches=tuple(switches) if switches is not None else (
            Switch(1, "emulator", indicate_tr=True),),
        **misc)  # type: ignore[arg-type]


def so2r(**misc: object) -> Config:
    """Two radios on one switch (ports 1 and 2): a tribander (0), a 40 m beam that also
    works on 15 (1), an 80 m dipole (2) and an all-band vertical (3, listed per band).
    Radio 1 uses relays 0-3, radio 2 relays 8-11; each radio inhibits the other."""
    def both(r1: int) -> dict[tuple[int, int], list[int]]:
        return {(1, 1): [r1], (1, 2): [r1 + 8]}
    every = (0, 1, 2, 3)
    antennas = [
        antenna(0, (20, 15, 10), both(0), fast=every, short="Tri", long="Tribander"),
        antenna(1, (40, 15), both(1), fast=every, short="40 Beam", long="40 m beam"),
        antenna(2, (80,), both(2), fast=every, short="80 Dip", long="80 m dipole"),
        antenna(3, (160, 80, 40, 20, 15, 10), both(3), fast=every, short="Vert",
                long="Vertical"),
    ]
    radios = [radio(1, 1, 1, always=(RadioRef(1, 2),)), radio(1, 2, 2, always=(RadioRef(1, 1),))]
    return config(antennas, radios, **misc)


def example(name: str) -> Config:
    result = load_config(EXAMPLES / f"{name}.moas")
    return result.unwrap()


def engine(name_or_config: str | Config, now: float = 0.0) -> Engine:
    cfg = example(name_or_config) if isinstance(name_or_config, str) else name_or_config
    return Engine(cfg, now)


def pair(e: Engine, station: int, number: int) -> tuple[int | None, int | None]:
    v = e.radio_view(station, number)
    return v.tx, v.rx




def _conflict(cfg: Config, a: int, b: int) -> bool:
    ant_a, ant_b = cfg.antenna(a), cfg.antenna(b)
    assert ant_a is not None and ant_b is not None
    return b in ant_a.conflicts or a in ant_b.conflicts


def _fast(cfg: Config, a: int, b: int) -> bool:
    ant_a, ant_b = cfg.antenna(a), cfg.antenna(b)
    assert ant_a is not None and ant_b is not None
    return b in ant_a.fast or a in ant_b.fast


def table_problems(e: Engine) -> list[str]:
    """Where a switch's slots or tables disagree with the configuration for antennas in use."""
    cfg = e.config
    problems: list[str] = []
    only = cfg.switches[0].id if len(cfg.switches) == 1 else None
    states = e.switch_states()
    used: dict[int, list[tuple[RadioRef, int, str, int]]] = {}
    # 6.10 "PersistSubReceiver ... True if the sub receiver relays should remain set during
    # transmit": such a sub receiver's port transmits on (keeps) its receive antenna
    persisted = set()
    for r in cfg.radios:
        sub = cfg.radio(r.station, r.sub_receiver) if r.sub_receiver is not None else None
        if sub is not None and (r.persist_sub_receiver or sub.persist_sub_receiver):
            persisted.add(sub.ref)
    for view in e.radios():
        r = cfg.radio(view.station, view.radio)
        if r is None:
            continue
        for sp in r.switches:
            w = sp.switch or only
            assert w is not None
            port = states[w].station(sp.port)
            held_tx = view.rx if r.ref in persisted else view.tx
            for role, antenna_id, slot in (("tx", held_tx, port.tx), ("rx", view.rx, port.rx)):
                if antenna_id is None:
                    if slot != 63:
                        problems.append(f"{r.ref} {role}: no antenna but slot {slot}")
                    continue
                want = e.slot_of(w, antenna_id, view.station, view.radio)
                if slot != want:
                    problems.append(f"{r.ref} {role}: slot {slot}, expected {want}")
                used.setdefault(w, []).append((r.ref, antenna_id, role, slot))
            if view.tx is not None and view.rx is not None and port.tx != port.rx:
                pair_ = (min(port.tx, port.rx), max(port.tx, port.rx))
                if (pair_ in states[w].fast) != _fast(cfg, view.tx, view.rx):
                    problems.append(f"{r.ref}: fast table disagrees for {view.tx}/{view.rx}")
    for w, items in used.items():
        table = states[w].conflicts
        for i, (ra, a, _ra, sa) in enumerate(items):
            for rb, b, _rb, sb in items[i + 1:]:
                if ra == rb:
                    continue
                expected = _conflict(cfg, a, b)
                present = (min(sa, sb), max(sa, sb)) in table
                if present and not expected:
                    problems.append(f"switch {w}: slots {sa}/{sb} conflict, antennas {a}/{b} "
                                    "do not")
                if expected and not present and not e.may_share(ra, a, rb, b):
                    problems.append(f"switch {w}: antennas {a}/{b} of {ra} and {rb} conflict "
                                    f"but slots {sa}/{sb} do not")
                if expected and not e.may_share(ra, a, rb, b):
                    problems.append(f"{ra} on {a} and {rb} on {b} conflict")
    return problems


__all__ = ["BANDS", "EXAMPLES", "antenna", "config", "engine", "example", "pair", "radio",
           "ref", "so2r", "table_problems"]
