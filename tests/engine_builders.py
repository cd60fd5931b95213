"""Small builders for engine tests: configurations in a few lines, and the examples."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from moas_gui.engine import Engine
from moas_gui.engine.config import load_config
from moas_gui.engine.config.model import (
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


__all__ = ["BANDS", "EXAMPLES", "antenna", "config", "engine", "example", "pair", "radio",
           "ref", "so2r"]
