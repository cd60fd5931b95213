"""Start an emulated controller for each Serial rotator of an example configuration whose
port does not exist yet, so the example runs with no hardware.

    python scripts/example_rotators.py FILE.moas DIR    prints the emulators' process ids

The emulators' links go into DIR (a private directory made for this run), not
where the file names them (``/tmp/moas-rotator-1`` ...), so two users or two
runs never share one; a copy of FILE naming those links is written to DIR under
FILE's name, for the server to open.  Used by scripts/run-example.sh, which
stops the emulators and removes DIR when the server ends.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from moas_gui.config import RotatorControl, load_config
from moas_gui.hw.rotators.addresses import is_local


def main(path: str, directory: str) -> int:
    config = load_config(path).config
    text = Path(path).read_text(encoding="utf-8")
    private = Path(directory)
    copy = private / Path(path).name
    if config is None:
        copy.write_text(text, encoding="utf-8")  # the server explains the problems itself
        return 0
    for rotator in config.rotators:
        host = (rotator.address or "127.0.0.1").rsplit(":", 1)[0]
        port = Path(rotator.comm_port)
        if rotator.control is not RotatorControl.SERIAL or not is_local(host) \
                or not port.is_absolute() or port.exists():
            continue
        link = private / port.name
        named = json.dumps(str(port))
        if named not in text:
            print(f"run-example: rotator {rotator.id}'s port {port} is not written as "
                  f"{named} in {path}; not emulated", file=sys.stderr)
            continue
        text = text.replace(named, json.dumps(str(link)))
        process = subprocess.Popen(
            [sys.executable, "-m", "moas_gui.cli.rotator", "--emulate", rotator.model,
             "--link", str(link), "--azimuth", str(rotator.ccw_limit % 360)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        print(process.pid)
        print(f"run-example: emulating {rotator.model} rotator {rotator.id} on {link}",
              file=sys.stderr)
    copy.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print("usage: python scripts/example_rotators.py FILE.moas DIR", file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
