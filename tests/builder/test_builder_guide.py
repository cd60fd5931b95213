"""The new-station guide: examples/small-station.moas's station built from nothing through
the model layer (the guide for the radios, switch and antennas; the builder's ordinary
edits for the rest), then compared with the example value by value."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.builder import Document
from moas_gui.builder.guide import Guide, GuideAntenna, GuideRadio, GuideSwitch, apply_guide, band
from moas_gui.config import load_config, parse_config
from moas_gui.config.model import RadioRef

ROOT = Path(__file__).resolve().parents[2]
SMALL = ROOT / "examples" / "small-station.moas"
HF = ("160 m", "80 m", "40 m", "30 m", "20 m", "17 m", "15 m", "12 m", "10 m")


def small_station_guide() -> Guide:
    """The answers a builder gives for the small station: two radios on a 2x4 antenna
    switch, each with a band filter (160, 80, 40, 20, 15, 10 m, and the WARC bands on
    its "other" relay)."""
    fast = (0, 1, 2, 3)
    return Guide(
        radios=[GuideRadio(1, 1, port=1), GuideRadio(1, 2, port=2)],
        switches=[GuideSwitch(1, "emulator")],
        outputs=4,
        filters={RadioRef(1, 1): 16, RadioRef(1, 2): 24},
        filter_bands=tuple(band(b) for b in ("160 m", "80 m", "40 m", "20 m", "15 m", "10 m")),
        antennas=[
            GuideAntenna(0, "Tribander", 1, tuple(band(b) for b in ("20 m", "15 m", "10 m")),
                         "Triband Yagi 20-15-10", "Tribander", fast=fast),
            GuideAntenna(1, "40 Dipole", 2, (band("40 m"), band("15 m")),
                         "40 m dipole (also 15 m)", "40 m dipole", fast=fast),
            GuideAntenna(2, "80 Dipole", 3, (band("80 m"),), "80 m dipole", "80 m dipole",
                         fast=fast),
            GuideAntenna(3, "Vertical", 4, tuple(band(b) for b in HF), "All-band vertical",
                         "All-band vertical", fast=fast),
        ])


def info(lower: float, upper: float, elements: int, width: int | None = None,
         lobes: int | None = None) -> dict[str, object]:
    out: dict[str, object] = {"LowerFrequency": lower, "UpperFrequency": upper, "Elements": elements}
    if width is not None:
        out["3dBWidth"] = width
    if lobes is not None:
        out["Lobes"] = lobes
    return out


def the_rest(doc: Document) -> None:
    """What the guide leaves to the pages: templates, functions, layout, relative
    antennas, the rotator, the radios' relations and the miscellaneous items."""
    doc.append(("Templates",), {"Name": "Tribander", "Type": "yagi", "Info": [
        info(14000, 14350, 3, 70, 1), info(21000, 21450, 3, 68, 1), info(28000, 29700, 3, 66, 1)]})
    doc.append(("Templates",), {"Name": "40 m dipole", "Type": "dipole", "Info": [
        info(7000, 7300, 1, 80, 2), info(21000, 21450, 1)]})
    doc.append(("Templates",), {"Name": "80 m dipole", "Type": "dipole",
                                "Info": [info(3500, 4000, 1, 80, 2)]})
    doc.append(("Templates",), {"Name": "All-band vertical", "Type": "vertical",
                                "Info": [info(*band(b), 1) for b in HF]})
    doc.set(("Systems",), [])
    doc.append(("Functions",), {"ID": 0, "Name": "AntennaSwap", "ShortName": "Swap",
                                "LongName": "Swap antennas between radio 1 and radio 2",
                                "IntParams": [1, 1, 1, 2], "StringParams": []})
    doc.append(("Functions",), {"ID": 1, "Name": "RXTX", "ShortName": "RX=TX",
                                "LongName": "Set RX antenna to TX antenna",
                                "IntParams": [], "StringParams": []})
    matrix = []
    for name, column_ids in (("160 m", [(2, 3)]), ("80 m", [(1, 2), (2, 3)]),
                             ("40 m", [(1, 1), (2, 3)]), ("30 m", [(2, 3)]),
                             ("20 m", [(0, 0), (2, 3)]), ("17 m", [(2, 3)]),
                             ("15 m", [(0, 0), (1, 1), (2, 3)]), ("12 m", [(2, 3)]),
                             ("10 m", [(0, 0), (2, 3)])):
        lower, upper = band(name)
        matrix.append({"LowerFrequency": lower, "UpperFrequency": upper, "Buttons": [
            {"Row": 0, "Column": c, "Type": "Antenna", "ID": i} for c, i in column_ids]})
    matrix.append({"Buttons": [{"Row": 1, "Column": 0, "Type": "Function", "ID": 0},
                               {"Row": 1, "Column": 1, "Type": "Function", "ID": 1}]})
    doc.append(("Layout",), {"Rows": 2, "Columns": 3, "Matrix": matrix})
    relative = [{"LowerFrequency": band(n)[0], "UpperFrequency": band(n)[1], "IDs": ids}
                for n, ids in (("160 m", [3]), ("80 m", [2, 3]), ("40 m", [1, 3]),
                               ("20 m", [0, 3]), ("15 m", [0, 1, 3]), ("10 m", [0, 3]))]
    doc.append(("RelativeAntennas",), {"Antennas": relative})
    doc.set(("Antennas", 0, "Rotator"), 1)
    doc.set(("Antennas", 0, "Offset"), 0)
    doc.append(("Rotators",), {"ID": 1, "ShortName": "Tribander", "LongName": "Tribander rotator",
                               "CCWLimit": 180, "Rotation": 360, "HasStop": True, "Control": "Test"})
    for index, other in ((0, 2), (1, 1)):
        doc.set(("Radios", index, "Interrupt"), False)
        doc.set(("Radios", index, "Always"), [{"Station": 1, "Radio": other}])
        doc.set(("Radios", index, "OutOfBand"), True)
    doc.set(("Switches", 0, "IndicateTR"), True)
    doc.set(("TCPPort",), 12059)
    doc.set(("UDPPort",), 12060)
    doc.set(("UseN1MMLogger",), True)
    doc.append(("N1MMLogger",), {"Address": "127.0.0.1", "Station": 1})
    doc.set(("ProtectSameBand",), True)
    doc.set(("StartMOASRotator",), False)


