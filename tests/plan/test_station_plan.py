"""The station plan (``moas-server --plan``): each example's plan is a reviewed golden file
(text and JSON, under ``tests/plan/plans/``), the plan is the same every time, and each kind of
finding is found, with its line, in a configuration made to show it.

The command runs as a process of its own once (``python -m moas_gui.cli.server --plan``,
text and JSON); its other options and messages are checked through the same ``main()`` in
this process (:func:`cli`), which gives the same output and exit status without starting
an interpreter for each.

To write the golden files again after a reviewed change of the engine or of the plan:
``.venv/bin/python tests/plan/test_station_plan.py --write``; then read the diff.
"""

from __future__ import annotations

import functools
import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from moas_gui.config import parse_config
from moas_gui.config.model import RadioRef
from moas_gui.plan import FINDING_KINDS, Plan, build_plan, plan_file

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.moas"))
GOLDEN = Path(__file__).resolve().parent / "plans"


def run_server(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args],
                          capture_output=True, text=True, check=False, timeout=120, cwd=ROOT)


@functools.cache
def example_plan(path: Path) -> tuple[Plan | None, str]:
    """``plan_file(path)``, made once per example for the tests that only read it (the
    plan being the same every time is a test of its own, on fresh plans)."""
    return plan_file(path)


@pytest.fixture
def cli(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
        ) -> Callable[..., subprocess.CompletedProcess[str]]:
    """``moas-server ARGS`` through its ``main()`` in this process, from the checkout's
    folder: the exit status (a usage error's too, which argparse raises as SystemExit)
    and what it printed, as :func:`run_server` returns them from a process."""
    from moas_gui.cli import server

    monkeypatch.chdir(ROOT)

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        capsys.readouterr()
        try:
            code = server.main(list(args))
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(["moas-server", *args], code, out, err)

    return run


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_each_example_plan_matches_its_golden_files(example: Path) -> None:
    plan, error = example_plan(example)
    assert plan is not None, error
    assert plan.to_text() == (GOLDEN / f"{example.stem}.txt").read_text(encoding="utf-8")
    assert plan.to_json() == (GOLDEN / f"{example.stem}.json").read_text(encoding="utf-8")


def test_the_plan_is_the_same_every_time() -> None:
    path = ROOT / "examples" / "two-op-shared-tx.moas"
    first, _ = plan_file(path)
    second, _ = plan_file(path)
    assert first is not None and second is not None
    assert first.to_json() == second.to_json() and first.to_text() == second.to_text()


@pytest.mark.realtime  # the command as a process of its own
def test_the_command_prints_the_plan_and_its_json() -> None:
    path = "examples/small-station.moas"
    text = run_server("--plan", path)
    assert text.returncode == 0, text.stderr
    assert text.stdout == (GOLDEN / "small-station.txt").read_text(encoding="utf-8")
    data = run_server("--plan", "--json", path)
    assert data.returncode == 0, data.stderr
    parsed = json.loads(data.stdout)
    assert parsed == json.loads((GOLDEN / "small-station.json").read_text(encoding="utf-8"))
    assert {o["why"]["rule"] for o in parsed["alone"]} == {"f4_lowest"}
    assert {f["kind"] for f in parsed["findings"]} <= set(FINDING_KINDS)


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_rule_codes_and_antennas_that_merely_do_not_cover_stay_out_of_the_text(
        example: Path) -> None:
    plan, error = example_plan(example)
    assert plan is not None, error
    text = plan.to_text()
    codes = {o.rule for o in plan.alone} | set(FINDING_KINDS)
    assert not [c for c in codes if f"[{c}]" in text or f" {c}" in text]
    assert "passed over" not in text or all(
        "does not cover" not in line for line in text.splitlines() if "passed over" in line)
    # ... while the JSON keeps them: every passed-over antenna, with its reason
    dropped = [r for o in plan.alone for _a, r in o.passed_over if r.startswith("does not")]
    assert dropped == [p["reason"] for o in json.loads(plan.to_json())["alone"]
                       for p in o["why"]["passed_over"] if p["reason"].startswith("does not")]


