"""The seven example stations of chapter 7, checked independently of the project's checker.

Each ``examples/*.moas`` file must be strict JSON (no duplicate names, no NaN), use only
the names of chapter 6 (plus ``Fast``, ``HasStop`` and ``ClientAllow``), and be consistent
in itself: everything it names exists, relays belong to a configured switch, conflicts and
fast transitions are symmetric, buttons sit inside their layout, and so on. The last tests
check that each example really shows what its section of chapter 7 describes.
"""

from __future__ import annotations

import json
import re
from collections import Counter, defaultdict
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from typing import Any

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CHAPTER_7 = ["2x6", "small-station", "big-station", "tribander-stack", "multi-multi-20",
             "triplexer", "ms-one-amp"]
NAMES = [*CHAPTER_7, "two-op-shared-tx"]
"""The chapter 7 stations and the project's own two-operator station (shared transmit
antennas, partners, alternate paths and rules, a sub receiver)."""
BANDS = {160: (1800, 2000), 80: (3500, 4000), 40: (7000, 7300), 30: (10100, 10150),
         20: (14000, 14350), 17: (18068, 18168), 15: (21000, 21450), 12: (24890, 24990),
         10: (28000, 29700)}
MAX_ID = 2_147_483_647
SERIAL_MODELS = {"DCU1", "RotorEZ", "Yaesu", "Alfaspid", "RC2800P-A", "RC2800P-X", "Prosistel D"}
FUNCTION_NAMES = {"AntennaSwap", "RXTX", "Store", "Recall", "Share", "Relay", "Inhibit",
                  "Extra", "Partner", "AltActive"}

# ------------------------------------------------------------------ the names of chapter 6

INT, BOOL, STR, INTS, STRS = "int", "bool", "str", "ints", "strs"
RANGE = {"LowerFrequency": INT, "UpperFrequency": INT}
REF = {"Station": INT, "Radio": INT}
SCHEMA: dict[str, dict[str, Any]] = {
    "top": {"Templates": ["Template"], "Antennas": ["Antenna"], "Systems": ["System"],
            "Functions": ["Function"], "Layout": ["Layout"], "RelativeAntennas": ["Relative"],
            "Rotators": ["Rotator"], "Radios": ["Radio"], "Switches": ["Switch"],
            "TCPPort": INT, "UDPPort": INT, "UseN1MMLogger": BOOL, "N1MMLogger": ["N1MM"],
            "ProtectSameBand": BOOL, "StartMOASRotator": BOOL, "ClientAllow": STRS},
    "Template": {"Name": STR, "Manufacturer": STR, "Model": STR, "Type": STR, "Info": ["Info"]},
    "Info": {**RANGE, "Elements": INT, "3dBWidth": INT, "Lobes": INT},
    "Antenna": {"ID": INT, "DisplayName": STR, "Template": STR, "ShortName": STR,
                "LongName": STR, "Enabled": BOOL, "RXOnly": BOOL, "TXOnly": BOOL,
                "NoSelect": BOOL, "Inhibit": BOOL, "SharedTX": BOOL, "InUse": INTS,
                "Rotator": INT, "Offset": INT, "Alternate": INTS, "Conflicts": INTS,
                "Fast": INTS, "Control": ["Control"]},
    "Control": {**RANGE, "Stations": ["StationRelays"]},
    "StationRelays": {**REF, "RadioRXAntenna": BOOL, "Relays": INTS, "RXRelays": INTS,
                      "PersistentRelays": INTS},
    "System": {"ID": INT, "DisplayName": STR, "Antennas": INT, "AdditiveAntennas": INTS,
               "ExclusiveAntennas": INTS, "SharedAntennas": INTS, "AdditiveSystems": INTS,
               "ExclusiveSystems": INTS, "SharedSystems": INTS, "Shared": BOOL},
    "Function": {"ID": INT, "DisplayName": STR, "Name": STR, "ShortName": STR,
                 "LongName": STR, "Longname": STR, "IntParams": INTS, "StringParams": STRS},
    "Layout": {"Rows": INT, "Columns": INT, **REF, "Matrix": ["Matrix"]},
    "Matrix": {**RANGE, "Buttons": ["Button"]},
    "Button": {"Row": INT, "Column": INT, "Type": STR, "ID": INT},
    "Relative": {**REF, "Antennas": ["RelativeList"]},
    "RelativeList": {**RANGE, "IDs": INTS, "RXIDs": INTS},
    "Rotator": {"ID": INT, "ShortName": STR, "LongName": STR, "Invisible": BOOL,
                "CCWLimit": INT, "Rotation": INT, "HasStop": BOOL, "Control": STR,
                "Address": STR, "CommPort": STR, "Model": STR, "Poll": INT},
    "Radio": {**REF, "SubReceiver": INT, "PersistSubReceiver": BOOL, "UseMainFreq": BOOL,
              "AltReceiver": INT, "Interrupt": BOOL, "InterruptModeDelay": INT,
              "Always": ["Ref"], "SameBand": ["Ref"], "Partner": ["Ref"], "InhibitBuss": INTS,
              "Alternate": ["AltRule"], "AltActive": ["Ref"], "OutOfBand": BOOL,
              "InhibitOnlyOnTransmit": BOOL, "Switches": ["SwitchPort"],
              "Relays": ["RadioRelays"]},
    "Ref": REF,
    "AltRule": {**RANGE, "ThisAntennas": INTS, "OtherAntennas": INTS, "Antenna": INT},
    "RadioRelays": {**RANGE, "Extra": INTS, "Set": INTS, "Reset": INTS},
    "SwitchPort": {"Switch": INT, "Port": INT},
    "Switch": {"ID": INT, "Type": STR, "Method": STR, "Port": STR, "Echo": INT,
               "InhibitTime": INT, "InterruptModeDelay": INT, "IndicateTR": BOOL},
    "N1MM": {"Address": STR, "Station": INT},
}
REQUIRED = {"Template": {"Name"}, "Antenna": {"ID"}, "System": {"ID"},
            "Function": {"ID", "Name"}, "Button": {"Row", "Column", "Type", "ID"},
            "Relative": {"Antennas"}, "RelativeList": {"IDs"}, "Rotator": {"ID"},
            "Radio": {"Station", "Radio", "Switches"}, "Ref": {"Station", "Radio"},
            "SwitchPort": {"Port"}, "Switch": {"ID", "Port"}, "N1MM": {"Address", "Station"}}


