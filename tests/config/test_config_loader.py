"""Loading a configuration: types, ranges, references, and every problem with its place."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from config_support import errors, line_of, text_of

from moas_gui.config import (
    ButtonType,
    ConfigError,
    RotatorControl,
    Severity,
    load_config,
    parse_config,
)


def test_the_base_configuration_loads_with_defaults_from_the_manual() -> None:
    result = parse_config(text_of(), "t.moas")
    assert result.problems == ()
    config = result.unwrap()
    assert config.tcp_port == 12059 and config.udp_port == 12060
    assert config.use_n1mm_logger is False and config.start_moas_rotator is True
    assert config.protect_same_band is False
    beam = config.antenna(1)
    assert beam is not None and beam.enabled and not beam.tx_only and beam.fast == (1,)
    assert beam.control[0].range.contains(14200) and not beam.control[0].range.contains(7000)
    assert beam.control[0].stations[1].relays == frozenset({6})
    assert config.antenna(2).control[0].range.unbounded  # type: ignore[union-attr]
    assert config.switch(1).inhibit_time == 20 and config.switch(1).echo is None  # type: ignore[union-attr]
    assert config.radio(1, 2).interrupt is False  # type: ignore[union-attr]
    assert config.rotator(0).control is RotatorControl.TEST and config.rotator(0).has_stop  # type: ignore[union-attr]
    assert config.layouts[0].matrix[0].buttons[1].type is ButtonType.FUNCTION


def test_fast_and_has_stop_from_the_manuals_examples_are_accepted() -> None:
    result = parse_config(text_of(), "t.moas")
    assert not result.warnings


def test_unknown_names_are_warnings_with_their_line_and_a_suggestion() -> None:
    data = json.loads(text_of())
    data["Antennas"][0]["Control"][0]["Stations"][0]["Relay"] = [3]
    text = json.dumps(data, indent=2)
    result = parse_config(text, "t.moas")
    assert result.config is not None
    (warning,) = result.warnings
    assert warning.line == line_of(text, '"Relay":')
    assert 'unknown name "Relay"' in warning.message and 'did you mean "Relays"' in warning.message


def test_a_single_value_where_a_list_is_needed_is_explained() -> None:
    data = json.loads(text_of())
    data["Antennas"][0]["Conflicts"] = 1
    text = json.dumps(data, indent=2)
    ((line, _column, message),) = errors(text)
    assert line == line_of(text, '"Conflicts"')
    assert message == '"Conflicts" of this antenna must be a list, even of one value: write [1]'


def test_wrong_types_are_reported_at_the_value() -> None:
    text = text_of(TCPPort="12059", UseN1MMLogger="true")
    found = errors(text)
    assert (line_of(text, '"TCPPort"'), 14) == found[0][:2]
    assert "without quotes" in found[0][2]
    assert "true or false" in found[1][2] and "without quotes" in found[1][2]


def test_numbers_beyond_32_bits_are_refused() -> None:
    data = json.loads(text_of())
    data["Antennas"][1]["ID"] = 2147483648
    ((_, _, message),) = [e for e in errors(json.dumps(data)) if "2147483648" in e[2]]
    assert "2,147,483,647" in message


def test_switch_ids_ports_and_relays_out_of_range() -> None:
    data = json.loads(text_of())
    data["Switches"].append({"ID": 100, "Port": "COM3"})
    data["Radios"][0]["Switches"] = [{"Port": 7}]
    data["Antennas"][1]["Control"][0]["Stations"][0]["Relays"] = [64, 105]
    text = json.dumps(data, indent=2)
    found = errors(text)
    texts = [m for _, _, m in found]
    assert any("is 100; it must be from 1 to 99" in m for m in texts)
    assert any("is 7; it must be from 1 to 6" in m for m in texts)
    assert any("relay 64; switch 1 has relays 0-63 only" in m for m in texts)
    assert any("relay 105, which belongs to switch 2" in m for m in texts)
    data["Antennas"][1]["Control"][0]["Stations"][0]["Relays"] = [999]
    (message,) = [m for _, _, m in errors(json.dumps(data)) if "relay 999" in m]
    assert "switch 10" in message and "no such switch" in message, message
    assert "has relays 900-963 only" not in message, "switch 10 is not configured at all"
    assert "relays: 0-63 on switch 1" in message
    relay_line = next(line for line, _, m in found if "relay 64" in m)
    assert relay_line == line_of(text, "64,")


def test_duplicate_ids_name_the_line_of_the_first() -> None:
    data = json.loads(text_of())
    data["Antennas"].append({"ID": 2, "ShortName": "again"})
    text = json.dumps(data, indent=2)
    ((line, _, message),) = errors(text)
    first = line_of(text, '"ID": 2')
    assert line == line_of(text, '"ID": 2', 2)
    assert message == f"antenna 2 is defined twice (also on line {first - 1}); each needs its own number" \
        or message == f"antenna 2 is defined twice (also on line {first}); each needs its own number"


def test_references_to_missing_things_are_errors() -> None:
    data = json.loads(text_of())
    data["Antennas"][0]["Conflicts"] = [1, 9]
    data["Antennas"][0]["Rotator"] = 5
    data["Functions"][0]["IntParams"] = [1, 1, 3, 1]
    data["Layout"][0]["Matrix"][0]["Buttons"][1]["ID"] = 4
    data["RelativeAntennas"][0]["Antennas"][0]["IDs"] = [1, 8]
    data["Radios"][0]["Always"] = [{"Station": 2, "Radio": 1}]
    data["Antennas"][1]["Control"][0]["Stations"][0]["Station"] = 4
    found = " | ".join(m for _, _, m in errors(json.dumps(data, indent=2)))
    assert 'names antenna 9, which is not in "Antennas"' in found
    assert 'uses rotator 5, which is not in "Rotators"' in found
    assert "names station 3 radio 1, which is not in" in found
    assert 'shows function 4, which is not in "Functions"' in found
    assert 'names antenna 8' in found
    assert "names station 2 radio 1" in found
    assert "names station 4 radio 1" in found


def test_an_antenna_in_two_systems_and_a_system_containing_itself() -> None:
    text = text_of(Systems=[{"ID": 1, "ExclusiveAntennas": [1, 2]},
                            {"ID": 2, "AdditiveAntennas": [2], "ExclusiveSystems": [2]}])
    found = errors(text)
    messages = [m for _, _, m in found]
    assert "antenna 2 is in system 2 and in system 1; an antenna can be part of only one system" in messages
    assert "system 2 contains itself" in messages


def test_systems_that_contain_each_other_in_a_circle() -> None:
    text = text_of(Systems=[{"ID": 1, "AdditiveSystems": [2]}, {"ID": 2, "AdditiveSystems": [3]},
                            {"ID": 3, "ExclusiveSystems": [1]}])
    messages = [m for _, _, m in errors(text)]
    assert any(m.startswith("systems contain each other in a circle: system 1 -> system 2 -> "
                            "system 3 -> system 1") for m in messages)


def test_a_button_outside_the_layout_is_an_error() -> None:
    data = json.loads(text_of())
    data["Layout"][0]["Matrix"][0]["Buttons"][0]["Column"] = 3
    ((_, _, message),) = errors(json.dumps(data, indent=2))
    assert "outside the layout's 2 rows and 2 columns" in message


def test_the_manuals_duplicate_buttons_key_is_an_error_with_its_line() -> None:
    text = text_of().replace('"Buttons": [', '"Buttons": [], "Buttons": [', 1)
    found = errors(text)
    assert found[0][2].startswith('the name "Buttons" appears twice')


def test_function_parameters_are_checked_per_function() -> None:
    text = text_of(Functions=[
        {"ID": 0, "Name": "AntennaSwap", "IntParams": [1, 1]},
        {"ID": 1, "Name": "Relay", "IntParams": [30], "StringParams": ["X"]},
        {"ID": 2, "Name": "Share", "IntParams": [7]},
        {"ID": 3, "Name": "Swap"},
    ])
    messages = [m for _, _, m in errors(text)]
    assert any("needs four numbers" in m for m in messages)
    assert any('"X" is not one of "T", "R", "S"' in m for m in messages)
    assert any("names system 7" in m for m in messages)
    assert any('"Name" of this function is "Swap"; it must be one of' in m for m in messages)


def test_serial_rotators_need_a_port_and_a_known_model() -> None:
    text = text_of(Rotators=[{"ID": 0, "Control": "Serial", "Model": "Ham IV"}])
    messages = [m for _, _, m in errors(text)]
    assert any('needs "CommPort"' in m for m in messages)
    assert any('model "Ham IV"' in m for m in messages)


def test_two_radios_on_one_switch_port() -> None:
    data = json.loads(text_of())
    data["Radios"][1]["Switches"] = [{"Port": 1}]
    ((_, _, message),) = errors(json.dumps(data))
    assert message == "station 1 radio 2 and station 1 radio 1 are both on port 1 of switch 1"


def test_radios_must_name_their_switch_when_there_are_several() -> None:
    data = json.loads(text_of())
    data["Switches"].append({"ID": 2, "Port": "COM4"})
    messages = [m for _, _, m in errors(json.dumps(data))]
    assert any('must say which "Switch"' in m for m in messages)


def test_all_problems_are_reported_at_once_in_file_order() -> None:
    text = '{\n "TCPPort": true,\n "Antennas": [{"ID": -1}],\n "Switches": [{"ID": 0, "Port": 3}]\n}'
    result = parse_config(text, "t.moas")
    lines = [p.line for p in result.errors]
    assert lines == sorted(lines) and len(lines) == 4


def test_syntax_and_meaning_errors_come_together() -> None:
    text = '{\n "Switches": [{"ID": 1, "Port": "COM3",}],\n "Radios": [{"Station": 1, "Radio": 1, "Switches": [{"Port": 9}]}]\n}'
    found = errors(text)
    assert (2, 39) == found[0][:2] and "extra comma" in found[0][2]
    assert found[1][0] == 3 and "from 1 to 6" in found[1][2]


def test_unwrap_raises_a_config_error_carrying_every_problem() -> None:
    result = parse_config('{"TCPPort": 0, "UDPPort": 0}', "t.moas")
    with pytest.raises(ConfigError) as raised:
        result.unwrap()
    assert len([p for p in raised.value.problems if p.severity is Severity.ERROR]) == 2
    assert "t.moas:1:13" in str(raised.value) and "1 more" in str(raised.value)


@pytest.mark.parametrize(("content", "expected"), [
    (None, "there is no such file"),
    (b"", "the file is empty"),
    (b"\xff\xfe{}", "not UTF-8"),
    (b"[1, 2]", "a configuration is a group that starts with '{', not a list"),
    (b"<xml/>", "expected a value but found '<'"),
])
def test_files_that_are_not_configurations_get_one_sentence(
        tmp_path: Path, content: bytes | None, expected: str) -> None:
    path = tmp_path / "station.moas"
    if content is not None:
        path.write_bytes(content)
    result = load_config(path)
    assert result.config is None
    assert len(result.errors) == 1 and expected in result.errors[0].message
    assert str(path) in str(result.errors[0])


def test_a_huge_file_is_refused_without_reading_it(tmp_path: Path) -> None:
    path = tmp_path / "huge.moas"
    with path.open("wb") as f:
        f.truncate(11 * 1024 * 1024)
    (error,) = load_config(path).errors
    assert "refused above 10 MB" in error.message


def test_a_folder_is_not_a_configuration(tmp_path: Path) -> None:
    (error,) = load_config(tmp_path).errors
    assert "folder" in error.message


def test_warnings_alone_leave_the_configuration_usable() -> None:
    result = parse_config('{"Colour": "red"}', "t.moas")
    assert result.config is not None
    assert {p.severity for p in result.problems} == {Severity.WARNING}


def test_more_relays_than_one_switch_command_carries_is_an_error() -> None:
    data = json.loads(text_of())
    data["Antennas"][1]["Control"][0]["Stations"][0]["Relays"] = list(range(36))
    text = json.dumps(data, indent=2)
    messages = [m for _, _, m in errors(text)]
    assert "antenna 2's Control sets 36 relays on switch 1 at once; a MOAS II command " \
           "carries at most 35" in messages
    data["Antennas"][1]["Control"][0]["Stations"][0]["Relays"] = list(range(35))
    assert parse_config(json.dumps(data), "t.moas").ok


def test_numbers_too_large_to_hold_are_refused_with_their_place() -> None:
    text = '{\n  "TCPPort": ' + "9" * 5000 + ',\n  "UDPPort": -1e999,\n  "Templates": []\n}'
    assert errors(text) == [
        (2, 14, '"TCPPort" of the configuration is far too large; it must be from 1 to 65,535'),
        (3, 14, '"UDPPort" of the configuration is far too small; it must be from 1 to 65,535')]


def test_leading_zeros_before_a_huge_exponent_are_explained() -> None:
    assert errors('{"TCPPort": 01e999}') == [
        (1, 13, "numbers cannot have leading zeros: write 1e999"),
        (1, 13, '"TCPPort" of the configuration is far too large; it must be from 1 to 65,535')]


def test_a_file_that_ends_after_a_name_or_its_colon_is_explained() -> None:
    assert errors('{"Antennas"') == [(1, 12, 'the file ends after the name "Antennas"')]
    assert errors('{"TCPPort":') == [(1, 12, "the file ends where a value was expected")]


def test_client_allow_entries_open_to_the_internet_are_warned_about_at_their_line() -> None:
    text = text_of(ClientAllow=["127.0.0.1", "192.168.1.0/24", "127.0.0.1/0", "10.0.0.0/8",
                                "203.0.113.7", "8.8.0.0/16", "fd00::/8", "::/0"])
    result = parse_config(text, "t.moas")
    assert result.ok
    warned = [(p.line, p.message) for p in result.warnings]
    assert warned == [
        (line_of(text, '"127.0.0.1/0"'), ('"ClientAllow" has "127.0.0.1/0", which lets in every '
         'address of the internet (0.0.0.0/0) (for one computer write "127.0.0.1"); anyone who '
         "reaches the port can switch antennas: allow single addresses or a private network "
         "such as 192.168.1.0/24")),
        (line_of(text, '"8.8.0.0/16"'), ('"ClientAllow" has "8.8.0.0/16", which lets in 65,536 '
         "addresses outside the private networks (8.8.0.0/16); anyone who reaches the port can "
         "switch antennas: allow single addresses or a private network such as 192.168.1.0/24")),
        (line_of(text, '"::/0"'), ('"ClientAllow" has "::/0", which lets in every address of the '
         "internet (::/0); anyone who reaches the port can switch antennas: allow single "
         "addresses or a private network such as 192.168.1.0/24"))]
    assert all(p.column == 5 for p in result.warnings)


def test_a_client_allow_entry_that_is_no_address_stays_an_error() -> None:
    text = text_of(ClientAllow=["192.168.1.300"])
    assert errors(text) == [(line_of(text, "192.168.1.300"), 5, ('"ClientAllow" has '
                             '"192.168.1.300", which is not an address or network such as '
                             "192.168.1.0/24"))]


def test_warnings_about_the_whole_station_point_at_a_place_in_the_file() -> None:
    result = parse_config('{\n  "Switches": [],\n  "UseN1MMLogger": true\n}', "t.moas")
    assert [(p.line, p.column, p.message.split(":")[0]) for p in result.warnings] == [
        (1, 1, 'there are no "Radios"'),
        (2, 3, 'there are no "Switches"'),
        (3, 3, ('UseN1MMLogger is true but "N1MMLogger" lists no computers; every packet will '
               "be ignored"))]
