"""The configuration keys of the sources: read into the model, and every mistake said
at its place."""

from __future__ import annotations

import json

from moas_gui.config import parse_config
from moas_gui.config.model import N1MMStation, WinTestStation
from moas_gui.config.summary import summarize
from tests.test_config_loader import BASE


def text_of(**changes: object) -> str:
    data = json.loads(json.dumps(BASE))
    data.update(changes)
    return json.dumps(data, indent=2)


def messages(text: str) -> list[str]:
    result = parse_config(text, "t.moas")
    assert result.config is None
    return [p.message for p in result.errors]


def test_the_source_keys_are_read() -> None:
    config = parse_config(text_of(
        UseN1MMLogger=True,
        N1MMLogger=[{"StationName": "RUN-PC", "Station": 1},
                    {"Address": "192.168.1.22", "StationName": "MULT", "Station": 1}],
        UseDXLog=True, DXLogPort=13063,
        UseWinTest=True, WinTestPort=9872,
        WinTest=[{"StationName": "STN1", "Station": 1, "Radio": 2}],
        UseN1MMRotor=True, N1MMRotorPort=12041, N1MMRotorHeadings=["192.168.1.255:13010"],
    ), "t.moas").unwrap()
    assert config.n1mm_logger == (N1MMStation("", 1, "RUN-PC"),
                                  N1MMStation("192.168.1.22", 1, "MULT"))
    assert (config.use_dxlog, config.dxlog_port) == (True, 13063)
    assert (config.use_wintest, config.wintest_port) == (True, 9872)
    assert config.wintest == (WinTestStation("STN1", 1, 2),)
    assert (config.use_n1mm_rotor, config.n1mm_rotor_port, config.n1mm_rotor_headings) == (
        True, 12041, ("192.168.1.255:13010",))
    summary = summarize(config)
    assert "DXLog.net on UDP 13063" in summary
    assert "Win-Test on UDP 9872: STN1 = station 1 radio 2" in summary
    assert "N1MM rotor window: commands on UDP 12041, headings to 192.168.1.255:13010" in summary


def test_the_defaults_are_the_documented_ports() -> None:
    config = parse_config(text_of(), "t.moas").unwrap()
    assert (config.dxlog_port, config.wintest_port, config.n1mm_rotor_port) == (12060, 9871, 12040)
    assert not (config.use_dxlog or config.use_wintest or config.use_n1mm_rotor)


def test_mistakes_are_said() -> None:
    found = messages(text_of(
        N1MMLogger=[{"Station": 1}],
        WinTest=[{"StationName": "STN1", "Station": 1, "Radio": 7}, {"Station": 1}],
        N1MMRotorHeadings=["192.168.1.20:99999", "ok-host"],
        WinTestPort=0,
    ))
    assert any("needs an \"Address\" or a \"StationName\"" in m for m in found), found
    assert any("station 1 radio 7, which is not in \"Radios\"" in m for m in found), found
    assert any("\"192.168.1.20:99999\" is not host:port" in m for m in found), found
    assert any("WinTest entry needs \"StationName\"" in m for m in found), found
    assert any("\"WinTestPort\" of the configuration is 0" in m for m in found), found
    assert len(found) == 5, found


def test_turned_on_with_nothing_to_do_is_a_warning() -> None:
    data = json.loads(text_of(UseWinTest=True, UseDXLog=True, UseN1MMRotor=True, Rotators=[]))
    for antenna in data["Antennas"]:
        antenna.pop("Rotator", None)
    result = parse_config(json.dumps(data, indent=2), "t.moas")
    assert result.config is not None
    warnings = " ".join(p.message for p in result.warnings)
    assert "UseWinTest is true but" in warnings and "UseDXLog is true but" in warnings
    assert "UseN1MMRotor is true but there are no \"Rotators\"" in warnings