def test_a_station_is_planned_only_on_the_bands_its_antennas_cover() -> None:
    plan, _ = example_plan(ROOT / "examples" / "multi-multi-20.moas")
    assert plan is not None
    assert [b.name for b in plan.bands] == ["20 m"]
    assert {o.khz for o in plan.alone} == {14025, 14250}
    text = plan.to_text()
    assert "1825" not in text and "160 m" not in text and "no free antenna" not in text
    assert all(o.has_antenna for o in plan.alone)


def test_each_band_is_planned_at_its_cw_and_phone_frequencies() -> None:
    plan, _ = example_plan(ROOT / "examples" / "small-station.moas")
    assert plan is not None
    twenty = plan.band("20 m")
    assert twenty.frequencies == ((14025, "CW"), (14250, "phone"))
    assert plan.band("30 m").frequencies == ((10125, "CW"),)  # no phone on 30 m
    assert {(o.radio.radio, o.khz) for o in plan.alone if o.band == "20 m"} == {
        (1, 14025), (2, 14025), (1, 14250), (2, 14250)}
    assert "  20 m at 14025 kHz CW and 14250 kHz phone\n" in plan.to_text()


def test_a_frequency_no_antenna_covers_is_named_not_planned() -> None:
    """An 80 m dipole cut for CW: 3800 kHz phone is left out, and the plan says so."""
    plan, _ = station([ant(0, "Tribander", TWENTY, BOTH),
                       ant(1, "CW dipole", [(3500, 3600)], BOTH)])
    assert plan.band("80 m").frequencies == ((3525, "CW"),)
    assert plan.band("80 m").uncovered == ((3800, "phone"),)
    assert "Not planned (no antenna covers them): 80 m 3800 kHz phone" in plan.to_text()


def test_a_station_covering_no_band_says_so() -> None:
    plan, _ = station([ant(0, "Marine whip", [(8000, 9000)], BOTH)])
    assert plan.bands == () and plan.alone == []
    assert plan.to_text().splitlines()[:3] == [
        "Station plan of crafted.moas",
        "Bands: none (no antenna of the station covers a band the plan knows)", ""]


def test_plan_khz_plans_the_frequencies_the_operator_names(
        cli: Callable[..., subprocess.CompletedProcess[str]]) -> None:
    done = cli("--plan", "--plan-khz", "14010,14200", "--plan-khz", "1830",
               "examples/two-op-shared-tx.moas")
    assert done.returncode == 0, done.stderr
    assert "  160 m at 1830 kHz\n" in done.stdout
    assert "  20 m at 14010 kHz and 14200 kHz\n" in done.stdout
    assert "40 m" not in done.stdout and "14025" not in done.stdout
    data = cli("--plan", "--json", "--plan-khz", "7010", "examples/small-station.moas")
    parsed = json.loads(data.stdout)
    assert [b["frequencies"] for b in parsed["bands"]] == [[{"khz": 7010.0, "mode": ""}]]
    assert {o["khz"] for o in parsed["alone"]} == {7010.0}
    for bad, said in (("14o00", "'14o00' is not a frequency in kHz"),
                      ("12345", "12345 kHz is in no amateur band"), ("-5", "above 0")):
        done = cli("--plan", "--plan-khz", bad, "examples/small-station.moas")
        assert done.returncode == 2 and said in done.stderr and not done.stdout
    assert cli("--plan-khz", "14000", "examples/small-station.moas").returncode == 2


