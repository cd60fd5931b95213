"""Helpers shared by the tests of configuration files: a small valid station (``BASE``),
the text of it with some keys changed, and the problems a text gives with their places."""

from __future__ import annotations

import json

from moas_gui.config import parse_config

BASE: dict = {
    "Antennas": [
        {"ID": 1, "ShortName": "Beam", "LongName": "20 m beam", "Conflicts": [1], "Fast": [1],
         "Rotator": 0,
         "Control": [{"LowerFrequency": 14000, "UpperFrequency": 14350,
                      "Stations": [{"Station": 1, "Radio": 1, "Relays": [0]},
                                   {"Station": 1, "Radio": 2, "Relays": [6]}]}]},
        {"ID": 2, "ShortName": "Vert", "Conflicts": [2],
         "Control": [{"Stations": [{"Station": 1, "Radio": 1, "Relays": [1]},
                                   {"Station": 1, "Radio": 2, "Relays": [7]}]}]},
    ],
    "Systems": [],
    "Functions": [{"ID": 0, "Name": "AntennaSwap", "IntParams": [1, 1, 1, 2]}],
    "Layout": [{"Rows": 2, "Columns": 2, "Matrix": [{"Buttons": [
        {"Row": 0, "Column": 0, "Type": "Antenna", "ID": 1},
        {"Row": 1, "Column": 1, "Type": "Function", "ID": 0}]}]}],
    "RelativeAntennas": [{"Antennas": [{"IDs": [1, 2]}]}],
    "Rotators": [{"ID": 0, "ShortName": "Tower", "Control": "Test", "HasStop": True}],
    "Radios": [
        {"Station": 1, "Radio": 1, "Always": [{"Station": 1, "Radio": 2}], "Switches": [{"Port": 1}]},
        {"Station": 1, "Radio": 2, "Always": [{"Station": 1, "Radio": 1}], "Switches": [{"Port": 2}]},
    ],
    "Switches": [{"ID": 1, "Port": "emulator"}],
}


def text_of(**changes: object) -> str:
    data = json.loads(json.dumps(BASE))
    for key, value in changes.items():
        data[key] = value
    return json.dumps(data, indent=2)


def errors(text: str) -> list[tuple[int, int, str]]:
    result = parse_config(text, "t.moas")
    assert result.config is None, "a file with errors must never be loaded"
    return [(p.line, p.column, p.message) for p in result.errors]


def line_of(text: str, needle: str, nth: int = 1) -> int:
    count = 0
    for number, line in enumerate(text.splitlines(), 1):
        if needle in line:
            count += 1
            if count == nth:
                return number
    raise AssertionError(f"{needle!r} not in text")