def _is_int(v: object) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def schema_problems(value: object, kind: str = "top", where: str = "") -> Iterator[str]:
    """Every name outside chapter 6 and every value of the wrong type, with its path."""
    if not isinstance(value, dict):
        yield f"{where or 'file'}: expected a group"
        return
    names = SCHEMA[kind]
    for missing in sorted(REQUIRED.get(kind, set()) - value.keys()):
        yield f"{where}: required \"{missing}\" is missing"
    for key, v in value.items():
        here = f"{where}/{key}"
        if key not in names:
            yield f"{here}: \"{key}\" is not a name chapter 6 knows in a {kind} group"
            continue
        want = names[key]
        if isinstance(want, list):
            if not isinstance(v, list):
                yield f"{here}: expected a list"
                continue
            for i, item in enumerate(v):
                yield from schema_problems(item, want[0], f"{here}[{i}]")
        elif want == INT and not (_is_int(v) and -(2**31) <= v <= MAX_ID):
            yield f"{here}: expected a whole number, got {v!r}"
        elif want == BOOL and not isinstance(v, bool):
            yield f"{here}: expected true or false, got {v!r}"
        elif want == STR and not isinstance(v, str):
            yield f"{here}: expected a string, got {v!r}"
        elif want == INTS and not (isinstance(v, list) and all(_is_int(x) for x in v)):
            yield f"{here}: expected a list of whole numbers, got {v!r}"
        elif want == STRS and not (isinstance(v, list) and all(isinstance(x, str) for x in v)):
            yield f"{here}: expected a list of strings, got {v!r}"


# ------------------------------------------------------------------ strict loading

def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    seen: dict[str, Any] = {}
    for key, value in pairs:
        if key in seen:
            raise ValueError(f"duplicate name {key!r}")
        seen[key] = value
    return seen


def _no_constants(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def strict_loads(text: str) -> Any:
    return json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=_no_constants)


@cache
def load(name: str) -> dict[str, Any]:
    data = strict_loads((EXAMPLES / f"{name}.moas").read_text(encoding="utf-8"))
    assert isinstance(data, dict)
    return data


# ------------------------------------------------------------------ views of a configuration

def antennas(cfg: dict[str, Any]) -> dict[int, dict[str, Any]]:
    return {a["ID"]: a for a in cfg.get("Antennas", [])}


def radios(cfg: dict[str, Any]) -> set[tuple[int, int]]:
    return {(r["Station"], r["Radio"]) for r in cfg.get("Radios", [])}


def systems(cfg: dict[str, Any]) -> dict[int, dict[str, Any]]:
    return {s["ID"]: s for s in cfg.get("Systems", [])}


def member_antennas(system: dict[str, Any]) -> list[int]:
    return [*system.get("AdditiveAntennas", []), *system.get("ExclusiveAntennas", []),
            *system.get("SharedAntennas", [])]


def member_systems(system: dict[str, Any]) -> list[int]:
    return [*system.get("AdditiveSystems", []), *system.get("ExclusiveSystems", []),
            *system.get("SharedSystems", [])]


def home_system(cfg: dict[str, Any]) -> dict[int, int]:
    return {a: s["ID"] for s in cfg.get("Systems", []) for a in member_antennas(s)}


def shared_members(cfg: dict[str, Any]) -> set[int]:
    return {a for s in cfg.get("Systems", []) for a in s.get("SharedAntennas", [])}


def uses(antenna: dict[str, Any]) -> Iterator[tuple[tuple[int, int], dict[str, Any], dict]]:
    """(station/radio, control range, station entry) for every way the antenna is wired."""
    for control in antenna.get("Control", []):
        for entry in control.get("Stations", []):
            yield (entry["Station"], entry["Radio"]), control, entry


def antenna_relays(antenna: dict[str, Any]) -> dict[tuple[int, int], set[int]]:
    out: dict[tuple[int, int], set[int]] = defaultdict(set)
    for ref, _, entry in uses(antenna):
        out[ref] |= set(entry.get("Relays", [])) | set(entry.get("RXRelays", []))
    return out


def usable_by(cfg: dict[str, Any], ref: tuple[int, int]) -> set[int]:
    return {aid for aid, a in antennas(cfg).items() if ref in antenna_relays(a)}


def switch_relays(cfg: dict[str, Any]) -> set[int]:
    return {(s["ID"] - 1) * 100 + n for s in cfg.get("Switches", []) for n in range(64)}


def band_of(group: dict[str, Any]) -> int | None:
    pair = (group.get("LowerFrequency"), group.get("UpperFrequency"))
    return next((b for b, r in BANDS.items() if r == pair), None)


def ranges_overlap(a: dict[str, Any], b: dict[str, Any]) -> bool:
    lo_a, hi_a = a.get("LowerFrequency", 0), a.get("UpperFrequency", MAX_ID)
    lo_b, hi_b = b.get("LowerFrequency", 0), b.get("UpperFrequency", MAX_ID)
    return lo_a <= hi_b and lo_b <= hi_a


