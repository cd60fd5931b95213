"""Each emulator checked by the real Hamlib client for its controller (``rotctl -m N``).

For every model, two ``rotctl`` runs go at the same time, each on its own
emulator on its own pseudo-terminal:

- a fast rotator: read the position, set it, read it again;
- a rotator at a realistic speed: set it, then stop it half-way.

Hamlib is the judge of the bytes: if an emulator answered differently from
what Hamlib's driver for that controller expects, ``rotctl`` would print an
error or a wrong number.
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterator

import pytest
from helpers import wait_for

from moas_gui.hw.rotators.controllers.models import find_model
from moas_gui.hw.rotators.controllers.pty_host import EmulatorHost, ServedPort

pytestmark = pytest.mark.realtime

ROTCTL = shutil.which("rotctl")

START = 123.0
FAST = 2000.0
"""Degrees per second of the 'fast' rotator: any turn is over before rotctl reads again."""
SLOW = 25.0
"""Degrees per second of the rotator that is stopped on its way (rotctl waits its
post-write delay, :data:`QUIET` ms, between the set and the stop)."""
QUIET = 20
"""Milliseconds rotctl waits after each command (its ``post_write_delay``).

Hamlib's own values (500 ms for the Hy-Gain boxes, 300 ms for the SPIDs) give a real
controller's processor time; the emulators answer at once, and 20 ms is enough for
the turn a set starts to be under way before the next command (a read, or the stop)."""

# (our model, rotctl -m, extra rotctl options)
CASES = [
    ("DCU1", 403, []),
    ("RotorEZ", 401, []),
    ("GS-232A", 601, []),
    ("Yaesu", 603, []),
    ("RC2800P-X", 1001, []),
    ("RC2800P-A", 1002, []),
    ("Rot2Prog", 901, []),
    ("Rot1Prog", 902, []),
    ("Alfaspid", 902, []),
    ("Prosistel D", 1701, []),
]


RUNNING: list[subprocess.Popen[str]] = []


@pytest.fixture
def host() -> Iterator[EmulatorHost]:
    with EmulatorHost() as running:
        try:
            yield running
        finally:
            while RUNNING:  # a failed test leaves its other rotctl behind: end it
                process = RUNNING.pop()
                if process.poll() is None:
                    process.kill()
                process.communicate()


def rotctl(hamlib: int, path: str, *commands: str,
           timeout: int = 5000) -> subprocess.Popen[str]:
    """rotctl on ``path``, pausing :data:`QUIET` ms after each command and waiting up to
    ``timeout`` ms for a reply (5 s, not rotctl's 0.4-1.5 s: on a busy machine the
    emulator's thread can be that late, which would prove nothing).  A last command
    ``-`` makes it read further commands from its standard input (the test writes them)."""
    assert ROTCTL is not None, "Hamlib's rotctl is missing: scripts/setup.sh --test installs it"
    conf = ["-C", f"timeout={timeout},post_write_delay={QUIET}"]
    process = subprocess.Popen([ROTCTL, "-m", str(hamlib), "-r", path, *conf, *commands],
                               stdin=subprocess.PIPE if commands[-1:] == ("-",)
                               else subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    RUNNING.append(process)
    return process


def finish(process: subprocess.Popen[str]) -> tuple[int, list[float], str]:
    """Exit code, the numbers printed, and all text printed (rotctl puts errors on stdout)."""
    try:
        out, err = process.communicate(timeout=30)  # closes its standard input, if any
    except subprocess.TimeoutExpired:
        process.kill()
        out, err = process.communicate()
        pytest.fail(f"rotctl did not finish: {err[-500:]}")
    numbers = []
    for line in out.split():
        try:
            numbers.append(float(line))
        except ValueError:
            pass
    return process.returncode, numbers, out + err


def state(host: EmulatorHost, port: ServedPort) -> tuple[float, bool]:
    return host.call(port, lambda emulator, now: (emulator.azimuth, emulator.busy))


@pytest.mark.parametrize(("model", "hamlib", "options"), CASES,
                         ids=[f"{m}-{h}" for m, h, _ in CASES])
def test_rotctl_reads_sets_and_stops_the_emulator(host: EmulatorHost, model: str, hamlib: int,
                                                  options: list[str]) -> None:
    maker = find_model(model)
    fast = host.add(maker.make_emulator(START, FAST, host.clock()))
    slow = host.add(maker.make_emulator(START, SLOW, host.clock()))
    has_readback = maker.info.has_readback

    read = ["p"] if has_readback else []
    # the read after the set waits until the emulator has moved: read at once, a loaded
    # machine's emulator thread could take the set and the read in the same instant
    fast_run = rotctl(hamlib, fast.path, *options, *read, "P", "200", "0",
                      *(["-"] if has_readback else []))
    slow_run = rotctl(hamlib, slow.path, *options, "P", "300", "0", "S", *read)
    if has_readback:
        wait_for(lambda: state(host, fast)[0] != START, timeout=10.0,
                 what="the fast rotator to move after the set")
        assert fast_run.stdin is not None
        fast_run.stdin.write("p\n")
        fast_run.stdin.flush()  # finish() closes it: rotctl reads no more and ends

    code, numbers, err = finish(fast_run)
    assert code == 0, err[-800:]
    if has_readback:
        assert numbers[0] == pytest.approx(START, abs=0.05)
        # read once the emulator moved: the turn is under way, or over
        assert numbers[2] != START
    # the last turn ends (a Hy-Gain box may have more than 300 degrees to go: 0.2 s)
    wait_for(lambda: not state(host, fast)[1], timeout=2.0, what="the fast turn to end")
    assert state(host, fast)[0] == pytest.approx(200.0, abs=0.05)

    code, numbers, err = finish(slow_run)
    assert code == 0, err[-800:]
    # rotctl has sent the stop; its turn would need about 7 s more to end by itself (slow
    # enough that a loaded machine delaying rotctl cannot let it end first)
    wait_for(lambda: not state(host, slow)[1], timeout=1.0,
             what="the stop to stop the emulator")
    azimuth, busy = state(host, slow)
    assert not busy, "the stop did not stop the emulator"
    assert abs(azimuth - START) > 0.05, "the set did not start a turn"
    assert abs(azimuth - 300.0) > 5, "the stop came after the turn was over"
    if has_readback:  # read after the stop: where the emulator stands, to its resolution
        assert numbers[0] == pytest.approx(azimuth, abs=0.51)


def test_rotctl_finds_no_position_readback_on_a_dcu1(host: EmulatorHost) -> None:
    port = host.add(find_model("DCU1").make_emulator(START))
    code, _, err = finish(rotctl(403, port.path, "p"))
    assert code != 0
    assert "Feature not available" in err


def test_rotctl_gets_the_rotorez_heading_after_the_power_on_byte(host: EmulatorHost) -> None:
    from moas_gui.hw.rotators.controllers.rotorez_emulator import RotorEZEmulator

    port = host.add(RotorEZEmulator(bearing=77.0, stray_byte=True))
    # past the stray byte by rotctl's own timeout and retry, as it comes (a short
    # timeout: rotctl waits it out once, for the rest of the broken answer)
    code, numbers, err = finish(rotctl(401, port.path, "p", timeout=300))
    assert code == 0, err[-800:]
    assert numbers[0] == 77.0
