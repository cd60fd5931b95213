"""Long lists in a configuration: one problem per kind, with a count, at the first culprit.

How long the checker takes as lists grow is measured by ``benchmarks/bench_config_fuzz.py``
(its "long lists" figures); these tests hold the messages.
"""

from __future__ import annotations

import json

from config_support import errors, line_of, text_of

from moas_gui.config import parse_config


def station_relays(relays: list[int]) -> str:
    data = json.loads(text_of())
    data["Antennas"][1]["Control"][0]["Stations"][0]["Relays"] = relays
    return json.dumps(data, indent=2)


def test_thousands_of_relays_of_missing_switches_are_one_problem_with_a_count() -> None:
    text = station_relays(list(range(100, 100 + 16_000)))
    found = errors(text)
    kinds = {m.split(";")[0].split(" (")[0] for _, _, m in found}
    assert len(found) == len(kinds) == 2, found
    messages = [m for _, _, m in found]
    assert ("antenna 2's Control sets more than 35 relays at once on 160 switches "
            "(switch 2: 100, switch 3: 100, switch 4: 100, switch 5: 100, switch 6: 100 "
            "and 155 more); a MOAS II command carries at most 35") in messages
    # relays of a switch that is not configured are named as such, whatever their number
    assert ("antenna 2's Control names 16,000 relays (100, 101, 102, 103, 104 and 15,995 "
            "more) of switches that are not in \"Switches\" (2, 3, 4, 5, 6 and 155 more)"
            ) in messages
    first = line_of(text, "100,")
    assert [line for line, _, m in found if "names" in m] == [first]


def test_many_relays_beyond_63_of_a_configured_switch_are_one_problem() -> None:
    text = station_relays([64, 65, 99])
    messages = [m for _, _, m in errors(text)]
    assert ("antenna 2's Control names 3 relays that no switch has (64, 65 and 99); switch N has "
            "relays (N-1)*100 to (N-1)*100+63 only") in messages


def test_one_wrong_relay_keeps_its_own_sentence() -> None:
    found = errors(station_relays([1, 64, 7]))
    assert [m for _, _, m in found] == [
        "antenna 2's Control names relay 64; switch 1 has relays 0-63 only"]


def test_thousands_of_missing_antennas_in_use_are_one_problem_with_a_count() -> None:
    data = json.loads(text_of())
    data["Antennas"][0]["InUse"] = [2] + list(range(1000, 9000))
    text = json.dumps(data, indent=2)
    assert errors(text) == [(line_of(text, "1000,"), 9,
                             ('antenna 1 names 8,000 antennas that are not in "Antennas" '
                             "(1000, 1001, 1002, 1003, 1004 and 7,995 more)"))]


def test_thousands_of_wrong_items_in_a_list_are_a_few_problems_and_a_count() -> None:
    data = json.loads(text_of())
    data["Antennas"][0]["Conflicts"] = ["x"] * 10_000
    text = json.dumps(data, indent=2)
    found = errors(text)
    assert len(found) == 6
    first = line_of(text, '"x"')
    assert [line for line, _, _ in found] == list(range(first, first + 6))
    assert found[0][2].startswith('item 1 of "Conflicts" of this antenna must be')
    assert found[5][2] == ('9,995 more items of "Conflicts" of this antenna are wrong too '
                           "(the first of them is here)")


def test_a_system_listing_thousands_of_missing_systems_is_one_problem() -> None:
    data = json.loads(text_of())
    data["Systems"] = [{"ID": 0, "ShortName": "S", "ExclusiveAntennas": [1, 2],
                        "ExclusiveSystems": list(range(1, 5001))}]
    messages = [m for _, _, m in errors(json.dumps(data, indent=2))]
    assert messages == [('system 0 names 5,000 systems that are not in "Systems" '
                        "(1, 2, 3, 4, 5 and 4,995 more)")]


def test_a_short_file_keeps_every_problem_separate() -> None:
    result = parse_config(station_relays([64, 105]), "t.moas")
    assert len(result.errors) == 2


def test_a_long_circle_of_systems_is_one_problem_that_shows_its_start_and_length() -> None:
    data = json.loads(text_of())
    count = 3000
    data["Systems"] = [{"ID": i, "ShortName": "S", "ExclusiveSystems": [(i + 1) % count]}
                       for i in range(count)]
    messages = [m for _, _, m in errors(json.dumps(data, indent=2))]
    assert messages == [("systems contain each other in a circle: system 0 -> system 1 -> "
                        "system 2 -> system 3 -> system 4 -> system 5 -> system 6 -> "
                        "system 7 -> ... -> system 0 (3,000 systems)")]


def test_circles_start_at_their_first_system_in_the_file_and_are_told_once() -> None:
    from moas_gui.config.circles import circles

    children = {5: (3,), 3: (9, 5), 9: (3,), 1: (1,), 2: (4,), 4: (2,), 7: (8,), 8: ()}
    assert circles([5, 3, 9, 1, 2, 4, 7, 8], children) == [[3, 9, 3], [2, 4, 2]]
    assert circles([2, 4], {2: (4,), 4: (2,)}, limit=1) == [[2, 4, 2]]
    chain_of = {i: (i + 1,) for i in range(50_000)}
    assert circles(list(chain_of), chain_of) == []


def test_an_antenna_without_the_electrical_rotator_of_its_system_is_told_once() -> None:
    data = json.loads(text_of())
    data["Rotators"] = [{"ID": 0, "ShortName": "Stack", "Control": "Electrical"}]
    data["Antennas"] = [{"ID": i, "ShortName": f"A{i}", "Conflicts": [i], "Rotator": 0}
                        for i in range(1, 4)] + [{"ID": 4, "ShortName": "A4", "Conflicts": [4]}]
    data["Systems"] = [{"ID": 0, "ShortName": "S", "ExclusiveAntennas": [1, 2, 3, 4]}]
    data["Functions"] = []
    data["Layout"] = []
    data["RelativeAntennas"] = []
    assert [m for _, _, m in errors(json.dumps(data, indent=2))] == [
        ('antenna 4 is in system 0 with antennas of electrical rotator 0, so it must also say '
        '"Rotator": 0')]


def test_a_system_naming_itself_many_times_is_told_once() -> None:
    data = json.loads(text_of())
    data["Systems"] = [{"ID": 0, "ExclusiveAntennas": [1, 2], "ExclusiveSystems": [0] * 500}]
    assert [m for _, _, m in errors(json.dumps(data, indent=2))] == ["system 0 contains itself"]
