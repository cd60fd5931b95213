"""Configuration fuzzing: mutations of every example and of generated stations, through
the reader and through ``moas-server --check``.  Never a traceback, every problem at a
line and column.  How long a file takes to read (never a second) is a figure of the
benchmark below, not a limit here: a busy machine must not fail a test.

The corpus is fixed (seeded), so every run reads the same files; the large run with
figures is ``benchmarks/bench_config_fuzz.py`` (docs/reliability.md).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from config_fuzzing import MUTATIONS, corpus, mutations, read

from moas_gui.cli import server
from moas_gui.config import read_config

FILES = corpus(generated=2)  # with the eight examples: ten files


def test_the_unmutated_corpus_is_usable_without_a_single_problem() -> None:
    assert len(FILES) == 10
    for name, data in FILES.items():
        result = read_config(data, name)
        assert result.ok and result.problems == (), (name, result.problems[:3])


@pytest.mark.parametrize("kind", sorted(MUTATIONS))
def test_mutated_files_give_placed_problems_never_a_crash(kind: str) -> None:
    made = [m for m in mutations(FILES, 400, seed=15) if m[1] == kind]
    assert len(made) == 80
    broken = 0
    for name, _, data in made:
        outcome = read(data, name)
        assert outcome.crash is None, f"{name} ({kind}):\n{outcome.crash}"
        assert outcome.unplaced is None, f"{name} ({kind}): {outcome.unplaced}"
        broken += not outcome.usable
    assert broken >= 10, "the mutations must break files, or they test nothing"


def test_check_explains_mutated_files_in_process(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    for index, (name, kind, data) in enumerate(mutations(FILES, 60, seed=1515)):
        path = tmp_path / f"{index}-{name}"
        path.write_bytes(data)
        status = server.main(["--check", str(path)])
        out = capsys.readouterr().out
        lines = out.splitlines()
        if status == 1:
            assert lines[-1].endswith("the configuration cannot be used."), (kind, out[-300:])
            for line in lines[:-1]:
                assert line.startswith(f"{path}:") and (": error: " in line
                                                        or ": warning: " in line), line
                place = line[len(str(path)) + 1:].split(":")
                assert int(place[0]) >= 1 and int(place[1]) >= 1, line
        else:
            assert status == 0 and "Switches:" in out, (kind, out[-300:])


@pytest.mark.realtime  # real --check processes
def test_check_as_a_process_on_files_cut_short() -> None:
    data = FILES["big-station.moas"]
    for cut in (1, len(data) // 3, len(data) - 2):
        done = subprocess.run(
            [sys.executable, "-m", "moas_gui.cli.server", "--check", "/dev/stdin"],
            input=data[:cut], capture_output=True, check=False, timeout=60)
        assert done.returncode == 1, done.stdout
        assert b"Traceback" not in done.stderr + done.stdout
        assert b"/dev/stdin:" in done.stdout and b"is never closed" in done.stdout
