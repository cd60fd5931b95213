"""Start an emulated controller for each Serial rotator of an example configuration whose
port does not exist yet, so the example runs with no hardware.

    python scripts/example_rotators.py FILE.moas DIR    prints the emulators' process ids

The emulators' links go into DIR (a private directory of this user's), not where
the file names them (``/tmp/moas-rotator-1`` ...), so two users or two runs never
share one.  The file is not copied or changed: DIR/rotator-ports lists one
``ID=LINK`` a line, which scripts/run-example.sh hands to the server as
``--rotator-port ID=LINK``, so the server opens the example itself (Recent Files and
every message name it, and its saved state comes back).  run-example.sh stops the
emulators and removes the links when the server ends.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from moas_gui.config import RotatorControl, load_config
from moas_gui.hw.rotators.addresses import is_local


def main(path: str, directory: str) -> int:
    config = load_config(path).config
    private = Path(directory)
    listed = private / "rotator-ports"
    moved: list[str] = []
    for rotator in config.rotators if config is not None else ():  # broken: the server says
        host = (rotator.address or "127.0.0.1").rsplit(":", 1)[0]
        port = Path(rotator.comm_port)
        if rotator.control is not RotatorControl.SERIAL or not is_local(host) \
                or not port.is_absolute() or port.exists():
            continue
        link = private / port.name
        process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.rotator", "--emulate", rotator.model,
             "--link", str(link), "--azimuth", str(rotator.ccw_limit % 360)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        print(process.pid)
        moved.append(f"{rotator.id}={link}")
        print(f"run-example: emulating {rotator.model} rotator {rotator.id} on {link}",
              file=sys.stderr)
    listed.write_text("".join(f"{line}\n" for line in moved), encoding="utf-8")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print("usage: python scripts/example_rotators.py FILE.moas DIR", file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