def test_a_pair_shows_only_what_differs_from_each_radio_alone() -> None:
    plan, _ = example_plan(ROOT / "examples" / "small-station.moas")
    assert plan is not None
    text = plan.to_text()
    ((a, b, _meet, scenarios),) = plan.pairs
    pair = text[text.index("Station 1 radio 1 and station 1 radio 2 ("):text.index("Findings")]
    # 80 m + 40 m: each radio gets what it gets alone; in the JSON, not in the text
    quiet = next(s for s in scenarios if (s.first.band, s.second.band) == ("80 m", "40 m"))
    assert plan.alone_at(a, quiet.first.khz).same_antennas(quiet.first)  # type: ignore[union-attr]
    assert plan.alone_at(b, quiet.second.khz).same_antennas(quiet.second)  # type: ignore[union-attr]
    assert "80 m + 40 m" not in pair
    # the inhibit that holds everywhere is said once, not on each of 88 scenarios
    assert pair.count("cannot transmit while") + pair.count("the other cannot") == 1
    assert "  on every band and every two bands: while one transmits, the other cannot" in pair
    # both on 20 m: radio 2 gets the vertical, and the plan says what it had alone
    assert ("  both on 20 m or 10 m:\n    Station 1 radio 2: All-band vertical \u2014 "
            "lowest-numbered antenna covering its frequency (alone: Triband Yagi 20-15-10)"
            in pair)
    assert len(pair.splitlines()) < 40 < len(scenarios)


def test_a_pair_on_separate_antennas_adds_one_line() -> None:
    """Two stations with an inhibit between them and their own antennas on every band:
    no scenario changes anything but the inhibit."""
    radios = [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}],
               "SameBand": [{"Station": 2, "Radio": 1}]},
              {"Station": 2, "Radio": 1, "Switches": [{"Port": 2}]}]
    plan, _ = station([ant(0, "Yagi A", TWENTY + FORTY, {(1, 1): 0}),
                       ant(1, "Yagi B", TWENTY + FORTY, {(2, 1): 8})], radios)
    text = plan.to_text()
    pair = text[text.index("Station 1 radio 1 and station 2 radio 1"):text.index("Findings")]
    assert pair.splitlines()[1:] == [
        ("  on every band they share: Station 1 radio 1 cannot transmit while station 2 radio "
         "1 transmits (it is inhibited)"),
        "  each gets the antennas it gets alone, on every band and every two bands", ""]


def test_a_finding_about_a_radio_left_with_a_receive_antenna_says_transmit() -> None:
    plan, _ = example_plan(ROOT / "examples" / "two-op-shared-tx.moas")
    assert plan is not None
    text = plan.to_text()
    taken = next(f for f in plan.findings if f.kind == "band_taken")
    assert taken.text.startswith("station 1 radio 1 and station 2 radio 1 cannot both transmit "
                                 "when both are on 160 m or 80 m (station 2 radio 1 keeps only "
                                 "a receive antenna)")
    assert "cannot both have an antenna" not in text
    # ... as the line above it says
    assert ("  both on 160 m or 80 m:\n    Station 2 radio 1: no transmit antenna, receives on "
            "Beverage north-east" in text)


def test_a_finding_about_a_radio_left_with_no_antenna_says_so() -> None:
    plan, _ = station([ant(0, "Tribander", TWENTY, {(1, 1): 0}, Conflicts=[0, 1]),
                       ant(1, "Vertical", TWENTY, {(1, 2): 9})])
    (taken,) = [f for f in plan.findings if f.kind == "band_taken"]
    assert "cannot both have an antenna for their frequencies when both are on 20 m" \
        in taken.text
    assert "receive" not in taken.text


def test_check_ends_with_the_count_of_findings_and_points_at_the_plan(
        cli: Callable[..., subprocess.CompletedProcess[str]]) -> None:
    done = cli("--check", "examples/small-station.moas")
    assert done.returncode == 0, done.stderr
    last = done.stdout.splitlines()[-1]
    plan, _ = example_plan(ROOT / "examples" / "small-station.moas")
    assert plan is not None
    assert last == (f"{len(plan.findings)} findings; the whole plan: moas-server --plan "
                    "examples/small-station.moas")
    for finding in plan.findings:
        assert f"examples/small-station.moas:{finding.line}: {finding.text}" in done.stdout


