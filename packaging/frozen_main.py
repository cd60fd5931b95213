"""The one entry point of the frozen app (packaging/moas-gui.spec).

Every program of the frozen app is this script under another name; it runs the program
its own file is named after, so one analysis of the package serves them all and they
share one folder of libraries.
"""

from __future__ import annotations

import multiprocessing
import sys
from pathlib import Path

PROGRAMS = {
    "moas-server": "moas_gui.cli.server",
    "moas-server-gui": "moas_gui.cli.server",
    "MOAS Server": "moas_gui.cli.server",  # the macOS application bundle's executable
    "moas-client": "moas_gui.cli.client",
    "moas-client-gui": "moas_gui.cli.client",
    "moas-emulator": "moas_gui.cli.emulator",
    "moas-rotator": "moas_gui.cli.rotator",
}


def program_of(executable: str) -> str:
    """The module whose ``main`` runs for this executable's name (``.exe`` dropped)."""
    name = Path(executable).name
    if name.lower().endswith(".exe"):
        name = name[:-4]
    try:
        return PROGRAMS[name]
    except KeyError:
        raise SystemExit(f"{name}: not a program of moas-gui "
                         f"(one of {', '.join(sorted(PROGRAMS))})") from None


def main() -> int:
    import importlib

    module = importlib.import_module(program_of(sys.executable))
    return int(module.main() or 0)


if __name__ == "__main__":
    multiprocessing.freeze_support()
    sys.exit(main())