def ranged_groups(cfg: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any]]]:
    for t in cfg.get("Templates", []):
        for info in t.get("Info", []):
            yield f"template {t['Name']}", info
    for a in cfg.get("Antennas", []):
        for c in a.get("Control", []):
            yield f"antenna {a['ID']} Control", c
    for i, layout in enumerate(cfg.get("Layout", [])):
        for m in layout.get("Matrix", []):
            if "LowerFrequency" in m or "UpperFrequency" in m:
                yield f"layout {i} Matrix", m
    for rel in cfg.get("RelativeAntennas", []):
        for entry in rel["Antennas"]:
            yield "RelativeAntennas", entry
    for r in cfg.get("Radios", []):
        for group in (*r.get("Alternate", []), *r.get("Relays", [])):
            yield f"radio {r['Station']}/{r['Radio']}", group


examples = pytest.mark.parametrize("name", NAMES)


# ------------------------------------------------------------------ the files

def test_the_examples_folder_holds_exactly_the_seven_stations_of_chapter_7_and_one_more() -> None:
    assert sorted(p.stem for p in EXAMPLES.glob("*.moas")) == sorted(NAMES)
    assert len(CHAPTER_7) == 7 and set(CHAPTER_7) < set(NAMES)


@pytest.mark.parametrize("text, problem", [
    ('{"ID": 1, "ID": 2}', "duplicate"),
    ('{"Relays": [0, 1, ]}', "Expecting value"),
    ('{"Shared": False}', "Expecting value"),
    ('{"Offset": NaN}', "not JSON"),
    ('{"A": 1 "B": 2}', "Expecting ',' delimiter"),
])
def test_the_strict_reader_refuses_what_the_manual_warns_about(text: str, problem: str) -> None:
    with pytest.raises(ValueError, match=problem):
        strict_loads(text)


@examples
def test_example_is_strict_utf8_json_with_one_group(name: str) -> None:
    raw = (EXAMPLES / f"{name}.moas").read_bytes()
    assert not raw.startswith(b"\xef\xbb\xbf"), "no byte-order mark"
    assert raw.endswith(b"}\n")
    assert isinstance(strict_loads(raw.decode("utf-8")), dict)


@examples
def test_example_uses_only_the_names_and_types_of_chapter_6(name: str) -> None:
    assert list(schema_problems(load(name))) == []


def test_the_schema_check_notices_a_misspelt_name_and_a_quoted_number() -> None:
    bad = {"Antennas": [{"ID": "4", "Relay": [1]}]}
    found = list(schema_problems(bad))
    assert any("\"Relay\" is not a name" in p for p in found)
    assert any("expected a whole number, got '4'" in p for p in found)


@examples
def test_project_checker_loads_example_without_errors_or_warnings(name: str) -> None:
    from moas_gui.config import load_config

    result = load_config(EXAMPLES / f"{name}.moas")
    assert [str(p) for p in result.problems] == []
    assert result.config is not None


# ------------------------------------------------------------------ identifiers and references

@examples
def test_identifiers_are_unique_for_each_kind(name: str) -> None:
    cfg = load(name)
    for kind in ("Antennas", "Systems", "Functions", "Rotators", "Switches"):
        ids = [item["ID"] for item in cfg.get(kind, [])]
        assert all(0 <= i <= MAX_ID for i in ids), kind
        assert [i for i, n in Counter(ids).items() if n > 1] == [], kind
    names = [t["Name"] for t in cfg.get("Templates", [])]
    assert len(names) == len(set(names))
    pairs = [(r["Station"], r["Radio"]) for r in cfg["Radios"]]
    assert len(pairs) == len(set(pairs)), "a station/radio pair appears once"


@examples
def test_every_antenna_named_anywhere_exists(name: str) -> None:
    cfg = load(name)
    known = set(antennas(cfg))
    named: list[tuple[str, int]] = []
    for a in cfg["Antennas"]:
        for key in ("InUse", "Alternate", "Conflicts", "Fast"):
            named += [(f"antenna {a['ID']} {key}", i) for i in a.get(key, [])]
    for s in cfg.get("Systems", []):
        named += [(f"system {s['ID']}", i) for i in member_antennas(s)]
    for layout in cfg.get("Layout", []):
        for m in layout["Matrix"]:
            named += [("layout", b["ID"]) for b in m["Buttons"] if b["Type"] == "Antenna"]
    for rel in cfg.get("RelativeAntennas", []):
        for entry in rel["Antennas"]:
            named += [("relative", i) for i in entry["IDs"] + entry.get("RXIDs", [])]
    for r in cfg["Radios"]:
        for rule in r.get("Alternate", []):
            ids = rule.get("ThisAntennas", []) + rule.get("OtherAntennas", [])
            named += [("radio Alternate", i) for i in ids + [rule["Antenna"]]]
    for f in cfg.get("Functions", []):
        if f["Name"] == "Share":
            named += [("Share", i) for i in f["IntParams"][1:]]
    assert [(where, i) for where, i in named if i not in known] == []


@examples
def test_every_template_rotator_and_function_named_exists(name: str) -> None:
    cfg = load(name)
    templates = {t["Name"] for t in cfg.get("Templates", [])}
    rotators = {r["ID"] for r in cfg.get("Rotators", [])}
    functions = {f["ID"] for f in cfg.get("Functions", [])}
    for a in cfg["Antennas"]:
        if "Template" in a:
            assert a["Template"] in templates, a["ID"]
        if "Rotator" in a:
            assert a["Rotator"] in rotators, a["ID"]
    for layout in cfg.get("Layout", []):
        for m in layout["Matrix"]:
            for b in m["Buttons"]:
                assert b["Type"] in ("Antenna", "Function")
                if b["Type"] == "Function":
                    assert b["ID"] in functions