def test_plan_options_are_checked(
        tmp_path: Path, cli: Callable[..., subprocess.CompletedProcess[str]]) -> None:
    assert cli("--plan").returncode == 2
    assert cli("--json", "examples/small-station.moas").returncode == 2
    broken = tmp_path / "broken.moas"
    broken.write_text("{ \"Antennas\": [ }\n")
    done = cli("--plan", str(broken))
    assert done.returncode == 1
    assert f"{broken}:1:" in done.stderr and "Traceback" not in done.stderr


# -- one configuration per kind of finding ------------------------------------------------------

def ant(ident: int, name: str, ranges: list[tuple[float, float]],
        relays: dict[tuple[int, int], int], **extra: Any) -> dict[str, Any]:
    return {"ID": ident, "ShortName": name, "LongName": name, "Conflicts": [ident],
            "Fast": [ident],
            "Control": [{"LowerFrequency": lo, "UpperFrequency": hi,
                         "Stations": [{"Station": s, "Radio": r, "Relays": [rel]}
                                      for (s, r), rel in relays.items()]}
                        for lo, hi in ranges],
            **extra}


def station(antennas: list[dict[str, Any]], radios: list[dict[str, Any]] | None = None,
            **top: Any) -> tuple[Plan, str]:
    """The plan of a configuration written as a file would be (one key a line)."""
    data = {"Antennas": antennas,
            "Radios": radios if radios is not None else [
                {"Station": 1, "Radio": 1, "Switches": [{"Port": 1}]},
                {"Station": 1, "Radio": 2, "Switches": [{"Port": 2}]}],
            "Switches": [{"ID": 1, "Port": "emulator", "IndicateTR": True}], **top}
    text = json.dumps(data, indent=2)
    config = parse_config(text, "crafted.moas").unwrap()
    return build_plan(config, "crafted.moas", text), text


def line_of(text: str, needle: str, after: str = "") -> int:
    start = text.index(after) if after else 0
    return text[:text.index(needle, start)].count("\n") + 1


def group_line(text: str, needle: str, after: str = "") -> int:
    """The line of the ``{`` opening the group that holds ``needle``."""
    start = text.index(after) if after else 0
    return text[:text.rindex("{", 0, text.index(needle, start))].count("\n") + 1


def kinds(plan: Plan) -> list[str]:
    return [f.kind for f in plan.findings]


TWENTY = [(14000, 14350)]
FORTY = [(7000, 7300)]
BOTH = {(1, 1): 0, (1, 2): 8}


def test_an_antenna_no_radio_can_get_is_found_at_its_group() -> None:
    plan, text = station([ant(0, "Tribander", TWENTY, BOTH),
                          ant(1, "Spare", FORTY, {(1, 1): 1}, Enabled=False)])
    found = [f for f in plan.findings if f.kind == "unreachable_antenna"]
    assert len(found) == 1
    finding = found[0]
    assert finding.line == group_line(text, '"ID": 1')
    assert "Spare" in finding.text and "not enabled" in finding.text


def test_a_radio_without_an_antenna_others_have_on_a_band_is_found() -> None:
    """The dipole covers 40 m for radio 1.1 and only 80 m for radio 1.2 (a relay list written
    in the wrong range): radio 1.2 has no antenna on 40 m, radio 1.1 none on 80 m."""
    plan, text = station([ant(0, "Tribander", TWENTY, BOTH),
                          {**ant(1, "Dipole", FORTY, {(1, 1): 1}),
                           "Control": [
                               {"LowerFrequency": 7000, "UpperFrequency": 7300,
                                "Stations": [{"Station": 1, "Radio": 1, "Relays": [1]}]},
                               {"LowerFrequency": 3500, "UpperFrequency": 4000,
                                "Stations": [{"Station": 1, "Radio": 2, "Relays": [9]}]}]}])
    found = [f for f in plan.findings if f.kind == "radio_without_antenna"]
    assert [f.bands for f in found] == [("80 m",), ("40 m",)]
    assert found[1].line == group_line(text, '"Radio": 2', '"Radios"')
    assert found[0].line == group_line(text, '"Radio": 1', '"Radios"')
    assert "Dipole covers 7025 kHz for station 1 radio 1" in found[1].text


