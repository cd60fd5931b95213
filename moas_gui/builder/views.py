"""The station at a glance, read from the draft's text (so they work while it has errors):
the band x antenna grid, the relay map of each switch, and each layout's buttons.

Each reads the document's plain data defensively (a value of the wrong kind is passed
over; the checks report it) and each edit goes through the :class:`Document`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from moas_gui.config.model import RadioRef

from .document import Document
from .guide import BAND_EDGES

RELAYS_PER_SWITCH = 64


def _list(value: object) -> list[Any]:
    return value if isinstance(value, list) else []


def _dict(value: object) -> dict[str, Any]:
    return value if isinstance(value, dict) else {}


def _number(value: object) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


def radios_of(data: dict[str, Any]) -> list[RadioRef]:
    out = []
    for radio in map(_dict, _list(data.get("Radios"))):
        station, number = radio.get("Station"), radio.get("Radio")
        if isinstance(station, int) and isinstance(number, int):
            out.append(RadioRef(station, number))
    return out


def label_of(antenna: dict[str, Any]) -> str:
    for key in ("ShortName", "LongName", "DisplayName"):
        if isinstance(antenna.get(key), str) and antenna[key]:
            return str(antenna[key])
    return f"Antenna {antenna.get('ID')}"


def covers(entry: dict[str, Any], lower: float, upper: float) -> bool:
    """Whether a ranged entry (Control, Matrix, ...) applies to the band ``lower``-``upper``
    (an entry without a range applies to every band)."""
    low, high = _number(entry.get("LowerFrequency")), _number(entry.get("UpperFrequency"))
    return (low is None or low <= upper) and (high is None or high >= lower)


def served(entry: dict[str, Any], radios: list[RadioRef]) -> list[RadioRef]:
    """The radios a Stations entry serves: one radio, every radio of a station, or all."""
    station, radio = entry.get("Station"), entry.get("Radio")
    if not isinstance(station, int):
        return list(radios)
    if not isinstance(radio, int):
        return [r for r in radios if r.station == station]
    return [RadioRef(station, radio)]


# -- the band x antenna grid -----------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class GridCell:
    tx: tuple[RadioRef, ...] = ()
    rx: tuple[RadioRef, ...] = ()

    def text(self) -> str:
        both = [r for r in self.tx if r in self.rx]
        words = [f"{r.station}/{r.radio}" for r in both]
        words += [f"{r.station}/{r.radio} TX" for r in self.tx if r not in both]
        words += [f"{r.station}/{r.radio} RX" for r in self.rx if r not in both]
        return " ".join(words)


@dataclass(slots=True)
class BandGrid:
    bands: list[tuple[str, float, float]]
    antennas: list[tuple[int, object, str]]
    """(index in "Antennas", ID, name)."""
    radios: list[RadioRef]
    cells: dict[tuple[int, str], GridCell] = field(default_factory=dict)


def band_grid(doc: Document) -> BandGrid:
    """For each antenna and band, the radios that can use it to transmit and to receive."""
    data = _dict(doc.get(()))
    radios = radios_of(data)
    antennas = list(map(_dict, _list(data.get("Antennas"))))
    used = [b for b in BAND_EDGES if any(
        covers(c, b[1], b[2]) and _list(c.get("Stations"))
        for a in antennas for c in map(_dict, _list(a.get("Control"))))]
    grid = BandGrid(used, [(i, a.get("ID"), label_of(a)) for i, a in enumerate(antennas)], radios)
    for index, antenna in enumerate(antennas):
        controls = list(map(_dict, _list(antenna.get("Control"))))
        for name, lower, upper in used:
            refs: list[RadioRef] = []
            for control in (c for c in controls if covers(c, lower, upper)):
                refs += [r for e in map(_dict, _list(control.get("Stations")))
                         for r in served(e, radios) if r not in refs]
            tx = () if antenna.get("RXOnly") is True else tuple(refs)
            rx = () if antenna.get("TXOnly") is True else tuple(refs)
            grid.cells[(index, name)] = GridCell(tx, rx)
    return grid


def set_band_radio(doc: Document, antenna: int, band: tuple[str, float, float],
                   radio: RadioRef, on: bool) -> str:
    """Let ``radio`` use antenna number ``antenna`` (its index) on ``band``, or not; returns
    what could not be done (empty when it was).  A new entry has no relays yet: the
    Antennas page (and the findings) ask for them."""
    name, lower, upper = band
    base = ("Antennas", antenna, "Control")
    controls = [_dict(c) for c in doc.items(base)]
    if on:
        for i, control in enumerate(controls):
            if _number(control.get("LowerFrequency")) == lower and \
                    _number(control.get("UpperFrequency")) == upper:
                doc.append((*base, i, "Stations"), {"Station": radio.station, "Radio": radio.radio,
                                                    "Relays": []},
                           f"station {radio.station} radio {radio.radio} on {name}")
                return ""
        doc.append(base, {"LowerFrequency": lower, "UpperFrequency": upper, "Stations": [
            {"Station": radio.station, "Radio": radio.radio, "Relays": []}]},
            f"station {radio.station} radio {radio.radio} on {name}")
        return ""
    wider = ""
    with doc.transaction(f"station {radio.station} radio {radio.radio} off {name}"):
        for i, control in enumerate(controls):
            if not covers(control, lower, upper):
                continue
            exact = _number(control.get("LowerFrequency")) == lower and \
                _number(control.get("UpperFrequency")) == upper
            entries = list(map(_dict, _list(control.get("Stations"))))
            for j in reversed(range(len(entries))):
                if radio not in served(entries[j], [radio]):
                    continue
                if exact and entries[j].get("Radio") == radio.radio:
                    doc.remove((*base, i, "Stations", j))
                else:
                    wider = (f"station {radio.station} radio {radio.radio} also gets it through "
                             f"Control entry {i + 1}, which covers more than {name} or more "
                             "radios: change that entry on the Antennas page")
    return wider


# -- the relay map -------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class RelayUse:
    relay: int
    antenna: object
    """The antenna's ID (None: a radio's own Extra, Set or Reset relays)."""
    label: str
    radio: RadioRef | None
    band: str
    kind: str


@dataclass(slots=True)
class RelayMap:
    switch: int
    ports: dict[int, RadioRef]
    uses: dict[int, list[RelayUse]]
    """Each relay number (as the file writes it: switch 2's are 100-163) to its uses."""
    flags: dict[int, str]

    def relays(self) -> list[int]:
        base = (self.switch - 1) * 100
        return list(range(base, base + RELAYS_PER_SWITCH))


def _band_text(entry: dict[str, Any]) -> str:
    low, high = _number(entry.get("LowerFrequency")), _number(entry.get("UpperFrequency"))
    if low is None and high is None:
        return "all bands"
    for name, lower, upper in BAND_EDGES:
        if low is not None and high is not None and lower <= low and high <= upper:
            return name
    return f"{low or 0:g}-{high or 0:g} kHz"


def _uses(data: dict[str, Any], radios: list[RadioRef]) -> list[RelayUse]:
    out: list[RelayUse] = []
    for antenna in map(_dict, _list(data.get("Antennas"))):
        for control in map(_dict, _list(antenna.get("Control"))):
            band = _band_text(control)
            for entry in map(_dict, _list(control.get("Stations"))):
                for radio in served(entry, radios):
                    out += [RelayUse(relay, antenna.get("ID"), label_of(antenna), radio, band, kind)
                            for kind in ("Relays", "RXRelays", "PersistentRelays")
                            for relay in _list(entry.get(kind)) if isinstance(relay, int)]
    for own in map(_dict, _list(data.get("Radios"))):
        ref = RadioRef(own.get("Station", 0), own.get("Radio", 0))
        for entry in map(_dict, _list(own.get("Relays"))):
            out += [RelayUse(relay, None, f"radio {ref.station}/{ref.radio}", ref, _band_text(entry),
                             kind) for kind in ("Extra", "Set", "Reset")
                    for relay in _list(entry.get(kind)) if isinstance(relay, int)]
    return out


def relay_map(doc: Document, switch: int) -> RelayMap:
    """Which antenna and radio each relay of switch ``switch`` serves, with the relays
    never used and those two radios use for different antennas that do not conflict
    (both could be selected at once, each closing the other's relay) flagged."""
    data = _dict(doc.get(()))
    radios = radios_of(data)
    ports: dict[int, RadioRef] = {}
    for radio in map(_dict, _list(data.get("Radios"))):
        for port in map(_dict, _list(radio.get("Switches"))):
            if port.get("Switch", 1) == switch and isinstance(port.get("Port"), int):
                ports[port["Port"]] = RadioRef(radio.get("Station", 0), radio.get("Radio", 0))
    base = (switch - 1) * 100
    uses: dict[int, list[RelayUse]] = {r: [] for r in range(base, base + RELAYS_PER_SWITCH)}
    for use in _uses(data, radios):
        if use.relay in uses:
            uses[use.relay].append(use)
    conflicts = _conflicts(data)
    flags = {}
    for relay, found in uses.items():
        if not found:
            flags[relay] = "never used"
            continue
        clash = _clash(found, conflicts)
        if clash:
            flags[relay] = clash
    return RelayMap(switch, ports, uses, flags)


def _conflicts(data: dict[str, Any]) -> set[tuple[object, object]]:
    """Pairs of antennas whose relays may be common: those never selected at once (in
    each other's Conflicts, or made of a common antenna: their InUse lists meet) and the
    antennas of shared systems (one setting for every radio, 5.10)."""
    pairs: set[tuple[object, object]] = set()
    parts: dict[object, set[object]] = {}
    for antenna in map(_dict, _list(data.get("Antennas"))):
        ident = antenna.get("ID")
        parts[ident] = {ident, *(x for x in _list(antenna.get("InUse")) if isinstance(x, int))}
        for other in _list(antenna.get("Conflicts")):
            pairs |= {(ident, other), (other, ident)}
    by_part: dict[object, list[object]] = {}
    for ident, used in parts.items():
        for part in used:
            by_part.setdefault(part, []).append(ident)
    shared = [x for system in map(_dict, _list(data.get("Systems")))
              for x in _list(system.get("SharedAntennas"))]
    for sharing in [*by_part.values(), shared]:  # a shared system's antennas: for all at once
        pairs |= {(a, b) for a in sharing for b in sharing}
    return pairs


def _clash(found: list[RelayUse], conflicts: set[tuple[object, object]]) -> str:
    selecting = [u for u in found if u.kind in ("Relays", "RXRelays") and u.antenna is not None]
    for i, a in enumerate(selecting):
        for b in selecting[i + 1:]:
            if a.radio != b.radio and a.antenna != b.antenna and (a.antenna, b.antenna) not in conflicts:
                assert a.radio is not None and b.radio is not None
                return (f"shared: station {a.radio.station} radio {a.radio.radio} ({a.label}, "
                        f"{a.band}) and station {b.radio.station} radio {b.radio.radio} "
                        f"({b.label}, {b.band}) can have these antennas at once")
    return ""


def switches_of(doc: Document) -> list[int]:
    out = [s.get("ID") for s in map(_dict, doc.items(("Switches",)))]
    return [s for s in out if isinstance(s, int)] or [1]


# -- the layout preview -------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class PreviewButton:
    row: int
    column: int
    kind: str
    id: object
    label: str
    matrix: int
    index: int


def layout_bands(doc: Document, layout: int) -> list[str]:
    """The bands a layout has buttons for (by its Matrix entries' ranges)."""
    matrix = list(map(_dict, doc.items(("Layout", layout, "Matrix"))))
    return [name for name, lower, upper in BAND_EDGES
            if any(_number(m.get("LowerFrequency")) is not None and covers(m, lower, upper)
                   for m in matrix)]


def layout_preview(doc: Document, layout: int, band: str) -> tuple[int, int, list[PreviewButton]]:
    """Rows, columns and the buttons a client draws for a layout on a band."""
    data = _dict(doc.get(()))
    value = _dict(doc.get(("Layout", layout)))
    names = {a.get("ID"): label_of(a) for a in map(_dict, _list(data.get("Antennas")))}
    functions = {f.get("ID"): str(f.get("ShortName") or f.get("Name") or "")
                 for f in map(_dict, _list(data.get("Functions")))}
    edges = next(((lo, hi) for n, lo, hi in BAND_EDGES if n == band), (0.0, 0.0))
    out = []
    for m, entry in enumerate(map(_dict, _list(value.get("Matrix")))):
        if not covers(entry, *edges):
            continue
        for b, button in enumerate(map(_dict, _list(entry.get("Buttons")))):
            kind = str(button.get("Type", ""))
            ident = button.get("ID")
            label = names.get(ident, f"Antenna {ident}") if kind == "Antenna" else \
                functions.get(ident, f"Function {ident}")
            out.append(PreviewButton(int(button.get("Row", 0)), int(button.get("Column", 0)), kind,
                                     ident, label, m, b))
    rows = value.get("Rows") if isinstance(value.get("Rows"), int) else \
        max((p.row + 1 for p in out), default=1)
    columns = value.get("Columns") if isinstance(value.get("Columns"), int) else \
        max((p.column + 1 for p in out), default=1)
    return int(rows), int(columns), out  # type: ignore[arg-type]


def move_button(doc: Document, layout: int, band: str, button: PreviewButton,
                row: int, column: int) -> None:
    """Move ``button`` to ``row``, ``column`` of the layout; a button shown there on the same
    band takes the moved one's place (one undo step)."""
    _, _, shown = layout_preview(doc, layout, band)
    there = [p for p in shown if (p.row, p.column) == (row, column) and p != button]
    base = ("Layout", layout, "Matrix")
    with doc.transaction(f"move {button.label} to row {row + 1}, column {column + 1}"):
        for other in there:
            doc.set((*base, other.matrix, "Buttons", other.index, "Row"), button.row)
            doc.set((*base, other.matrix, "Buttons", other.index, "Column"), button.column)
        doc.set((*base, button.matrix, "Buttons", button.index, "Row"), row)
        doc.set((*base, button.matrix, "Buttons", button.index, "Column"), column)


__all__ = ["BandGrid", "GridCell", "PreviewButton", "RelayMap", "RelayUse", "band_grid",
           "covers", "label_of", "layout_bands", "layout_preview", "move_button", "radios_of",
           "relay_map", "served", "set_band_radio", "switches_of"]