@examples
def test_every_station_and_radio_named_is_in_radios(name: str) -> None:
    cfg = load(name)
    known = radios(cfg)
    stations = {s for s, _ in known}
    named: list[tuple[str, tuple[int, int]]] = []
    for a in cfg["Antennas"]:
        named += [(f"antenna {a['ID']}", ref) for ref, _, _ in uses(a)]
    for r in cfg["Radios"]:
        for key in ("Always", "SameBand", "Partner", "AltActive"):
            for ref in r.get(key, []):
                named.append((f"radio {key}", (ref["Station"], ref["Radio"])))
                assert (ref["Station"], ref["Radio"]) != (r["Station"], r["Radio"])
    for group in (*cfg.get("Layout", []), *cfg.get("RelativeAntennas", [])):
        if "Radio" in group:
            named.append(("layout or relative", (group["Station"], group["Radio"])))
        elif "Station" in group:
            assert group["Station"] in stations
    for f in cfg.get("Functions", []):
        p = f["IntParams"]
        if f["Name"] in ("AntennaSwap", "Partner"):
            named += [(f"function {f['ID']}", (p[0], p[1])), (f"function {f['ID']}", (p[2], p[3]))]
    for entry in cfg.get("N1MMLogger", []):
        assert entry["Station"] in stations
    assert [(where, ref) for where, ref in named if ref not in known] == []


@examples
def test_each_control_range_wires_a_radio_at_most_once(name: str) -> None:
    for a in load(name)["Antennas"]:
        assert a.get("Control"), f"antenna {a['ID']} has no relays at all"
        for c in a["Control"]:
            refs = [(e["Station"], e["Radio"]) for e in c["Stations"]]
            assert len(refs) == len(set(refs)), a["ID"]
            assert all(e.get("Relays") for e in c["Stations"]), a["ID"]


# ------------------------------------------------------------------ relays and switches

@examples
def test_every_relay_belongs_to_a_configured_switch(name: str) -> None:
    cfg = load(name)
    owned = switch_relays(cfg)
    used: list[tuple[str, int]] = []
    for a in cfg["Antennas"]:
        for _, _, e in uses(a):
            for key in ("Relays", "RXRelays", "PersistentRelays"):
                used += [(f"antenna {a['ID']} {key}", n) for n in e.get(key, [])]
    for r in cfg["Radios"]:
        for group in r.get("Relays", []):
            for key in ("Extra", "Set", "Reset"):
                used += [(f"radio {key}", n) for n in group.get(key, [])]
    for f in cfg.get("Functions", []):
        if f["Name"] == "Relay":
            used.append((f"function {f['ID']}", f["IntParams"][0]))
    assert [(where, n) for where, n in used if n not in owned] == []


@examples
def test_persistent_relays_are_some_of_the_antennas_own_relays(name: str) -> None:
    for a in load(name)["Antennas"]:
        for _, _, e in uses(a):
            assert set(e.get("PersistentRelays", [])) <= set(e["Relays"]), a["ID"]


@examples
def test_switches_are_the_built_in_emulator_and_report_transmit(name: str) -> None:
    for s in load(name)["Switches"]:
        assert 1 <= s["ID"] <= 99
        assert s["Port"] == "emulator"
        assert s["IndicateTR"] is True
        assert s.get("Type", "MOAS II") == "MOAS II"


@examples
def test_radios_sit_on_ports_one_to_six_of_configured_switches_one_radio_a_port(name: str) -> None:
    cfg = load(name)
    switch_ids = {s["ID"] for s in cfg["Switches"]}
    taken: set[tuple[int, int]] = set()
    for r in cfg["Radios"]:
        assert r["Switches"], "every radio is wired to a switch"
        for sp in r["Switches"]:
            assert 1 <= sp["Port"] <= 6
            if len(switch_ids) > 1:
                assert "Switch" in sp, "with several switches each port says its switch"
            switch = sp.get("Switch", next(iter(switch_ids)))
            assert switch in switch_ids
            assert (switch, sp["Port"]) not in taken
            taken.add((switch, sp["Port"]))


@examples
def test_antennas_sharing_a_relay_across_radios_are_declared_in_conflict(name: str) -> None:
    """A relay two radios would both drive is common hardware: one must lock out the other."""
    cfg = load(name)
    ants = antennas(cfg)
    shared = shared_members(cfg)
    wiring = {aid: antenna_relays(a) for aid, a in ants.items()}
    missing = []
    for a, ra in wiring.items():
        for b, rb in wiring.items():
            if a >= b or (a in shared and b in shared):
                continue
            clash = any(ra[x] & rb[y] for x in ra for y in rb if x != y)
            if clash and b not in ants[a].get("Conflicts", []):
                missing.append((a, b))
    assert missing == []


@examples
def test_transmit_and_function_relays_never_drive_an_antenna(name: str) -> None:
    cfg = load(name)
    antenna_side = set().union(*(set().union(*antenna_relays(a).values(), set())
                                 for a in cfg["Antennas"]))
    other = set()
    for r in cfg["Radios"]:
        for group in r.get("Relays", []):
            other |= set(group.get("Extra", []) + group.get("Set", []) + group.get("Reset", []))
    other |= {f["IntParams"][0] for f in cfg.get("Functions", []) if f["Name"] == "Relay"}
    assert antenna_side & other == set()


# ------------------------------------------------------------------ conflicts, fast, alternates

@examples
def test_conflicts_are_mutual_and_each_antenna_blocks_itself_unless_shared(name: str) -> None:
    cfg = load(name)
    ants = antennas(cfg)
    shared = shared_members(cfg)
    for aid, a in ants.items():
        conflicts = a.get("Conflicts", [])
        assert len(conflicts) == len(set(conflicts)), aid
        if aid in shared:
            assert not set(conflicts) & shared, f"shared antenna {aid} must not lock out sharers"
        else:
            assert aid in conflicts, f"antenna {aid} does not conflict with itself"
        for other in conflicts:
            assert aid in ants[other].get("Conflicts", []), (aid, other)


