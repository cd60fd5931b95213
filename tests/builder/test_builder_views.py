"""The station at a glance (band x antenna grid, relay map, layout preview) read from the
examples and edited through the document; and one builder window per file."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.builder import Document
from moas_gui.builder.claims import FileClaimed, claim, claims_dir, holder, release
from moas_gui.builder.views import (
    band_grid,
    layout_bands,
    layout_preview,
    move_button,
    relay_map,
    set_band_radio,
    switches_of,
)
from moas_gui.config import parse_config
from moas_gui.config.model import RadioRef

ROOT = Path(__file__).resolve().parents[2]
SMALL = ROOT / "examples" / "small-station.moas"
EXAMPLES = sorted((ROOT / "examples").glob("*.moas"))


def test_the_grid_shows_who_can_use_each_antenna_on_each_band() -> None:
    grid = band_grid(Document.open(SMALL))
    assert [b[0] for b in grid.bands] == ["160 m", "80 m", "40 m", "30 m", "20 m", "17 m",
                                          "15 m", "12 m", "10 m"]
    names = [name for _, _, name in grid.antennas]
    assert names == ["Tribander", "40 Dipole", "80 Dipole", "Vertical"]
    assert grid.cells[(0, "20 m")].text() == "1/1 1/2"
    assert grid.cells[(0, "40 m")].text() == ""
    assert grid.cells[(1, "15 m")].text() == "1/1 1/2"


def test_receive_only_antennas_show_as_such() -> None:
    grid = band_grid(Document.open(ROOT / "examples" / "two-op-shared-tx.moas"))
    rx_only = [(i, name) for i, _, name in grid.antennas if name.startswith("RX")]
    assert rx_only
    index = rx_only[0][0]
    texts = [grid.cells[(index, b[0])].text() for b in grid.bands]
    assert any(texts) and all(t == "" or t.endswith("RX") for t in texts)


def test_the_grid_edits_the_control_entries() -> None:
    doc = Document.open(SMALL)
    assert set_band_radio(doc, 0, ("40 m", 7000, 7300), RadioRef(1, 1), True) == ""
    assert band_grid(doc).cells[(0, "40 m")].text() == "1/1"
    assert doc.get(("Antennas", 0, "Control", 3)) == {
        "LowerFrequency": 7000, "UpperFrequency": 7300,
        "Stations": [{"Station": 1, "Radio": 1, "Relays": []}]}
    assert set_band_radio(doc, 3, ("20 m", 14000, 14350), RadioRef(1, 2), False) == ""
    assert band_grid(doc).cells[(3, "20 m")].text() == "1/1"
    doc.undo()
    doc.undo()
    assert doc.text == SMALL.read_text(encoding="utf-8")


def test_a_radio_given_by_a_wider_entry_is_explained() -> None:
    doc = Document("""{"Antennas": [{"ID": 1, "Control": [{"Stations": [{"Station": 1, "Radio": 1, "Relays": [1]}]}]}],
 "Radios": [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}]}], "Switches": [{"ID": 1, "Port": "emulator"}]}""")
    said = set_band_radio(doc, 0, ("20 m", 14000, 14350), RadioRef(1, 1), False)
    assert "covers more than 20 m" in said
    assert band_grid(doc).cells[(0, "20 m")].text() == "1/1"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_every_example_s_relay_map_has_no_wrongly_shared_relay(path: Path) -> None:
    doc = Document.open(path)
    for switch in switches_of(doc):
        found = relay_map(doc, switch)
        assert len(found.relays()) == 64
        assert not [f for f in found.flags.values() if f.startswith("shared")], path.name
        used = [r for r, uses in found.uses.items() if uses]
        assert used and all(found.flags.get(r) != "never used" for r in used)


def test_a_relay_two_radios_use_for_different_antennas_is_flagged() -> None:
    doc = Document.open(SMALL)
    found = relay_map(doc, 1)
    assert found.ports == {1: RadioRef(1, 1), 2: RadioRef(1, 2)}
    assert found.flags[8] == "never used" and 0 not in found.flags
    assert {(u.antenna, u.radio) for u in found.uses[0]} == {(0, RadioRef(1, 1))}
    doc.set(("Antennas", 1, "Control", 0, "Stations", 1, "Relays"), [0, 26])  # radio 2's 40 m dipole on relay 0
    flag = relay_map(doc, 1).flags[0]
    assert flag.startswith("shared: station 1 radio 1 (Tribander") and "station 1 radio 2 (40 Dipole" in flag


def test_the_layout_preview_and_moving_a_button() -> None:
    doc = Document.open(SMALL)
    assert "20 m" in layout_bands(doc, 0)
    rows, columns, buttons = layout_preview(doc, 0, "20 m")
    assert (rows, columns) == (2, 3)
    assert [(b.row, b.column, b.label) for b in buttons] == [
        (0, 0, "Tribander"), (0, 2, "Vertical"), (1, 0, "Swap"), (1, 1, "RX=TX")]
    move_button(doc, 0, "20 m", buttons[0], 0, 2)  # onto the vertical: they change places
    _, _, moved = layout_preview(doc, 0, "20 m")
    assert [(b.row, b.column, b.label) for b in moved][:2] == [(0, 2, "Tribander"), (0, 0, "Vertical")]
    assert len(doc.undo_steps) == 1 and parse_config(doc.text).ok
    doc.undo()
    assert doc.text == SMALL.read_text(encoding="utf-8")


def test_a_file_open_in_one_builder_window_is_refused_to_another(tmp_path: Path) -> None:
    station = tmp_path / "station.moas"
    station.write_text("{}")
    claim(station, "Station builder - station.moas")
    try:
        with pytest.raises(FileClaimed, match='open in the builder window "Station builder - '
                                              'station.moas" \\(this program'):
            claim(station, "another")
        other = tmp_path / "other.moas"
        claim(other, "second")
        release(other)
    finally:
        release(station)
    assert holder(station) is None
    claim(station, "again")
    release(station)


@pytest.mark.realtime
def test_a_claim_of_another_living_process_is_honoured_and_a_dead_one_is_not(tmp_path: Path) -> None:
    station = tmp_path / "station.moas"
    station.write_text("{}")
    code = ("import sys, time; from pathlib import Path; from moas_gui.builder.claims import claim; "
            "claim(Path(sys.argv[1]), 'the other window'); print('ok', flush=True); time.sleep(60)")
    with subprocess.Popen([sys.executable, "-c", code, str(station)], stdout=subprocess.PIPE,
                          text=True, env=os.environ.copy()) as child:
        try:
            assert child.stdout is not None and child.stdout.readline().strip() == "ok"
            with pytest.raises(FileClaimed, match=f'"the other window" \\(process {child.pid}'):
                claim(station, "mine")
        finally:
            child.kill()
            child.wait()
    assert holder(station) is None, "its process ended: the claim is stale"
    claim(station, "mine")
    release(station)
    assert not [json.loads(p.read_text()) for p in claims_dir().glob("*.json")]
