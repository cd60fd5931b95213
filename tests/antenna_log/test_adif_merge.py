"""The merging recipe of docs/antenna-log.md, run as written on a logger's export and
ours: each contact gets the antennas of the nearest record of the same call and band
within a minute, and the others come out as they went in."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import adif_io
import pytest
from antenna_log_support import T0, MemoryJournal, contact

from moas_gui.antenna_log.adif import write_adif
from moas_gui.antenna_log.records import Period

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.realtime  # real processes, end to end


def recipe() -> str:
    text = (ROOT / "docs" / "antenna-log.md").read_text(encoding="utf-8")
    section = text[text.index("### Merging with the logger's export") :]
    found = re.search(r"```python\n(.*?)```", section, re.DOTALL)
    assert found is not None, "the merging section holds a Python script"
    return found.group(1)


def logger_record(call: str, date: str, time: str, band: str, **more: str) -> str:
    fields = {"CALL": call, "QSO_DATE": date, "TIME_ON": time, "BAND": band, "MODE": "CW"}
    fields |= more
    return "".join(f"<{k}:{len(v)}>{v} " for k, v in fields.items()) + "<EOR>\n"


def test_the_documented_merge_adds_the_antennas(tmp_path: Path) -> None:
    journal = MemoryJournal(
        [
            contact(1, T0 + 5, "DL1AA", "14", tx="Yagi 20", rx="Bev NE", heading=45.0),
            contact(2, T0 + 65, "DL1AA", "21", tx="Yagi 15"),  # the same call on 15 m
            contact(3, T0 + 130, "G4BB", "14", tx="Stack 20", path="R1 > Stack 20 BIP"),
            contact(4, T0 + 190, "G4BB", "14", tx="Dipole 20"),  # a dupe a minute later
            contact(5, T0 + 600, "OK1CC", "7", tx="4-Square"),
        ]
    )
    ours = tmp_path / "antennas.adi"
    write_adif(journal, Period(T0, T0 + 3600), ours)
    # the logger stamps a few seconds apart, to the minute in one case, and has a contact
    # logged while the server was off
    logger = tmp_path / "logger.adi"
    logger.write_text(
        "Exported by a logger\n<ADIF_VER:5>3.1.0 <PROGRAMID:6>LOGGER <EOH>\n"
        + logger_record("DL1AA", "20261118", "110012", "20M", RST_SENT="599")
        + logger_record("DL1AA", "20261118", "1101", "15M")
        + logger_record("G4BB", "20261118", "110215", "20M")
        + logger_record("G4BB", "20261118", "110305", "20M")
        + logger_record("OK1CC", "20261118", "111145", "40M")  # 105 s off: not matched
        + logger_record("W1DD", "20261118", "112000", "20M"),
        encoding="utf-8",
    )
    script = tmp_path / "merge_antennas.py"
    script.write_text(recipe(), encoding="utf-8")
    out = tmp_path / "merged.adi"
    done = subprocess.run(
        [sys.executable, str(script), str(logger), str(ours), str(out)],
        capture_output=True,
        text=True,
        check=True,
        timeout=60,
    )
    assert done.stdout.strip() == f"{out}: 4 contacts got their antennas"
    merged, headers = adif_io.read_from_file(str(out))
    assert headers["PROGRAMID"] == "LOGGER"
    antennas = [(q["CALL"], q.get("MY_ANTENNA"), q.get("APP_MOAS_RXANT")) for q in merged]
    assert antennas == [
        ("DL1AA", "Yagi 20", "Bev NE"),
        ("DL1AA", "Yagi 15", "Yagi 15"),
        ("G4BB", "Stack 20", "Stack 20"),
        ("G4BB", "Dipole 20", "Dipole 20"),
        ("OK1CC", None, None),
        ("W1DD", None, None),
    ]
    assert merged[0]["ANT_AZ"] == "45" and merged[0]["RST_SENT"] == "599"
    assert merged[2]["APP_MOAS_SWITCH_PATH"] == "R1 > Stack 20 BIP"
    assert "ANT_AZ" not in merged[1]