@examples
def test_fast_and_alternate_lists_are_mutual(name: str) -> None:
    ants = antennas(load(name))
    for key in ("Fast", "Alternate"):
        for aid, a in ants.items():
            for other in a.get(key, []):
                assert aid in ants[other].get(key, []), (key, aid, other)


@examples
def test_alternate_paths_reach_the_same_antenna_by_different_relays(name: str) -> None:
    ants = antennas(load(name))
    for aid, a in ants.items():
        for other in a.get("Alternate", []):
            assert other != aid
            assert antenna_relays(a) != antenna_relays(ants[other])
            bands = {band_of(c) for c in a["Control"]}
            assert bands == {band_of(c) for c in ants[other]["Control"]}


# ------------------------------------------------------------------ systems

@examples
def test_an_antenna_is_in_one_system_at_most_and_no_system_contains_itself(name: str) -> None:
    cfg = load(name)
    syss = systems(cfg)
    members = [a for s in syss.values() for a in member_antennas(s)]
    assert [a for a, n in Counter(members).items() if n > 1] == []
    children = [c for s in syss.values() for c in member_systems(s)]
    assert [c for c, n in Counter(children).items() if n > 1] == [], "a system has one parent"
    assert all(c in syss for c in children)
    for start in syss:
        seen, todo = set(), list(member_systems(syss[start]))
        while todo:
            child = todo.pop()
            assert child != start, f"system {start} contains itself"
            if child not in seen:
                seen.add(child)
                todo += member_systems(syss[child])


def _root(cfg: dict[str, Any], system_id: int) -> int:
    parent = {c: s["ID"] for s in cfg.get("Systems", []) for c in member_systems(s)}
    while system_id in parent:
        system_id = parent[system_id]
    return system_id


@examples
def test_combinations_are_unique_and_built_from_their_own_system_tree(name: str) -> None:
    cfg = load(name)
    ants = antennas(cfg)
    home = home_system(cfg)
    for aid, a in ants.items():
        parts = [p for p in a.get("InUse", []) if p != aid]
        if not parts:
            continue
        assert aid in home, f"combination {aid} is in no system"
        for p in parts:
            assert p in home and _root(cfg, home[p]) == _root(cfg, home[aid]), (aid, p)
            assert not [q for q in ants[p].get("InUse", []) if q != p], "parts are single"
    for ref in radios(cfg):
        seen: dict[frozenset[int], int] = {}
        for aid in sorted(usable_by(cfg, ref)):
            key = frozenset(ants[aid].get("InUse") or [aid])
            assert key not in seen, f"{ref}: antennas {seen.get(key)} and {aid} are the same set"
            seen[key] = aid


@examples
def test_electric_rotators_turn_whole_systems_and_serial_ones_name_a_model(name: str) -> None:
    cfg = load(name)
    ants = antennas(cfg)
    home = home_system(cfg)
    syss = systems(cfg)
    for rot in cfg.get("Rotators", []):
        assert rot["Control"] in ("Serial", "Electrical", "Test")
        users = [aid for aid, a in ants.items() if a.get("Rotator") == rot["ID"]]
        assert users, f"rotator {rot['ID']} turns nothing"
        if rot["Control"] == "Serial":
            assert rot["Model"] in SERIAL_MODELS
            assert rot["CommPort"] and rot.get("Poll", 1000) > 0
        if rot["Control"] == "Electrical":
            system_ids = {home.get(aid) for aid in users}
            assert None not in system_ids and len(system_ids) == 1
            members = member_antennas(syss[system_ids.pop()])
            assert sorted(members) == sorted(users)
            offsets = [ants[aid]["Offset"] for aid in users]
            assert len(set(offsets)) == len(offsets), "each direction has its own offset"
            assert all(0 <= o < 360 for o in offsets)
    serial = any(r["Control"] == "Serial" for r in cfg.get("Rotators", []))
    assert cfg["StartMOASRotator"] is serial


# ------------------------------------------------------------------ layouts and relative lists

@examples
def test_layout_buttons_lie_inside_their_grid_and_never_share_a_place(name: str) -> None:
    for layout in load(name).get("Layout", []):
        rows, cols = layout["Rows"], layout["Columns"]
        placed: list[tuple[dict[str, Any], tuple[int, int]]] = []
        for m in layout["Matrix"]:
            for b in m["Buttons"]:
                assert 0 <= b["Row"] < rows and 0 <= b["Column"] < cols, b
                place = (b["Row"], b["Column"])
                clash = [other for other, p in placed if p == place and ranges_overlap(other, m)]
                assert clash == [], f"two buttons at {place}"
                placed.append((m, place))


@examples
def test_layout_buttons_show_antennas_usable_on_that_band(name: str) -> None:
    cfg = load(name)
    ants = antennas(cfg)
    for layout in cfg.get("Layout", []):
        for m in layout["Matrix"]:
            for b in m["Buttons"]:
                if b["Type"] != "Antenna" or not {"LowerFrequency", "UpperFrequency"} & m.keys():
                    continue  # a Matrix entry without a range is for every frequency
                bands = {band_of(c) for c in ants[b["ID"]]["Control"]}
                assert band_of(m) in bands, (b["ID"], band_of(m))


@examples
def test_relative_lists_match_their_receive_lists_and_do_not_overlap(name: str) -> None:
    cfg = load(name)
    ants = antennas(cfg)
    for rel in cfg.get("RelativeAntennas", []):
        entries = rel["Antennas"]
        for i, entry in enumerate(entries):
            if "RXIDs" in entry:
                assert len(entry["RXIDs"]) == len(entry["IDs"])
            for aid in entry["IDs"]:
                assert band_of(entry) in {band_of(c) for c in ants[aid]["Control"]}
            assert not any(ranges_overlap(entry, other) for other in entries[i + 1:])


