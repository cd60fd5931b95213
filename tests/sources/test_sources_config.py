"""The configuration keys of the sources: read into the model, and every mistake said
at its place."""

from __future__ import annotations

import json
from types import SimpleNamespace

import pytest
from config_support import BASE

from moas_gui.cli import server
from moas_gui.config import parse_config
from moas_gui.config.model import N1MMStation, WinTestStation
from moas_gui.config.rigs import RigDaemon
from moas_gui.config.summary import summarize
from moas_gui.sources.spec import SourceSpec, config_specs, server_spec


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


# -- the rig sources the server runs: Rigctld, Flrig, OTRSP --------------------------------

RIGS = {
    "Rigctld": [{"Station": 1, "Radio": 2, "Address": "shack-pc:4534", "Rate": 5, "Retry": 2},
                {"Station": 1, "Enabled": False}],
    "Flrig": [{"Station": 1, "Address": "12346"}],
    "OTRSP": [{"Station": 1, "Port": "/dev/ttyUSB1", "Radio1": 2, "Radio2": 1,
               "AUX1": [{"Value": 3, "Antenna": 1}], "AUX2": [{"Value": 3, "Antenna": 2}]}],
}


def test_the_rig_source_keys_are_read_and_summarized() -> None:
    config = parse_config(text_of(**RIGS), "t.moas").unwrap()
    assert config.rigctld == (RigDaemon(1, 2, "shack-pc:4534", 5, 2),
                              RigDaemon(1, enabled=False))
    assert config.flrig == (RigDaemon(1, 1, "12346"),)
    [otrsp] = config.otrsp
    assert (otrsp.port, otrsp.radio1, otrsp.radio2) == ("/dev/ttyUSB1", 2, 1)
    assert otrsp.antennas() == {(1, 3): 1, (2, 3): 2}
    summary = summarize(config)
    assert ("rigctld at shack-pc:4534: station 1 radio 2, 5 polls a second, first retry "
            "after 2 s") in summary
    assert "rigctld at 127.0.0.1:4532: station 1 radio 1, 10 polls a second (Enabled: false" \
        in summary
    assert "flrig at 127.0.0.1:12346: station 1 radio 1, 10 polls a second" in summary
    assert ("OTRSP on /dev/ttyUSB1: station 1, radio 1 = radio 2, radio 2 = radio 1; "
            "AUX1 3 = antenna 1 (Beam), AUX2 3 = antenna 2 (Vert)") in summary


def test_the_entries_and_the_command_line_say_the_same_thing() -> None:
    config = parse_config(text_of(**RIGS), "t.moas").unwrap()
    assert config_specs(config) == [  # the disabled entry is not run
        server_spec("rigctld:shack-pc:4534,station=1,radio=2,rate=5,retry=2"),
        server_spec("flrig:12346,station=1,radio=1,rate=10,retry=0.5"),
        server_spec("otrsp:/dev/ttyUSB1,station=1,radio1=2,radio2=1,retry=0.5,ant1.3=1,"
                    "ant2.3=2"),
    ]


def _problems(**changes: object) -> list[tuple[int, str]]:
    text = text_of(**changes)
    result = parse_config(text, "t.moas")
    assert result.config is None
    return [(p.line, p.message) for p in result.errors]


def _line(text: str, needle: str, after: int = 0) -> int:
    lines = text.splitlines()
    return next(n for n, line in enumerate(lines, 1) if n > after and needle in line)