@pytest.mark.realtime  # ends with moas-server --check as a process
def test_the_small_station_built_from_nothing_is_the_example(tmp_path: Path) -> None:
    doc = Document.new(tmp_path / "small.moas")
    apply_guide(doc, small_station_guide())
    assert parse_config(doc.text).ok, "the guide's station alone is accepted"
    the_rest(doc)
    example = Document.open(SMALL)
    built = doc.get(())
    wanted = example.get(())
    assert isinstance(built, dict) and isinstance(wanted, dict)
    assert sorted(built) == sorted(wanted)
    for key in wanted:
        assert built[key] == wanted[key], key
    doc.save()
    done = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--check", str(doc.path)],
                          capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stdout
    assert load_config(doc.path or "").unwrap().antennas == load_config(SMALL).unwrap().antennas


def test_the_guide_alone_makes_a_file_check_accepts_and_one_undo_step() -> None:
    doc = Document.new()
    guide = Guide(radios=[GuideRadio(1, 1, 1), GuideRadio(2, 1, 2), GuideRadio(3, 1, 3)],
                  antennas=[GuideAntenna(i, f"Ant {i}", i + 1, (band("20 m"), band("40 m")))
                            for i in range(6)])
    apply_guide(doc, guide)
    result = parse_config(doc.text, "new.moas")
    assert result.ok, result.problems
    assert len(doc.undo_steps) == 1
    assert doc.get(("Antennas", 5, "Control", 1, "Stations", 2, "Relays")) == [17]
    doc.undo()
    assert doc.text == "{\n}\n"


@pytest.mark.parametrize(("change", "words"), [
    ({"radios": []}, "at least one radio"),
    ({"radios": [GuideRadio(1, 1, 1), GuideRadio(1, 1, 2)]}, "given once"),
    ({"radios": [GuideRadio(1, 1, 1), GuideRadio(1, 2, 1)]}, "two radios are on one switch port"),
    ({"radios": [GuideRadio(1, 1, 1, switch=2)]}, "switch 2, which is not given"),
    ({"antennas": [GuideAntenna(0, "A", 9, (band("20 m"),))]}, "beyond the switch's 6"),
    ({"antennas": [GuideAntenna(0, "A", 1, ())]}, "antenna 0 has no band"),
])
def test_the_guide_says_what_is_missing(change: dict[str, object], words: str) -> None:
    values: dict[str, object] = {"radios": [GuideRadio(1, 1, 1)],
                                 "antennas": [GuideAntenna(0, "A", 1, (band("20 m"),))]}
    values.update(change)
    guide = Guide(**values)  # type: ignore[arg-type]
    doc = Document.new()
    with pytest.raises(ValueError, match=words):
        apply_guide(doc, guide)
    assert doc.text == "{\n}\n"