@examples
def test_frequency_ranges_are_whole_amateur_bands_listed_separately(name: str) -> None:
    for where, group in ranged_groups(load(name)):
        assert band_of(group) is not None, f"{where}: {group.get('LowerFrequency')}-" \
                                          f"{group.get('UpperFrequency')} is not one band"
    for a in load(name)["Antennas"]:
        bands = [band_of(c) for c in a["Control"]]
        assert len(bands) == len(set(bands)), a["ID"]


# ------------------------------------------------------------------ names, functions, misc

@examples
def test_antennas_have_short_names_that_fit_a_button_and_distinct_long_names(name: str) -> None:
    cfg = load(name)
    for a in cfg["Antennas"]:
        assert 0 < len(a["ShortName"]) <= 14, a["ShortName"]
        assert a["LongName"].strip()
    long_names = [a["LongName"] for a in cfg["Antennas"]]
    assert len(long_names) == len(set(long_names))


@examples
def test_a_radio_never_sees_two_buttons_with_the_same_label_on_one_band(name: str) -> None:
    cfg = load(name)
    for ref in radios(cfg):
        labels: dict[int | None, list[str]] = defaultdict(list)
        for a in cfg["Antennas"]:
            for who, control, _ in uses(a):
                if who == ref:
                    labels[band_of(control)].append(a["ShortName"])
        for band, names in labels.items():
            assert len(names) == len(set(names)), (ref, band, names)


@examples
def test_functions_have_known_names_and_parameters_that_fit(name: str) -> None:
    cfg = load(name)
    syss = systems(cfg)
    for f in cfg.get("Functions", []):
        assert f["Name"] in FUNCTION_NAMES
        p = f.get("IntParams", [])
        if f["Name"] in ("RXTX", "Store", "Recall"):
            assert p == []
        elif f["Name"] in ("AntennaSwap", "Partner"):
            assert len(p) == 4 and (p[0], p[1]) != (p[2], p[3])
        elif f["Name"] == "Share":
            system = syss[p[0]]
            assert system.get("SharedAntennas"), "Share switches a system with shared antennas"
            assert not set(p[1:]) & set(system["SharedAntennas"]), "preferences are unshared"
        elif f["Name"] == "Relay":
            assert len(p) == 1 or len(p) >= 3


@examples
def test_miscellaneous_items_are_set(name: str) -> None:
    cfg = load(name)
    assert 0 < cfg["TCPPort"] < 65536 and 0 < cfg["UDPPort"] < 65536
    assert cfg["TCPPort"] == 12059 and cfg["UDPPort"] == 12060
    assert cfg["UseN1MMLogger"] is True
    assert {"Address": "127.0.0.1", "Station": 1} in cfg["N1MMLogger"]
    assert isinstance(cfg["ProtectSameBand"], bool)
    assert isinstance(cfg["StartMOASRotator"], bool)


@examples
def test_radios_interlock_or_share_a_buss_so_only_one_transmits_at_a_time(name: str) -> None:
    cfg = load(name)
    receivers = {(r["Station"], n) for r in cfg["Radios"]
                 for n in (r.get("SubReceiver"), r.get("AltReceiver")) if n is not None}
    by_ref = {(r["Station"], r["Radio"]): r for r in cfg["Radios"]
              if (r["Station"], r["Radio"]) not in receivers}
    for me, r in by_ref.items():
        assert r["OutOfBand"] is True
        guards = {(x["Station"], x["Radio"]) for x in r.get("Always", []) + r.get("SameBand", [])}
        for other, o in by_ref.items():
            if other == me:
                continue
            busses = set(r.get("InhibitBuss", [])) & set(o.get("InhibitBuss", []))
            assert other in guards or busses, f"{me} is never inhibited by {other}"


# ------------------------------------------------------------------ what each station shows

def test_2x6_wires_six_all_band_antennas_to_relays_0_to_11() -> None:
    cfg = load("2x6")
    ants = antennas(cfg)
    assert sorted(ants) == [1, 2, 3, 4, 5, 6]
    for port, a in ants.items():
        assert {band_of(c) for c in a["Control"]} == set(BANDS)
        assert antenna_relays(a) == {(1, 1): {port - 1}, (1, 2): {port + 5}}
    for key in ("Templates", "Systems", "Functions", "RelativeAntennas", "Rotators"):
        assert cfg[key] == [], "a template: the group is there, empty"


def test_small_station_offers_swap_on_its_buttons_and_a_bandpass_filter_per_band() -> None:
    cfg = load("small-station")
    ants = antennas(cfg)
    assert len(ants) == 4
    bands = {a["ShortName"]: {band_of(c) for c in a["Control"]} for a in ants.values()}
    assert bands["Tribander"] == {20, 15, 10}
    assert bands["40 Dipole"] == {40, 15}
    assert bands["80 Dipole"] == {80}
    assert bands["Vertical"] == set(BANDS)
    swap = [f for f in cfg["Functions"] if f["Name"] == "AntennaSwap"]
    assert swap and swap[0]["IntParams"] == [1, 1, 1, 2]
    buttons = [b for m in cfg["Layout"][0]["Matrix"] for b in m["Buttons"]]
    assert any(b["Type"] == "Function" and b["ID"] == swap[0]["ID"] for b in buttons)
    # the same antenna on different bands goes through a different filter relay
    tribander = next(a for a in ants.values() if a["ShortName"] == "Tribander")
    filters = [set(e["Relays"]) for _, _, e in uses(tribander) if e["Radio"] == 1]
    assert len({frozenset(f) for f in filters}) == 3