def test_two_bands_two_radios_cannot_have_together_are_found_at_the_conflict() -> None:
    plan, text = station([ant(0, "Tribander", TWENTY, BOTH, Conflicts=[0, 1]),
                          ant(1, "Dipole", FORTY, BOTH)])
    found = [f for f in plan.findings if f.kind == "band_pair_blocked"]
    assert found and all(f.line == line_of(text, '"Conflicts"') for f in found)
    assert "20 m + 40 m" in found[0].text and "lists Dipole in its Conflicts" in found[0].text


def test_a_conflict_taking_a_whole_band_from_another_radio_is_found() -> None:
    plan, text = station([ant(0, "Tribander", TWENTY, {(1, 1): 0}, Conflicts=[0, 1]),
                          ant(1, "Vertical", TWENTY, {(1, 2): 9})])
    found = [f for f in plan.findings if f.kind == "band_taken"]
    assert len(found) == 1 and found[0].bands == ("20 m",)
    assert found[0].line == line_of(text, '"Conflicts"')
    assert "when both are on 20 m" in found[0].text


def test_an_inhibit_on_every_shared_band_is_found_at_the_radio_setting() -> None:
    radios = [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}],
               "Always": [{"Station": 1, "Radio": 2}]},
              {"Station": 1, "Radio": 2, "Switches": [{"Port": 2}]}]
    plan, text = station([ant(0, "Tribander", TWENTY, BOTH), ant(1, "Vertical", TWENTY, BOTH)],
                         radios)
    found = [f for f in plan.findings if f.kind == "inhibit_every_same_band"]
    assert len(found) == 1
    assert found[0].line == line_of(text, '"Always"')


def test_same_band_protection_on_every_shared_band_is_found_at_its_key() -> None:
    radios = [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}]},
              {"Station": 2, "Radio": 1, "Switches": [{"Port": 2}]}]
    both = {(1, 1): 0, (2, 1): 8}
    plan, text = station([ant(0, "Tribander", TWENTY, both), ant(1, "Vertical", TWENTY, both)],
                         radios, ProtectSameBand=True)
    found = [f for f in plan.findings if f.kind == "inhibit_every_same_band"]
    assert len(found) == 1
    assert found[0].line == line_of(text, '"ProtectSameBand"')


def test_an_alternate_never_usable_is_found_at_its_rule() -> None:
    radios = [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}],
               "Alternate": [{"LowerFrequency": 14000, "UpperFrequency": 14350,
                              "ThisAntennas": [0], "OtherAntennas": [1], "Antenna": 2}]},
              {"Station": 1, "Radio": 2, "Switches": [{"Port": 2}]}]
    plan, text = station([ant(0, "Tribander", TWENTY, BOTH), ant(1, "Vertical", TWENTY, BOTH),
                          ant(2, "Beverage", [(1800, 2000)], {(1, 1): 2}, RXOnly=True)],
                         radios)
    found = [f for f in plan.findings if f.kind == "alternate_never_usable"]
    assert len(found) == 1
    assert found[0].line == line_of(text, '"Alternate"')
    assert "covers no frequency of the rule's range" in found[0].text


CASE_29 = ROOT / "tests" / "engine" / "engine_cases" / "alternate-is-transmitting-antenna.json"


