"""``moas-server --install-service FILE``: run the headless server as a systemd user
service (a Raspberry Pi or any small Linux computer at the tower).

It writes ``$XDG_CONFIG_HOME/systemd/user/moas-server.service`` (by default
``~/.config/systemd/user``), whose ``ExecStart`` is this installation's
``moas-server --headless`` with FILE made absolute and the other options given with it
(``--web-port 8080``, say), and tells what to run next: ``systemctl --user enable --now
moas-server`` to start it now and at every log-in, and ``loginctl enable-linger`` so that
it starts at boot without anyone logging in.  systemd stops it with SIGTERM, on which
the server writes its state and leaves the relays as they are; it is restarted when it
fails.  No administrator rights are needed.  See ``docs/platforms.md``.
"""

from __future__ import annotations

import getpass
import os
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Final

from .files import write_text_atomic

UNIT_NAME: Final = "moas-server.service"


def systemd_quote(argument: str) -> str:
    """One word of an ``ExecStart`` line: ``%`` and ``$`` doubled (systemd's specifiers
    and variables), in double quotes with ``\\`` and ``"`` escaped when needed."""
    argument = argument.replace("%", "%%").replace("$", "$$")
    if argument and not any(c in argument for c in ' \t\n"\'\\;'):
        return argument
    return '"' + argument.replace("\\", "\\\\").replace('"', '\\"') + '"'


def systemd_unit(command: Sequence[str]) -> str:
    """The text of ``moas-server.service`` running ``command`` (absolute program first)."""
    exec_start = " ".join(systemd_quote(part) for part in command)
    return "\n".join([
        "# Written by moas-server --install-service; see docs/platforms.md",
        "[Unit]",
        "Description=MOAS II antenna switch server (headless)",
        "After=network-online.target",
        "Wants=network-online.target",
        "",
        "[Service]",
        "Type=simple",
        f"ExecStart={exec_start}",
        "Environment=PYTHONUNBUFFERED=1",
        # SIGTERM: the server writes its state and stops; the relays stay as they are
        "KillSignal=SIGTERM",
        "TimeoutStopSec=30",
        "Restart=on-failure",
        "RestartSec=5",
        "",
        "[Install]",
        "WantedBy=default.target",
        "",
    ])


def user_unit_dir(environ: Mapping[str, str] = os.environ) -> Path:
    value = environ.get("XDG_CONFIG_HOME", "")
    base = Path(value) if value and os.path.isabs(value) else Path.home() / ".config"
    return base / "systemd" / "user"


def service_command(server: Sequence[str], arguments: Sequence[str], config: str) -> list[str]:
    """``server`` (the program) with ``arguments`` as given to ``--install-service``: that
    option dropped, ``--headless`` added, ``config`` made absolute."""
    absolute = str(Path(config).expanduser().resolve())
    kept = [absolute if arg == config else arg for arg in arguments if arg != "--install-service"]
    if "--headless" not in kept:
        kept.insert(0, "--headless")
    return [*server, *kept]


def install_service(command: Sequence[str], *, platform: str = sys.platform,
                    environ: Mapping[str, str] = os.environ) -> list[str]:
    """Write the user unit running ``command``; returns the sentences to print."""
    if not platform.startswith("linux"):
        raise OSError("systemd services are for Linux; on Windows and macOS see "
                      "docs/platforms.md (a scheduled task, a launchd agent)")
    unit = user_unit_dir(environ) / UNIT_NAME
    unit.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(unit, systemd_unit(command))
    user = environ.get("USER") or getpass.getuser()
    return [
        f"wrote {unit}",
        ("start it now and at every log-in:  systemctl --user daemon-reload && "
         "systemctl --user enable --now moas-server"),
        f"start it at boot, before anyone logs in:  sudo loginctl enable-linger {user}",
        "follow its log:  journalctl --user -u moas-server -f",
    ]


__all__ = ["UNIT_NAME", "install_service", "service_command", "systemd_quote", "systemd_unit",
           "user_unit_dir"]