def test_big_station_has_three_electric_four_squares_and_thirteen_yagis() -> None:
    cfg = load("big-station")
    ants = antennas(cfg)
    electrical = [r for r in cfg["Rotators"] if r["Control"] == "Electrical"]
    assert len(electrical) == 3
    for rot in electrical:
        users = [a for a in ants.values() if a.get("Rotator") == rot["ID"]]
        assert sorted(a["Offset"] for a in users) == [45, 135, 225, 315]
        assert {band_of(a["Control"][0]) for a in users} <= {160, 80, 40}
    templates = {t["Name"]: t for t in cfg["Templates"]}
    yagis = [a for a in ants.values() if templates[a["Template"]]["Type"] == "yagi"
             and not [p for p in a.get("InUse", []) if p != a["ID"]]]
    assert len(yagis) == 13
    assert sum(1 for r in cfg["Rotators"] if r["Control"] == "Serial") == 9
    assert {f["Name"] for f in cfg["Functions"]} >= {"Store", "Recall"}


def test_big_station_beverages_are_one_shared_receive_only_system_on_160_and_80() -> None:
    cfg = load("big-station")
    ants = antennas(cfg)
    bev = [s for s in cfg["Systems"] if s.get("SharedAntennas")]
    assert len(bev) == 1 and bev[0]["Shared"] is True
    members = bev[0]["SharedAntennas"]
    assert len(members) == 3
    for aid in members:
        assert ants[aid]["RXOnly"] is True
        assert {band_of(c) for c in ants[aid]["Control"]} == {160, 80}
        # receive on a beverage while transmitting on the 4-square of the band
        square = [x for x in ants[aid]["Fast"] if ants[x].get("Rotator") in
                  {r["ID"] for r in cfg["Rotators"] if r["Control"] == "Electrical"}]
        assert len(square) == 8


def test_big_station_stacks_mix_additive_and_exclusive_and_the_knob_has_all_seven() -> None:
    cfg = load("big-station")
    stacks = [s for s in cfg["Systems"] if s.get("AdditiveAntennas")]
    assert len(stacks) == 3
    knob = next(layout for layout in cfg["Layout"] if layout["Rows"] == 1)
    assert knob["Columns"] == 50
    knob_ids = {b["ID"] for m in knob["Matrix"] for b in m["Buttons"]}
    for s in stacks:
        assert len(s["AdditiveAntennas"]) == 3 and len(s["ExclusiveAntennas"]) == 4
        assert set(member_antennas(s)) <= knob_ids


def test_tribander_stack_single_antennas_have_a_main_and_a_sub_feed_path() -> None:
    ants = antennas(load("tribander-stack"))
    singles = [a for a in ants.values() if a.get("InUse") == [a["ID"]]]
    assert len(singles) == 3
    for a in singles:
        (sub,) = a["Alternate"]
        # the sub feed path cannot be taken by the main feed's other users ...
        assert sub in a["Conflicts"]
    for a in ants.values():
        if len(a.get("InUse", [])) > 1:
            assert "Alternate" not in a, "two or more antennas need the main feed"
    # both radios can reach every path
    for a in ants.values():
        assert set(antenna_relays(a)) == {(1, 1), (1, 2)}


def test_multi_multi_20_station_1_has_more_choices_than_a_switch_has_slots() -> None:
    cfg = load("multi-multi-20")
    station1, station2 = usable_by(cfg, (1, 1)), usable_by(cfg, (1, 2))
    assert len(station1) > 63
    assert 70 <= len(station1) <= 80, "the manual counts 78"
    ants = antennas(cfg)
    square = {a for a in ants if ants[a].get("Rotator") in
              {r["ID"] for r in cfg["Rotators"] if r["Control"] == "Electrical"}}
    assert len(square) == 4 and square <= station2 and not square & station1
    assert all(ants[a]["Control"][0]["LowerFrequency"] == 14000 for a in ants)


def test_multi_multi_20_six_el_and_africa_are_additive_on_1_and_exclusive_on_2() -> None:
    cfg = load("multi-multi-20")
    ants = antennas(cfg)
    additive = {a for s in cfg["Systems"] for a in s.get("AdditiveAntennas", [])}
    station1, station2 = usable_by(cfg, (1, 1)), usable_by(cfg, (1, 2))
    for word in ("6 el", "Africa"):
        s1 = [a for a in station1 if ants[a]["LongName"].startswith(word)
              and "InUse" not in ants[a]]
        s2 = [a for a in station2 if ants[a]["LongName"].startswith(word)
              and "InUse" not in ants[a]]
        assert len(s1) == 1 and s1[0] in additive
        assert len(s2) == 1 and s2[0] not in additive
    assert any(s.get("AdditiveSystems") for s in cfg["Systems"]), "nested systems"


def test_multi_multi_20_swap_is_only_on_station_1_and_both_share_an_inhibit_buss() -> None:
    cfg = load("multi-multi-20")
    swap = next(f["ID"] for f in cfg["Functions"] if f["Name"] == "AntennaSwap")
    for layout in cfg["Layout"]:
        has_swap = any(b["Type"] == "Function" and b["ID"] == swap
                       for m in layout["Matrix"] for b in m["Buttons"])
        assert has_swap == (layout["Radio"] == 1 and layout["Rows"] > 1)
    busses = [set(r["InhibitBuss"]) for r in cfg["Radios"]]
    assert busses[0] & busses[1]
    assert cfg["ProtectSameBand"] is False, "both stations work 20 m"
    knobs = [layout for layout in cfg["Layout"] if layout["Rows"] == 1 and layout["Radio"] == 1]
    knob_ids = {b["ID"] for m in knobs[0]["Matrix"] for b in m["Buttons"]}
    assert len(knob_ids) < len(usable_by(cfg, (1, 1))), "the knob gets a limited set"


