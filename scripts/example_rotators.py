"""Start an emulated controller for each Serial rotator of an example configuration whose
port does not exist yet, so the example runs with no hardware.

    python scripts/example_rotators.py FILE.moas     prints the emulators' process ids

Used by scripts/run-example.sh, which stops them when the server ends.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from moas_gui.config import RotatorControl, load_config
from moas_gui.hw.rotators.addresses import is_local


def main(path: str) -> int:
    config = load_config(path).config
    if config is None:
        return 0  # the server explains the problems itself
    for rotator in config.rotators:
        host = (rotator.address or "127.0.0.1").rsplit(":", 1)[0]
        port = Path(rotator.comm_port)
        if rotator.control is not RotatorControl.SERIAL or not is_local(host) \
                or not port.is_absolute() or port.exists():
            continue
        process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.rotator", "--emulate", rotator.model,
             "--link", str(port), "--azimuth", str(rotator.ccw_limit % 360)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        print(process.pid)
        print(f"run-example: emulating {rotator.model} rotator {rotator.id} on {port}",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
