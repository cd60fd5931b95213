"""What-if: the model layer's answers against the engine itself, and ``moas-server
--what-if`` through the real command (a process of its own; its refusals of bad
arguments through the command's own ``main`` in this process, as they are about the
words and the exit status, not the process)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from moas_gui.builder.whatif import WhatIfError, what_if
from moas_gui.cli.server import main as server_main
from moas_gui.config import load_config
from moas_gui.config.model import RadioRef
from moas_gui.engine import Engine

ROOT = Path(__file__).resolve().parents[2]
SMALL = ROOT / "examples" / "small-station.moas"
SHARED = ROOT / "examples" / "two-op-shared-tx.moas"


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "moas_gui.cli.server", *args],
                          capture_output=True, text=True, timeout=120, check=False)


@pytest.mark.parametrize("path", sorted((ROOT / "examples").glob("*.moas")), ids=lambda p: p.name)
def test_answers_are_the_engine_s(path: Path) -> None:
    config = load_config(path).unwrap()
    first, second = sorted(Engine(config)._ix.mains)[:2]
    answers = {a.radio: a for a in what_if(config, [(first, 14025), (second, 14030)], [first])}
    engine = Engine(config)
    engine.set_frequency(first.station, first.radio, 14025)
    engine.set_frequency(second.station, second.radio, 14030)
    ix = engine._ix
    switch, port = ix.radios[first].ports[0]
    engine.set_transmitting(switch, port, True)
    for view in engine.radios():
        answer = answers[RadioRef(view.station, view.radio)]
        assert (answer.tx, answer.rx, answer.alt, answer.inhibited, answer.transmitting) == \
            (view.tx, view.rx, view.alt, view.inhibited, view.transmitting)
        assert answer.why == (view.why.text if view.why else "")


@pytest.mark.realtime
def test_the_command_prints_each_radio_s_antennas_and_why() -> None:
    done = run("--what-if", str(SMALL), "--radio", "1/1", "--khz", "14025",
               "--radio", "1/2", "--khz", "14200", "--transmitting", "1/1")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        ("station 1 radio 1 at 14025 kHz, transmitting: transmit 0 Tribander; "
        "receive 0 Tribander; alternate none"),
        "  why: lowest-numbered antenna covering 14025 kHz [f4_lowest]",
        ("station 1 radio 2 at 14200 kHz: transmit 3 Vertical; receive 3 Vertical; "
        "alternate none"),
        "  inhibited: inhibited while station 1 radio 1 transmits",
        "  why: lowest-numbered antenna covering 14200 kHz [f4_lowest]",
        "  passed over 0 Tribander: is in use by station 1 radio 1",
    ]


@pytest.mark.realtime
def test_the_command_speaks_json() -> None:
    done = run("--what-if", str(SHARED), "--radio", "1/1", "--khz", "14025",
               "--radio", "2/1", "--khz", "14200", "--json")
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout)
    config = load_config(SHARED).unwrap()
    expected = {a.radio: a.to_dict() for a in what_if(
        config, [(RadioRef(1, 1), 14025), (RadioRef(2, 1), 14200)])}
    assert answer["file"] == str(SHARED)
    assert {(r["station"], r["radio"]): r for r in answer["radios"]} == \
        {(k.station, k.radio): v for k, v in expected.items()}
    first = answer["radios"][0]
    assert first["tx"] == {"id": 0, "name": "Tribander"} and first["why"]["rule"] == "f4_lowest"


@pytest.mark.parametrize(("args", "status", "words"), [
    (["--radio", "1/1", "--khz", "14025"], 2, "go with --what-if FILE"),
    (["--what-if", str(SMALL), "--radio", "1/1"], 2, "each --radio needs its --khz"),
    (["--what-if", str(SMALL), "--radio", "one", "--khz", "1"], 2, "'one' is not a station and radio"),
    (["--what-if", str(SMALL), "--radio", "1/1", "--khz", "-5"], 2, "not a frequency in kHz above 0"),
    (["--what-if", str(SMALL), "--radio", "3/1", "--khz", "7025"], 1,
     'station 3 radio 1 is not in "Radios"'),
    (["--what-if", str(ROOT / "nowhere.moas"), "--radio", "1/1", "--khz", "7025"], 1,
     "there is no such file"),
])
def test_the_command_says_what_is_wrong(capsys: pytest.CaptureFixture[str], args: list[str],
                                       status: int, words: str) -> None:
    returned: object
    try:
        returned = server_main(args)
    except SystemExit as exit_:  # argparse's refusals
        returned = exit_.code
    said = capsys.readouterr()
    assert returned == status
    assert words in said.err and said.out == ""


def test_an_unknown_radio_is_refused_in_the_model_too() -> None:
    config = load_config(SMALL).unwrap()
    with pytest.raises(WhatIfError, match="station 9 radio 9"):
        what_if(config, [], [RadioRef(9, 9)])


@pytest.mark.realtime
def test_edit_opens_the_builder_window_through_the_real_command(tmp_path: Path) -> None:
    """``moas-server --edit FILE`` (offscreen): the window claims the file (so a second
    ``--edit`` is refused, naming it) and runs until it is ended."""
    import os
    import time

    from moas_gui.builder.claims import holder

    station = tmp_path / "station.moas"
    station.write_bytes(SMALL.read_bytes())
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    with subprocess.Popen([sys.executable, "-m", "moas_gui.cli.server", "--edit", str(station)],
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as first:
        try:
            deadline = time.monotonic() + 60
            while holder(station) is None and first.poll() is None and time.monotonic() < deadline:
                time.sleep(0.1)
            claim = holder(station)
            assert claim is not None and claim.pid == first.pid, first.poll()
            assert claim.window == "Station builder - station.moas"
            second = subprocess.run([sys.executable, "-m", "moas_gui.cli.server", "--edit",
                                     str(station)], env=env, capture_output=True, text=True,
                                    timeout=120, check=False)
            assert second.returncode == 1
            assert f'open in the builder window "Station builder - station.moas" (process {first.pid}' \
                in second.stderr
        finally:
            first.terminate()
            first.communicate(timeout=60)
    assert station.read_bytes() == SMALL.read_bytes(), "nothing was written"