def test_triplexer_share_function_switches_a_stack_that_starts_unshared() -> None:
    cfg = load("triplexer")
    ants = antennas(cfg)
    share = next(f for f in cfg["Functions"] if f["Name"] == "Share")
    system = systems(cfg)[share["IntParams"][0]]
    assert system["Shared"] is False
    shared = system["SharedAntennas"]
    assert len(shared) == 7
    for aid in shared:
        a = ants[aid]
        assert a["Fast"] == [], "no TX on one stack setting and RX on another"
        assert set(antenna_relays(a)) == {(1, 1), (1, 2)}
    # everything the tribander-stack example has is still there
    assert set(antennas(load("tribander-stack"))) < set(ants)


def test_ms_one_amp_sends_yaesu_band_data_and_lights_each_radios_led() -> None:
    cfg = load("ms-one-amp")
    yaesu = {160: 1, 80: 2, 40: 3, 30: 4, 20: 5, 17: 6, 15: 7, 12: 8, 10: 9}
    lines = [44, 45, 46, 47]  # band data A, B, C, D
    leds = {}
    transmitters = [r for r in cfg["Radios"] if r["Radio"] in (1, 2)]
    for r in transmitters:
        groups = r["Relays"]
        assert {band_of(g) for g in groups} == set(BANDS)
        for g in groups:
            code = sum(1 << i for i, relay in enumerate(lines) if relay in g["Extra"])
            assert code == yaesu[band_of(g)]
        common = set.intersection(*(set(g["Extra"]) - set(lines) for g in groups))
        leds[r["Radio"]] = common
    amp_key = leds[1] & leds[2]
    assert len(amp_key) == 1, "one amplifier keying relay for both radios"
    assert len(leds[1] - amp_key) == 1 and len(leds[2] - amp_key) == 1
    assert leds[1] - amp_key != leds[2] - amp_key
    r1, r2 = transmitters
    # the amplifier's 2x2 switches follow whichever radio transmits last
    assert all(g["Reset"] == r2["Relays"][0]["Set"] for g in r1["Relays"])


def test_ms_one_amp_moves_the_listener_to_the_vertical_when_both_use_tribanders_on_20() -> None:
    cfg = load("ms-one-amp")
    ants = antennas(cfg)
    for r in cfg["Radios"][:2]:
        (rule,) = r["Alternate"]
        assert band_of(rule) == 20
        assert ants[rule["Antenna"]]["ShortName"] == "Vertical"
        assert 20 in {band_of(c) for c in ants[rule["Antenna"]]["Control"]}
        assert set(rule["ThisAntennas"]) == set(rule["OtherAntennas"])
        assert len(r["AltActive"]) == 1
    on_160 = [a for a in ants.values() if 160 in {band_of(c) for c in a["Control"]}
              and not a.get("RXOnly")]
    assert len(on_160) == 1, "only one station at a time on 160"
    assert cfg["ProtectSameBand"] is False


def test_ms_one_amp_has_a_sub_receiver_on_a_receive_loop_at_the_radios_rx_input() -> None:
    cfg = load("ms-one-amp")
    r1 = cfg["Radios"][0]
    assert r1["SubReceiver"] == 3
    sub = next(r for r in cfg["Radios"] if r["Radio"] == 3)
    assert sub["Switches"] == [{"Port": 3}] and "Relays" not in sub
    (loop,) = [a for a in antennas(cfg).values() if a.get("RXOnly")]
    assert {band_of(c) for c in loop["Control"]} == {160, 80}
    for c in loop["Control"]:
        assert {(e["Station"], e["Radio"]) for e in c["Stations"]} == {(1, 1), (1, 2), (1, 3)}
        assert all(e["RadioRXAntenna"] is True for e in c["Stations"])


# ------------------------------------------------------------------ the guide and the list

GUIDE = EXAMPLES.parent / "docs" / "configuration.md"


def test_the_guide_and_the_examples_readme_speak_of_every_example() -> None:
    guide = GUIDE.read_text(encoding="utf-8")
    readme = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    for name in NAMES:
        assert f"(`{name}.moas`)" in guide, f"no section for {name} in the guide"
        assert f"| `{name}.moas` |" in readme, f"no line for {name} in examples/README.md"


def test_json_snippets_in_the_guide_are_valid_json() -> None:
    blocks = re.findall(r"```json\n(.*?)```", GUIDE.read_text(encoding="utf-8"), re.DOTALL)
    assert len(blocks) >= 10
    for block in blocks:
        for text in (block, "{" + block + "}", "[" + block + "]"):
            try:
                strict_loads(text)
                break
            except ValueError:
                continue
        else:
            pytest.fail(f"not JSON, even as a list or group:\n{block}")


def test_two_op_shared_tx_shares_the_tribander_between_interlocked_partners() -> None:
    cfg = load("two-op-shared-tx")
    ants = antennas(cfg)
    by_ref = {(r["Station"], r["Radio"]): r for r in cfg["Radios"]}
    one, two = by_ref[(1, 1)], by_ref[(2, 1)]
    assert ants[0].get("SharedTX") is True
    assert {"Station": 2, "Radio": 1} in one["Always"] and {"Station": 1, "Radio": 1} in two["Always"]
    assert one["Partner"] == [{"Station": 2, "Radio": 1}] and two["Partner"] == [{"Station": 1, "Radio": 1}]
    # the dipole on two feeds, each feed shared with another antenna
    assert ants[4]["Alternate"] == [5] and ants[5]["Alternate"] == [4]
    assert 3 in ants[4]["Conflicts"] and 6 in ants[5]["Conflicts"]
    # the sub receiver's flags sit on the main radio's entry (6.10's table)
    assert one["SubReceiver"] == 2 and one["UseMainFreq"] is True
    assert one["PersistSubReceiver"] is True
    assert "UseMainFreq" not in by_ref[(1, 2)] and by_ref[(1, 2)]["Switches"] == [{"Port": 3}]
    assert all(rule["Antenna"] == 7 for r in (one, two) for rule in r["Alternate"])
    assert one["AltActive"] == [{"Station": 2, "Radio": 1}]