def test_every_rig_source_mistake_is_said_at_its_line() -> None:
    changes: dict[str, object] = {
        "Rigctld": [{"Station": 1, "Radio": 9},
                    {"Station": 1, "Address": "pc:65536"},
                    {"Station": 1, "Rate": 1000},
                    {"Radio": 1}],
        "Flrig": [{"Station": 1, "Address": "127.0.0.1:12345"},
                  {"Station": 1, "Radio": 2, "Retry": 0}],
        "OTRSP": [{"Station": 1, "Port": "emulator"},
                  {"Station": 1, "Port": "COM7", "Radio2": 4,
                   "AUX1": [{"Value": 300, "Antenna": 1}, {"Value": 4, "Antenna": 77},
                            {"Value": 5, "Antenna": 1}, {"Value": 5, "Antenna": 2}]},
                  {"Station": 1, "Port": "com7", "Radio1": 2},
                  {"Station": 5, "Port": ""}],
    }
    text = text_of(**changes)
    found = _problems(**changes)
    rig = _line(text, '"Rigctld"')
    flrig = _line(text, '"Flrig"')
    otrsp = _line(text, '"OTRSP"')
    expected = [
        (_line(text, '"Radio": 9', rig), ("this Rigctld entry names station 1 radio 9, which "
                                         "is not in \"Radios\"")),
        (_line(text, "pc:65536", rig), ("\"Address\" of this Rigctld entry is \"pc:65536\": "
                                       "port '65536' is not between 1 and 65535")),
        (_line(text, '"Rate": 1000', rig), ("\"Rate\" of this Rigctld entry is 1000; it must "
                                           "be from 0.1 to 100")),
        (_line(text, '"Radio": 1', _line(text, '"Rate": 1000', rig)) - 1,  # its "{" line
         "this Rigctld entry needs \"Station\""),
        (_line(text, '"Retry": 0', flrig),
         '"Retry" of this Flrig entry is 0; it must be from 0.01 to 10'),
        (_line(text, '"Port": "emulator"', otrsp), ("this OTRSP entry's port \"emulator\" is "
                                                   "switch 1's port")),
        (_line(text, '"Radio2": 4', otrsp), ("\"Radio2\" of this OTRSP entry names station 1 "
                                            "radio 4, which is not in \"Radios\"")),
        (_line(text, '"Value": 300', otrsp), ("\"Value\" of this AUX1 entry is 300; it must be "
                                             "from 0 to 255")),
        (_line(text, '"Antenna": 77', otrsp), ("AUX1 value 4 of this OTRSP entry selects "
                                              "antenna 77, which is not in \"Antennas\"")),
        (_line(text, '"Value": 5', _line(text, '"Value": 5', otrsp)),
         "AUX1 value 5 of this OTRSP entry is given twice"),
        (_line(text, '"Port": "com7"', otrsp), ("this OTRSP entry's port \"com7\" is read by "
                                               "another OTRSP entry too")),
        (_line(text, '"Radio1": 2', otrsp), ("this OTRSP entry makes both OTRSP radios "
                                            "station 1 radio 2")),
        (_line(text, '"Port": ""', otrsp), "\"Port\" of this OTRSP entry is empty"),
        (_line(text, '"Station": 5', otrsp), ("this OTRSP entry names station 5, which has no "
                                             "radio in \"Radios\"")),
    ]
    for line, words in expected:
        assert any(at == line and words in message for at, message in found), (line, words,
                                                                               found)
    assert len(found) == len(expected), found
    # the second Flrig entry polls the default address, which the first names: a warning
    warnings = [(p.line, p.message) for p in parse_config(text, "t.moas").warnings]
    second = _line(text, '"Radio": 2', flrig) - 2  # its "{" line: it has no "Address"
    assert (second, (f"this Flrig entry polls 127.0.0.1:12345 again (also on line "
                    f"{_line(text, '127.0.0.1:12345', flrig) - 2}); one rig daemon serves one "
                    "radio")) in warnings, warnings


# -- moas-server --source --------------------------------------------------------------

def test_the_server_command_line_takes_rig_sources_naming_their_station() -> None:
    args = server._parser().parse_args(
        ["--source", "rigctld:4534,station=1,radio=2", "--source", "otrsp:COM7,station=2",
         "station.moas"])
    options = server._options(args)
    assert options.sources == (  # type: ignore[attr-defined]
        SourceSpec("rigctld", "4534", {"station": "1", "radio": "2"}),
        SourceSpec("otrsp", "COM7", {"station": "2"}))
    assert server.launch_request(args)["source"] == ("rigctld:4534,station=1,radio=2 "
                                                     "otrsp:COM7,station=2")


@pytest.mark.parametrize(("text", "words"), [
    ("rigctld:4532", "the server needs the station this source feeds: rigctld:4532,station=N"),
    ("n1mm", "n1mm is turned on in the configuration"),
    ("flrig:1,station=x", "'x' is not a whole number"),
])
def test_a_bad_server_source_is_a_usage_error_that_says_why(
        text: str, words: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        server._parser().parse_args(["--source", text, "station.moas"])
    assert exited.value.code == 2
    assert words in capsys.readouterr().err


def test_a_second_launch_with_other_sources_is_refused_by_the_running_server() -> None:
    running = SimpleNamespace(
        options=server._options(server._parser().parse_args(
            ["--source", "rigctld:4534,station=1"])),
        client_address=("127.0.0.1", 12059))
    same = server.launch_request(server._parser().parse_args(
        ["--source", "rigctld:4534,station=1"]))
    other = server.launch_request(server._parser().parse_args(
        ["--source", "flrig:station=1"]))
    assert server.vet_launch(running, same, headless=False) is None
    refusal = server.vet_launch(running, other, headless=False)
    assert refusal is not None and "--source flrig:station=1" in refusal