def test_an_alternate_another_radio_can_transmit_on_is_found_at_its_rule(
        tmp_path: Path, cli: Callable[..., subprocess.CompletedProcess[str]]) -> None:
    """Issue 29's station: station 2 radio 1's Alternate rule names the SharedTX antenna 0,
    which station 1 radio 1 transmits on when it sets the rule off (5.9, 5.12).  As the case
    has it (``OtherAntennas`` [0]) the rule is never usable; without ``OtherAntennas`` it
    acts while station 1 radio 1 transmits anywhere, on antenna 0 too."""
    moas = json.loads(CASE_29.read_text())["moas"]
    text = json.dumps(moas, indent=2)
    plan = build_plan(parse_config(text, "crafted.moas").unwrap(), "crafted.moas", text)
    assert kinds(plan).count("alternate_never_usable") == 1
    del moas["Radios"][1]["Alternate"][0]["OtherAntennas"]
    text = json.dumps(moas, indent=2)
    plan = build_plan(parse_config(text, "crafted.moas").unwrap(), "crafted.moas", text)
    found = [f for f in plan.findings if f.kind == "alternate_can_be_transmitted_on"]
    assert len(found) == 1, plan.findings
    rule_line = line_of(text, '"Alternate"')
    assert found[0].line == rule_line
    assert found[0].text == (
        "station 2 radio 1's Alternate rule switches it to receive on STX (antenna 0), but "
        "station 1 radio 1 can be transmitting on that antenna when the rule acts: then "
        "station 2 radio 1 receives on no antenna instead")
    assert found[0].radios == (RadioRef(2, 1), RadioRef(1, 1))
    # --check says it with the file's line, and the file stays usable (exit status 0)
    path = tmp_path / "station.moas"
    path.write_text(text)
    done = cli("--check", str(path))
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"{path}:{rule_line}: {found[0].text}" in done.stdout
    # an alternate nobody can transmit on (a receive-only antenna) is no finding
    moas["Radios"][1]["Alternate"][0]["Antenna"] = 1
    text = json.dumps(moas, indent=2)
    plan = build_plan(parse_config(text, "crafted.moas").unwrap(), "crafted.moas", text)
    assert "alternate_can_be_transmitted_on" not in kinds(plan)


def test_an_alternate_only_the_radio_setting_it_off_could_use_is_no_finding() -> None:
    """Two radios: the rule acts while the other transmits on one of OtherAntennas, so the
    other cannot be transmitting on the alternate then (ms-one-amp's rules)."""
    radios = [{"Station": 1, "Radio": 1, "Switches": [{"Port": 1}],
               "Alternate": [{"LowerFrequency": 14000, "UpperFrequency": 14350,
                              "OtherAntennas": [0], "Antenna": 1}]},
              {"Station": 1, "Radio": 2, "Switches": [{"Port": 2}]}]
    both = {(1, 1): 1, (1, 2): 9}
    plan, _text = station([ant(0, "Tribander", TWENTY, BOTH), ant(1, "Vertical", TWENTY, both)],
                          radios)
    assert "alternate_can_be_transmitted_on" not in kinds(plan)
    radios[0]["Alternate"][0]["OtherAntennas"] = [0, 1]
    plan, _text = station([ant(0, "Tribander", TWENTY, BOTH), ant(1, "Vertical", TWENTY, both)],
                          radios)
    assert kinds(plan).count("alternate_can_be_transmitted_on") == 1


def test_every_kind_of_finding_is_tested_here() -> None:
    source = Path(__file__).read_text(encoding="utf-8")
    for kind in FINDING_KINDS:
        assert f'"{kind}"' in source


def write_golden() -> None:
    GOLDEN.mkdir(exist_ok=True)
    for example in EXAMPLES:
        plan, error = plan_file(example)
        assert plan is not None, error
        (GOLDEN / f"{example.stem}.txt").write_text(plan.to_text(), encoding="utf-8")
        (GOLDEN / f"{example.stem}.json").write_text(plan.to_json(), encoding="utf-8")


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        write_golden()


def test_a_plan_out_of_time_stops_and_check_says_so_instead_of_waiting(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    # --check of any file stays quick (issue 20); the plan of a huge station is for --plan
    from moas_gui.cli import server
    from moas_gui.plan import PlanTooLong, deadline_after

    big = ROOT / "examples" / "big-station.moas"
    config = parse_config(big.read_text()).unwrap()
    with pytest.raises(PlanTooLong):
        build_plan(config, in_time=deadline_after(0.0))
    assert build_plan(config, in_time=deadline_after(None)).findings  # no limit: finished
    monkeypatch.setattr(server, "CHECK_SECONDS", 0.0)
    assert server.main(["--check", str(big)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1].startswith("findings: not counted (the station is too large to plan")
    assert out[-1].endswith(f"moas-server --plan {big}")
